#pragma once
/// \file The seen-and-lit ratio of an open mesh's cells (hierarchy/volume/cells.h,
/// CellGrid::lit_ratio): how much more often a light reaches the surfaces a camera sees than
/// the cells' lit share says, by the angle between viewer and light and by level. Traced
/// through the real triangles once per mesh, like the coverage bake.
///
/// From each of `views` directions v (uniform over the sphere), parallel lines along v across
/// the mesh's bounding sphere find the points seen from v; for each angle bin k, one light
/// direction l at that angle from -v (random azimuth) and one shadow ray from each point
/// through the triangles. Per level L the ratio is the points lit over the sum of the lit
/// shares toward l of the level-L cells holding them. It holds what cells cannot: at fine
/// levels the gap a camera ray came through (the hot spot, a leaf wide), at coarse levels also
/// where in a cell the seen surfaces lie (its front, which a light near the viewer reaches
/// more often and a light behind the cell less), and any bias of a level's lit share.

#include <cstdint>

namespace amalgam {

class ExplicitHierarchy;
class CellGrid;

struct LitRatioConfig {
  int views = 128;  ///< view directions
  int lines = 200;  ///< lines per view direction
  std::uint64_t seed = 0x6c6974;
};

/// Fills g.lit_ratio for `mesh` (g baked from it: bake_cells). Deterministic: the same ratios
/// for any thread count.
void bake_lit_ratio(const ExplicitHierarchy& mesh, CellGrid& g, const LitRatioConfig& config = {});

}  // namespace amalgam

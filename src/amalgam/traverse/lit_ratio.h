#pragma once
/// \file The seen-and-lit correction of an open mesh's cells (hierarchy/volume/cells.h,
/// CellGrid::lit_ratio and seen_lit): how much more often a light reaches the surfaces a camera
/// sees than the cells' lit share says, by level, by how steeply the camera looks (the view's
/// rise in object space) and by the angle between viewer and light. Traced through the real
/// triangles once per mesh, like the coverage bake.
///
/// From each of `views` directions v (uniform over the sphere), parallel lines along v across
/// the mesh's bounding sphere find the points seen from v; for each angle bin k, one light
/// direction l at that angle from -v (random azimuth) and one shadow ray from each point
/// through the triangles. Per level L, rise bin and angle bin, the share of the points lit
/// against the mean lit share toward l of the level-L cells holding them gives the correction
/// (CellGrid::lit_ratio). It holds what cells cannot: at fine levels the gap a camera ray came
/// through (the hot spot, a leaf wide), at coarse levels also where in a cell the seen surfaces
/// lie (its front, which a light near the viewer reaches more often and a light behind the cell
/// less), and any bias of a level's lit share.

#include <cstdint>

#include "amalgam/geometry/ray.h"

namespace amalgam {

class ExplicitHierarchy;
class CellGrid;

struct LitRatioConfig {
  int views = 4096;  ///< view directions (the correction's noise falls with their number)
  int lines = 50;    ///< lines per view direction
  std::uint64_t seed = 0x6c6974;
};

/// A line along unit `v` across the bounding sphere of grid `g`'s box, at (u1, u2) in [0, 1)^2
/// of the square about the sphere's centre across v (starting outside the sphere).
Ray line_across(const CellGrid& g, Vec3 v, float u1, float u2);

/// The cell (id + 1, or 0: no surface there) of `level` holding point `p` (clamped to the
/// grid), and when `corner` is given, the cell's lowest corner.
std::uint32_t cell_holding(const CellGrid& g, int level, Vec3 p, Vec3* corner = nullptr);

/// Fills g.lit_ratio for `mesh` (g baked from it: bake_cells). Deterministic: the same
/// corrections for any thread count.
void bake_lit_ratio(const ExplicitHierarchy& mesh, CellGrid& g, const LitRatioConfig& config = {});

}  // namespace amalgam

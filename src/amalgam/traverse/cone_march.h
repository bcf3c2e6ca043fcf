#pragma once
/// \file The cone march through one object's volumetric amalgams (hierarchy/volume/cells.h):
/// the level chosen from the cone's width, then the cells of that level that the cone's axis
/// crosses, front to back (march_cells, cells.h). Not the BVH walk: cells are disjoint and come
/// out in depth order, so nothing is sorted and nothing overlaps. Counting is the caller's: one
/// intersection test per cell stepped through (empty ones included: their index is read), under
/// ObjectKind::kCell.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "amalgam/geometry/ray.h"
#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/math/random.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// The level of `g` at which a cone of width `cone_width` (object units) meets cells of
/// `cell_pixels` cone widths (their longest edge): log2(longest / (cell_pixels * cone_width)),
/// rounded down or up at
/// random with probability by its fraction (`u` uniform in [0, 1)), so that the expected
/// image is the exact mix of the two nearest levels (no second filter). May exceed the finest
/// level: the cone is then finer than the finest cell and the object is traced at full detail.
inline int choose_cell_level(const CellGrid& g, float cone_width, float cell_pixels, float u) {
  if (!(cone_width > 0.0f)) return g.levels;  // a cone of no width: full detail
  const float lambda = std::log2(g.longest() / (cell_pixels * cone_width));
  if (!(lambda > 0.0f)) return 0;
  if (lambda >= static_cast<float>(g.levels)) return g.levels;
  const float f = std::floor(lambda);
  return static_cast<int>(f) + (u < lambda - f ? 1 : 0);
}

/// The uniform number choose_cell_level uses for object `object` and the ray keyed `key`.
inline float level_choice_u(std::uint64_t key, std::uint64_t object) {
  return to_unit_float(hash_combine(key ^ 0x6c6576656cull, object));
}

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file Generated placements of instances (a scene file's "grid" and "scatter"): pure
/// functions from a pattern to the transforms of its instances, composed in double.

#include <cstdint>
#include <vector>

#include "amalgam/math/transform.h"
#include "amalgam/math/vec.h"

namespace amalgam {

/// nx * nz placements on the plane y = origin.y, `spacing` apart, centred on `origin`.
struct GridPattern {
  std::int64_t nx = 1, nz = 1;  ///< >= 1 each
  double spacing = 1.0;         ///< > 0
  Vec3 origin{};
};

/// The translations of a grid, x varying fastest: instance (i, j) is at origin +
/// ((i - (nx - 1) / 2) spacing, 0, (j - (nz - 1) / 2) spacing).
std::vector<AffineD> grid_placements(const GridPattern& grid);

/// `count` placements uniform on the disc of `radius` around `centre` in the plane
/// y = centre.y, each turned about y by a uniform angle when `rotate`.
struct ScatterPattern {
  std::int64_t count = 1;  ///< >= 1
  double radius = 1.0;     ///< > 0
  std::uint64_t seed = 0;
  Vec3 centre{};
  bool rotate = true;
};

/// The placements of a scatter: translate * rotate_y. Placement i depends only on
/// (seed, i), not on `count`.
std::vector<AffineD> scatter_placements(const ScatterPattern& scatter);

}  // namespace amalgam

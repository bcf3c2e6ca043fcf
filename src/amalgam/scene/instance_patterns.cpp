#include "amalgam/scene/instance_patterns.h"

#include <cmath>
#include <cstddef>
#include <numbers>

#include "amalgam/math/random.h"

namespace amalgam {

std::vector<AffineD> grid_placements(const GridPattern& g) {
  const std::int64_t nx = g.nx, nz = g.nz;
  std::vector<AffineD> out;
  out.reserve(static_cast<std::size_t>(nx * nz));
  for (std::int64_t j = 0; j < nz; ++j)
    for (std::int64_t i = 0; i < nx; ++i)
      out.push_back(AffineD::translate(
          {g.origin.x + static_cast<float>((static_cast<double>(i) - 0.5 * (nx - 1)) * g.spacing),
           g.origin.y,
           g.origin.z +
               static_cast<float>((static_cast<double>(j) - 0.5 * (nz - 1)) * g.spacing)}));
  return out;
}

std::vector<AffineD> scatter_placements(const ScatterPattern& sc) {
  std::vector<AffineD> out;
  out.reserve(static_cast<std::size_t>(sc.count));
  for (std::int64_t i = 0; i < sc.count; ++i) {
    // Uniform on the disc of `radius` in the plane y = centre.y.
    Sampler s(hash_combine(sc.seed, static_cast<std::uint64_t>(i)));
    const double r = sc.radius * std::sqrt(static_cast<double>(s.next()));
    const double phi = 2.0 * std::numbers::pi * s.next();
    const double angle = sc.rotate ? 360.0 * s.next() : 0.0;
    out.push_back(
        AffineD::translate({sc.centre.x + static_cast<float>(r * std::cos(phi)), sc.centre.y,
                            sc.centre.z + static_cast<float>(r * std::sin(phi))}) *
        AffineD::rotate(1, angle));
  }
  return out;
}

}  // namespace amalgam

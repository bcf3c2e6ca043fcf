#pragma once
// A cloud of random leaves for the volumetric amalgams' tests (volume_test.cpp,
// traverse/lit_ratio_test.cpp): n rectangles 12 x 8 cm (two triangles each) at random
// orientations, centred uniformly in the unit ball.

#include <cmath>
#include <vector>

#include "amalgam/math/random.h"
#include "amalgam/scene/scene.h"

namespace amalgam {

inline std::vector<Primitive> leaves(int n, std::uint64_t seed) {
  std::vector<Primitive> out;
  Sampler s(seed);
  for (int i = 0; i < n; ++i) {
    Vec3 c;
    do {
      c = {2 * s.next() - 1, 2 * s.next() - 1, 2 * s.next() - 1};
    } while (dot(c, c) > 1.0f);
    const float z = 2 * s.next() - 1, phi = 6.2831853f * s.next();
    const Vec3 nrm{std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z};
    const Vec3 a = std::fabs(nrm.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 u = normalize(cross(a, nrm)) * 0.06f, v = cross(nrm, normalize(u)) * 0.04f;
    out.push_back({PrimKind::kTriangle, 0, c - u - v, c + u - v, c + u + v});
    out.push_back({PrimKind::kTriangle, 0, c - u - v, c + u + v, c - u + v});
  }
  return out;
}

/// A closed octahedron-subdivided sphere of radius r (outward wound).

}  // namespace amalgam

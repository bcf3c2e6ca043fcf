#pragma once
/// \file Rays with a cone footprint (for level-of-detail decisions).

#include <limits>

#include "amalgam/math/vec.h"

namespace amalgam {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

/// A ray o + t d for t in [tmin, tmax]. `inv_dir` is precomputed for slab tests.
/// The cone describes the ray's footprint: its width at parameter t is
/// `cone_width + cone_spread * t` (world units; `t` measured along a unit `dir`).
struct Ray {
  Vec3 origin;
  Vec3 dir;
  Vec3 inv_dir;
  float tmin = 0.0f;
  float tmax = kInfinity;
  float cone_width = 0.0f;
  float cone_spread = 0.0f;

  /// Makes a ray; `dir` need not be normalised, but footprints assume it is.
  static Ray make(Vec3 o, Vec3 d, float tmin = 0.0f, float tmax = kInfinity) {
    Ray r;
    r.origin = o;
    r.dir = d;
    r.inv_dir = {1.0f / d.x, 1.0f / d.y, 1.0f / d.z};
    r.tmin = tmin;
    r.tmax = tmax;
    return r;
  }
  Vec3 at(float t) const { return origin + dir * t; }
  float footprint(float t) const { return cone_width + cone_spread * t; }
};

}  // namespace amalgam

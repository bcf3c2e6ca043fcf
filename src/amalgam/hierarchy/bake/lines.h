#pragma once
/// \file Random lines crossing a box: the bake's samples.
///
/// "Random line crossing a box" is the isotropic (motion-invariant) line measure restricted to
/// the box: pick a face with probability proportional to its area, a uniform point on it and
/// a cosine-weighted direction into the box (Santalo, "Integral Geometry and Geometric
/// Probability", ch. 12).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "amalgam/geometry/bbox.h"
#include "amalgam/geometry/ray.h"
#include "amalgam/math/random.h"

namespace amalgam {

/// Lines crossing one box: what depends on the box alone is computed once, for the many lines
/// a bake draws through it. `LineSampler(box)(u)` is `sample_line(box, u)`, bit for bit.
class LineSampler {
 public:
  explicit LineSampler(const Bbox& box);
  /// A random line crossing the box as a ray (unit direction) that starts outside it. `u` are
  /// six uniform numbers in [0, 1); u[0] picks the face (stratify it), u[1] the side.
  Ray operator()(const float u[6]) const {
    if (!(total_ > 0.0f)) [[unlikely]]
      return point(u);
    int axis = 2;
    const float pick = u[0] * total_;
    if (pick < area0_)
      axis = 0;
    else if (pick < area01_)
      axis = 1;
    const int i = axis == 2 ? 0 : axis + 1, j = axis == 0 ? 2 : axis - 1;
    const bool low = u[1] < 0.5f;
    // Arrays indexed by axis (Vec3::operator[] is a chain of selects).
    float p[3], d[3];
    p[axis] = low ? lo_[axis] : hi_[axis];
    p[i] = lo_[i] + e_[i] * u[2];
    p[j] = lo_[j] + e_[j] * u[3];
    // Cosine-weighted direction into the box.
    const float r = std::sqrt(u[4]), phi = 2.0f * std::numbers::pi_v<float> * u[5];
    d[i] = r * std::cos(phi);
    d[j] = r * std::sin(phi);
    d[axis] = std::sqrt(std::max(0.0f, 1.0f - u[4])) * (low ? 1.0f : -1.0f);
    const Vec3 dir{d[0], d[1], d[2]};
    return Ray::make(Vec3{p[0], p[1], p[2]} - dir * reach_, dir);
  }

 private:
  /// A box of no area (a segment or a point): a uniformly random direction through its centre.
  Ray point(const float u[6]) const;
  float lo_[3], hi_[3], e_[3];
  float area0_, area01_, total_, reach_;
};

/// A random line crossing `box` (see LineSampler).
Ray sample_line(const Bbox& box, const float u[6]);

/// The six uniform numbers of line `r` of `rays` drawn for the stream `key`: u[d] is dimension
/// d of Sampler(hash_combine(key, r)), and u[0] is stratified, (r + u[0]) / rays. The same
/// numbers as drawing them from the Sampler, with the hashes of the dimensions precomputed.
inline void line_uniforms(std::uint64_t key, int r, int rays, float u[6]) {
  static constexpr std::uint64_t kDim[6] = {mix64(0), mix64(1), mix64(2),
                                            mix64(3), mix64(4), mix64(5)};
  const std::uint64_t k = hash_combine(key, static_cast<std::uint64_t>(r));
  for (int d = 0; d < 6; ++d) u[d] = to_unit_float(mix64(k ^ kDim[d]));
  u[0] = (static_cast<float>(r) + u[0]) / static_cast<float>(rays);
}

}  // namespace amalgam

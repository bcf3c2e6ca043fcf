#pragma once
/// \file Random lines crossing a box: the bake's samples.
///
/// "Random line crossing a box" is the isotropic (motion-invariant) line measure restricted to
/// the box: pick a face with probability proportional to its area, a uniform point on it and
/// a cosine-weighted direction into the box (Santalo, "Integral Geometry and Geometric
/// Probability", ch. 12).

#include <cstdint>

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
  Ray operator()(const float u[6]) const;

 private:
  Bbox box_;
  Vec3 e_;
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

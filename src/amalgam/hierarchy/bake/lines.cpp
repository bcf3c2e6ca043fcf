#include "amalgam/hierarchy/bake/lines.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace amalgam {

LineSampler::LineSampler(const Bbox& box) : box_(box), e_(box.extent()) {
  const float area[3] = {e_.y * e_.z, e_.z * e_.x, e_.x * e_.y};
  area0_ = area[0];
  area01_ = area[0] + area[1];
  total_ = area[0] + area[1] + area[2];
  reach_ = std::max(box.diagonal(), 1e-30f) * 1.01f + 1e-30f;
}

Ray LineSampler::operator()(const float u[6]) const {
  const Bbox& box = box_;
  const Vec3 e = e_;
  if (!(total_ > 0.0f)) {
    // A segment or a point: a uniformly random direction through the centre.
    const float z = 1.0f - 2.0f * u[4], r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * std::numbers::pi_v<float> * u[5];
    const Vec3 d{r * std::cos(phi), r * std::sin(phi), z};
    return Ray::make(box.center() - d * reach_, d);
  }
  int axis = 2;
  float pick = u[0] * total_;
  if (pick < area0_)
    axis = 0;
  else if (pick < area01_)
    axis = 1;
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  const bool low = u[1] < 0.5f;
  Vec3 p;
  p[axis] = low ? box.lo[axis] : box.hi[axis];
  p[i] = box.lo[i] + e[i] * u[2];
  p[j] = box.lo[j] + e[j] * u[3];
  // Cosine-weighted direction into the box.
  const float r = std::sqrt(u[4]), phi = 2.0f * std::numbers::pi_v<float> * u[5];
  Vec3 d;
  d[i] = r * std::cos(phi);
  d[j] = r * std::sin(phi);
  d[axis] = std::sqrt(std::max(0.0f, 1.0f - u[4])) * (low ? 1.0f : -1.0f);
  return Ray::make(p - d * reach_, d);
}

Ray sample_line(const Bbox& box, const float u[6]) {
  return LineSampler(box)(u);
}

}  // namespace amalgam

#include "amalgam/hierarchy/bake/lines.h"

namespace amalgam {

LineSampler::LineSampler(const Bbox& box) {
  const Vec3 e = box.extent();
  for (int a = 0; a < 3; ++a) lo_[a] = box.lo[a], hi_[a] = box.hi[a], e_[a] = e[a];
  const float area[3] = {e.y * e.z, e.z * e.x, e.x * e.y};
  area0_ = area[0];
  area01_ = area[0] + area[1];
  total_ = area[0] + area[1] + area[2];
  reach_ = std::max(box.diagonal(), 1e-30f) * 1.01f + 1e-30f;
}

Ray LineSampler::point(const float u[6]) const {
  const float z = 1.0f - 2.0f * u[4], r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * std::numbers::pi_v<float> * u[5];
  const Vec3 d{r * std::cos(phi), r * std::sin(phi), z};
  const Bbox box{{lo_[0], lo_[1], lo_[2]}, {hi_[0], hi_[1], hi_[2]}};
  return Ray::make(box.center() - d * reach_, d);
}

Ray sample_line(const Bbox& box, const float u[6]) {
  return LineSampler(box)(u);
}

}  // namespace amalgam

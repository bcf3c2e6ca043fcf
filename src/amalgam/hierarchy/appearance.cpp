#include "amalgam/hierarchy/appearance.h"

#include <algorithm>
#include <cmath>

namespace amalgam {

float directional_opacity(const Appearance& app, const Bbox& box, Vec3 dir) {
  const float a = app.opacity;
  if (app.shading == Shading::kFace || !(a > 0.0f)) return a;
  const float len = length(dir);
  if (!(len > 0.0f)) return a;
  const Vec3 d = dir / len;
  if (app.shading == Shading::kOriented && dot(app.normal, d) > 0.0f) return 0.0f;  // behind
  const Vec3 e = box.extent();
  const float quarter = 0.5f * (e.y * e.z + e.z * e.x + e.x * e.y);  // S(box) / 4
  const float proj =
      e.y * e.z * std::fabs(d.x) + e.z * e.x * std::fabs(d.y) + e.x * e.y * std::fabs(d.z);
  if (!(quarter > 0.0f) || !(proj > 0.0f)) return a;  // degenerate box: no better estimate
  const float contents =
      app.shading == Shading::kCloud ? 1.0f : 2.0f * std::fabs(dot(app.normal, d));
  return std::clamp(a * contents * quarter / proj, 0.0f, 1.0f);
}

}  // namespace amalgam

#include "amalgam/scene/framing.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace amalgam {
namespace {

/// `v` turned by the shortest rotation that takes +y to the direction of `up` (Rodrigues'
/// formula; half a turn about x when `up` points down). Identity for +y or a zero `up`.
Vec3 from_y_up(Vec3 v, Vec3 up) {
  const float len = length(up);
  if (!(len > 0.0f)) return v;
  const Vec3 u = up / len, y{0, 1, 0};
  const float c = dot(y, u);
  if (c < -0.9999f) return {v.x, -v.y, -v.z};
  const Vec3 k = cross(y, u);  // axis times sin
  return v * c + cross(k, v) + k * (dot(k, v) / (1.0f + c));
}

}  // namespace

Camera frame_camera(const Bbox& bounds, float vfov_deg, Vec3 up) {
  Camera c;
  c.vfov_deg = vfov_deg;
  const Vec3 centre = bounds.center();
  const float radius = std::max(0.5f * bounds.diagonal(), 1e-6f);
  // Azimuth 35 degrees right of +z, elevation 25 degrees.
  const float az = 35.0f * std::numbers::pi_v<float> / 180.0f;
  const float el = 25.0f * std::numbers::pi_v<float> / 180.0f;
  const Vec3 dir =
      from_y_up({std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)}, up);
  const float half = 0.5f * vfov_deg * std::numbers::pi_v<float> / 180.0f;
  c.position = centre + dir * (radius / std::sin(half));
  c.look_at = centre;
  c.up = length(up) > 0.0f ? up : Vec3{0, 1, 0};
  return c;
}

std::vector<Light> default_lights(const Bbox& bounds, const Camera& camera) {
  Light key;
  key.kind = LightKind::kDirectional;
  key.direction = normalize(from_y_up(Vec3{0.45f, -1.0f, -0.6f}, camera.up));
  key.intensity = {2.2f, 2.1f, 2.0f};
  Light fill;
  fill.kind = LightKind::kPoint;
  fill.position = camera.position;
  const float d = length(camera.position - bounds.center());
  const float e = 0.9f * d * d;  // irradiance 0.9 at the centre of the bounds
  fill.intensity = {e, e, e};
  return {key, fill};
}

}  // namespace amalgam

#include "amalgam/scene/framing.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace amalgam {

Camera frame_camera(const Bbox& bounds, float vfov_deg) {
  Camera c;
  c.vfov_deg = vfov_deg;
  const Vec3 centre = bounds.center();
  const float radius = std::max(0.5f * bounds.diagonal(), 1e-6f);
  // Azimuth 35 degrees right of +z, elevation 25 degrees.
  const float az = 35.0f * std::numbers::pi_v<float> / 180.0f;
  const float el = 25.0f * std::numbers::pi_v<float> / 180.0f;
  const Vec3 dir{std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
  const float half = 0.5f * vfov_deg * std::numbers::pi_v<float> / 180.0f;
  c.position = centre + dir * (radius / std::sin(half));
  c.look_at = centre;
  c.up = {0, 1, 0};
  return c;
}

std::vector<Light> default_lights(const Bbox& bounds, const Camera& camera) {
  Light key;
  key.kind = LightKind::kDirectional;
  key.direction = normalize(Vec3{0.45f, -1.0f, -0.6f});
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

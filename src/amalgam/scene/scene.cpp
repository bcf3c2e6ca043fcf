#include "amalgam/scene/scene.h"

#include <cmath>
#include <numbers>

namespace amalgam {

std::optional<SurfaceHit> intersect(const Primitive& prim, const Ray& ray) {
  switch (prim.kind) {
    case PrimKind::kTriangle:
      return intersect_triangle(ray, prim.a, prim.b, prim.c);
    case PrimKind::kSphere:
      return intersect_sphere(ray, prim.a, prim.radius);
    case PrimKind::kBox:
      return intersect_solid_box(ray, Bbox{prim.a, prim.b});
  }
  return std::nullopt;
}

Bbox bounds(const Primitive& prim) {
  Bbox b;
  switch (prim.kind) {
    case PrimKind::kTriangle:
      b.extend(prim.a), b.extend(prim.b), b.extend(prim.c);
      break;
    case PrimKind::kSphere:
      b = Bbox{prim.a - Vec3{prim.radius, prim.radius, prim.radius},
               prim.a + Vec3{prim.radius, prim.radius, prim.radius}};
      break;
    case PrimKind::kBox:
      b = Bbox{prim.a, prim.b};
      break;
  }
  return b;
}

Ray Camera::generate(float fx, float fy, int width, int height) const {
  const Vec3 w = normalize(look_at - position);
  const Vec3 u = normalize(cross(w, up));
  const Vec3 v = cross(u, w);
  const float tan_half = std::tan(vfov_deg * std::numbers::pi_v<float> / 360.0f);
  const float pixel = 2.0f * tan_half / static_cast<float>(height);  // film units per pixel
  const float sx = (fx - 0.5f * width) * pixel;
  const float sy = (0.5f * height - fy) * pixel;
  const Vec3 d = w + u * sx + v * sy;
  const float len = length(d);
  Ray r = Ray::make(position, d / len);
  // Angular size of one pixel along this ray (smaller off-axis by the cosine).
  r.cone_spread = pixel / len;
  r.cone_width = 0.0f;
  return r;
}

Vec3 Environment::seen_toward(Vec3 dir) const {
  for (const Light& l : lights)
    if (l.kind == LightKind::kSky) {
      if (!sky_map) return l.intensity;
      const Vec3 m = sky_map->radiance(dir);
      return {l.intensity.x * m.x, l.intensity.y * m.y, l.intensity.z * m.z};
    }
  return background;
}

}  // namespace amalgam

#include "amalgam/geometry/intersect.h"

#include <cmath>
#include <limits>
#include <utility>

namespace amalgam {
namespace {

bool slab(const Ray& ray, const Bbox& box, float& t_near, float& t_far, int& near_axis) {
  return detail::slab<true>(ray, box, t_near, t_far, near_axis);
}

}  // namespace

SurfaceHit box_face_hit(const Ray& ray, float t, int axis, float plane) {
  SurfaceHit s;
  s.t = t;
  s.p = ray.at(t);
  s.p_error = (abs(ray.origin) + abs(ray.dir * t)) * gamma(3);
  s.p[axis] = plane;
  s.p_error[axis] = 0.0f;
  s.normal = Vec3{};
  s.normal[axis] = ray.dir[axis] > 0 ? -1.0f : 1.0f;
  return s;
}

Vec3 offset_ray_origin(Vec3 p, Vec3 p_error, Vec3 n) {
  const float d = dot(abs(n), p_error);
  const Vec3 offset = n * d;
  Vec3 po = p + offset;
  for (int i = 0; i < 3; ++i) {
    if (n[i] > 0)
      po[i] = std::nextafter(po[i], kInfinity);
    else if (n[i] < 0)
      po[i] = std::nextafter(po[i], -kInfinity);
  }
  return po;
}

SurfaceHit box_entry_hit(const Ray& ray, const Bbox& box, float t) {
  float t_near, t_far;
  int axis;
  slab(ray, box, t_near, t_far, axis);
  if (ray.dir[axis] == 0.0f) {  // degenerate: origin inside; pick the dominant axis
    const Vec3 ad = abs(ray.dir);
    axis = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  }
  SurfaceHit s = box_face_hit(ray, t, axis, ray.dir[axis] > 0 ? box.lo[axis] : box.hi[axis]);
  if (t > t_near) {  // origin inside the box: not on a face; keep the unsnapped point
    s.p = ray.at(t);
    s.p_error = (abs(ray.origin) + abs(ray.dir * t)) * gamma(3);
  }
  return s;
}

std::optional<SurfaceHit> intersect_solid_box(const Ray& ray, const Bbox& box) {
  float t_near, t_far;
  int axis;
  if (!slab(ray, box, t_near, t_far, axis)) return std::nullopt;
  if (t_near >= ray.tmin && t_near <= ray.tmax)
    return box_face_hit(ray, t_near, axis, ray.dir[axis] > 0 ? box.lo[axis] : box.hi[axis]);
  if (t_near < ray.tmin && t_far >= ray.tmin && t_far <= ray.tmax) {
    // Origin inside: the ray leaves through a face; report its normal facing the ray.
    const Vec3 p = ray.at(t_far);
    int best = 0;
    float best_d = kInfinity;
    for (int a = 0; a < 3; ++a) {
      const float d = std::min(std::fabs(p[a] - box.lo[a]), std::fabs(p[a] - box.hi[a]));
      if (ray.dir[a] != 0.0f && d < best_d) best_d = d, best = a;
    }
    SurfaceHit s = box_face_hit(ray, t_far, best, ray.dir[best] > 0 ? box.hi[best] : box.lo[best]);
    s.normal[best] = ray.dir[best] > 0 ? -1.0f : 1.0f;  // facing the ray
    return s;
  }
  return std::nullopt;
}

std::optional<SurfaceHit> intersect_triangle(const Ray& ray, Vec3 a, Vec3 b, Vec3 c) {
  TriangleCandidate h;
  if (!triangle_test(ray, TrianglePre::of(ray), a, b, c, h)) return std::nullopt;
  return triangle_finish(ray, a, b, c, h);
}

Vec3 detail::triangle_normal_double(Vec3 a, Vec3 b, Vec3 c) {
  const double ex = double(b.x) - a.x, ey = double(b.y) - a.y, ez = double(b.z) - a.z;
  const double fx = double(c.x) - a.x, fy = double(c.y) - a.y, fz = double(c.z) - a.z;
  const double nx = ey * fz - ez * fy, ny = ez * fx - ex * fz, nz = ex * fy - ey * fx;
  const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
  return len > 0.0 ? Vec3{float(nx / len), float(ny / len), float(nz / len)} : Vec3{};
}

std::optional<SurfaceHit> intersect_sphere(const Ray& ray, Vec3 center, float radius) {
  const Vec3 f = ray.origin - center;
  const float a = dot(ray.dir, ray.dir);
  const float b = -dot(f, ray.dir);
  // l: from the centre to the point of the line closest to it. Its length decides the hit
  // far more accurately than the textbook discriminant when the origin is far away.
  const Vec3 l = f + ray.dir * (b / a);
  const float disc = radius * radius - dot(l, l);
  if (disc < 0.0f) return std::nullopt;
  const float c = dot(f, f) - radius * radius;
  const float q = b + std::copysign(std::sqrt(a * disc), b);
  float t0 = q != 0.0f ? c / q : 0.0f;
  float t1 = q / a;
  if (t0 > t1) std::swap(t0, t1);
  float t = t0;
  bool near = true;
  if (t < ray.tmin) t = t1, near = false;
  if (!(t >= ray.tmin && t <= ray.tmax)) return std::nullopt;
  // The hit relative to the centre, l -/+ (unit d) sqrt(disc): no cancellation against the
  // ray origin; then reprojected onto the sphere.
  const float inv_len = 1.0f / std::sqrt(a);
  Vec3 v = l + ray.dir * (inv_len * (near ? -std::sqrt(disc) : std::sqrt(disc)));
  const float vlen = length(v);
  const Vec3 outward = vlen > 0.0f ? v / vlen : -ray.dir * inv_len;
  const Vec3 p = center + outward * radius;
  Vec3 n = outward;
  if (dot(n, ray.dir) > 0) n = -n;
  return SurfaceHit{t, n, p, abs(p) * gamma(5)};
}

}  // namespace amalgam

#include "amalgam/geometry/intersect.h"

#include <cmath>
#include <limits>
#include <utility>

namespace amalgam {
namespace {

/// Unclamped slab interval [t_near, t_far] of the infinite line, with the index of the axis
/// that produced t_near (the entry face). Returns false when the line misses the box.
bool slab(const Ray& ray, const Bbox& box, float& t_near, float& t_far, int& near_axis) {
  t_near = -kInfinity;
  t_far = kInfinity;
  near_axis = 0;
  for (int a = 0; a < 3; ++a) {
    const float o = ray.origin[a];
    if (ray.dir[a] == 0.0f) {
      if (o < box.lo[a] || o > box.hi[a]) return false;
      continue;
    }
    float t0 = (box.lo[a] - o) * ray.inv_dir[a];
    float t1 = (box.hi[a] - o) * ray.inv_dir[a];
    if (t0 > t1) std::swap(t0, t1);
    t1 *= 1.0f + 2.0f * gamma(3);  // Ize 2013: never lose a hit through an edge or a corner.
    if (t0 > t_near) t_near = t0, near_axis = a;
    if (t1 < t_far) t_far = t1;
  }
  return t_near <= t_far;
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

std::optional<Span> intersect_box(const Ray& ray, const Bbox& box) {
  float t_near, t_far;
  int axis;
  if (!slab(ray, box, t_near, t_far, axis)) return std::nullopt;
  const float t0 = std::max(t_near, ray.tmin);
  const float t1 = std::min(t_far, ray.tmax);
  if (t0 > t1) return std::nullopt;
  return Span{t0, t1};
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
  // Woop, Benthin, Wald 2013. Permute so that z is the dominant direction axis.
  const Vec3 ad = abs(ray.dir);
  int kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  if (ray.dir[kz] < 0.0f) std::swap(kx, ky);
  const float sx = ray.dir[kx] / ray.dir[kz];
  const float sy = ray.dir[ky] / ray.dir[kz];
  const float sz = 1.0f / ray.dir[kz];
  const Vec3 A = a - ray.origin, B = b - ray.origin, C = c - ray.origin;
  const float ax = A[kx] - sx * A[kz], ay = A[ky] - sy * A[kz];
  const float bx = B[kx] - sx * B[kz], by = B[ky] - sy * B[kz];
  const float cx = C[kx] - sx * C[kz], cy = C[ky] - sy * C[kz];
  float u = cx * by - cy * bx;
  float v = ax * cy - ay * cx;
  float w = bx * ay - by * ax;
  if (u == 0.0f || v == 0.0f || w == 0.0f) {  // Edge case: redo in double precision.
    u = static_cast<float>(double(cx) * by - double(cy) * bx);
    v = static_cast<float>(double(ax) * cy - double(ay) * cx);
    w = static_cast<float>(double(bx) * ay - double(by) * ax);
  }
  if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return std::nullopt;
  const float det = u + v + w;
  if (det == 0.0f) return std::nullopt;
  const float az = sz * A[kz], bz = sz * B[kz], cz = sz * C[kz];
  const float t = (u * az + v * bz + w * cz) / det;
  if (!(t >= ray.tmin && t <= ray.tmax)) return std::nullopt;
  Vec3 n = normalize(cross(b - a, c - a));
  if (dot(n, ray.dir) > 0) n = -n;
  // Barycentric reconstruction: the error depends on the vertices, not on the ray origin.
  const float inv = 1.0f / det;
  const Vec3 p = a * (u * inv) + b * (v * inv) + c * (w * inv);
  const Vec3 err = (abs(a * (u * inv)) + abs(b * (v * inv)) + abs(c * (w * inv))) * gamma(7);
  return SurfaceHit{t, n, p, err};
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

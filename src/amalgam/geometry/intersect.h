#pragma once
/// \file Ray/object intersection kernels (scalar reference versions).
///
/// Each kernel is one "intersection test" in the paper's sense; the traversal counts calls.
/// The box test is inline (it is called once per box in the traversal's inner loop); the
/// triangle test is split into a per-ray setup (`TrianglePre`), the test proper
/// (`triangle_test`: t and the scaled barycentrics only) and `triangle_finish` (normal, point,
/// error bound), so a traversal can set up once per ray and finish only the closest hit.
/// `intersect_triangle` is the three in sequence: the results are bit-identical either way.

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "amalgam/geometry/bbox.h"

namespace amalgam {

/// The parameter interval over which a ray is inside a box.
struct Span {
  float t0, t1;
};

/// Ray/box slab test, robust in the sense of Ize, "Robust BVH Ray Traversal" (JCGT 2013):
/// the far distance is enlarged by 2 gamma(3) so that rounding never loses a hit through an
/// edge or a corner. Axis-parallel rays whose origin lies on a slab plane count as inside.
/// Returns the overlap of [ray.tmin, ray.tmax] with the box, or nothing.
inline std::optional<Span> intersect_box(const Ray& ray, const Bbox& box);

/// A surface hit: parameter, geometric normal (unit length, facing against the ray), the
/// hit point and a per-component bound on its absolute rounding error (for offsetting
/// secondary-ray origins without a fixed epsilon). On a triangle (a, b, c), `b1` and `b2` are
/// the barycentric weights of b and c from the counted test (texture coordinates are
/// interpolated with them); 0 on other primitives.
struct SurfaceHit {
  float t;
  Vec3 normal;
  Vec3 p;
  Vec3 p_error;
  float b1 = 0.0f, b2 = 0.0f;
};

/// gamma(n) of Pharr, Jakob, Humphreys (pbrt 3, section 3.9.1): bounds n rounding errors.
constexpr float gamma(int n) {
  constexpr float eps = 0x1.0p-24f;
  return (n * eps) / (1 - n * eps);
}

/// Point o + t d, with its coordinate on axis `axis` snapped to `plane` (exact) and the
/// error bound of the rest. Used for hits on axis-aligned box faces.
SurfaceHit box_face_hit(const Ray& ray, float t, int axis, float plane);

/// A ray origin just off the surface at `p` on the side of `n`: moved along n by the error
/// bound projected on n, then one more float step, so rounding can never place it behind
/// the surface (pbrt 3, section 3.9.5).
Vec3 offset_ray_origin(Vec3 p, Vec3 p_error, Vec3 n);

/// Watertight ray/triangle test (Woop, Benthin, Wald, "Watertight Ray/Triangle Intersection",
/// JCGT 2013): a ray through a shared edge or vertex hits at least one of the triangles.
std::optional<SurfaceHit> intersect_triangle(const Ray& ray, Vec3 a, Vec3 b, Vec3 c);

/// The per-ray part of the watertight test: the axis permutation (z the dominant direction
/// axis) and the shear constants (Woop et al. 2013, section 3).
struct TrianglePre {
  int kx, ky, kz;
  float sx, sy, sz;
  [[gnu::always_inline]] static TrianglePre of(const Ray& ray) {
    const Vec3 ad = abs(ray.dir);
    TrianglePre p;
    p.kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
    p.kx = (p.kz + 1) % 3, p.ky = (p.kx + 1) % 3;
    if (ray.dir[p.kz] < 0.0f) std::swap(p.kx, p.ky);
    p.sx = ray.dir[p.kx] / ray.dir[p.kz];
    p.sy = ray.dir[p.ky] / ray.dir[p.kz];
    p.sz = 1.0f / ray.dir[p.kz];
    return p;
  }
};

/// An accepted triangle hit before finishing: t and the unnormalised barycentrics.
struct TriangleCandidate {
  float t, u, v, w, det;
};

/// A conservative bound on the rounding error of the t that `triangle_test` computes: from
/// the sheared vertices (x, y), their coordinates along the ray's dominant axis before (z)
/// and after (sz * z) scaling, the edge functions u, v, w and their sum det. The error terms
/// are those of Pharr, Jakob, Humphreys, pbrt 3, section 3.9.6 (the shear, the edge functions,
/// their weighted sum), except that the shear's term uses the unscaled z: the shear adds
/// sx * z with |sx| <= 1, so its size is |z|, not |sz * z| (which grows without bound as the
/// direction shrinks: a ray of direction length 1e-15 would reject every hit). A hit at t at or
/// below the bound may lie behind the ray's origin: a shadow ray leaving a triangle whose
/// point error is zero along its normal (a plane at coordinate 0) would otherwise meet it again.
///
/// A triangle wholly ahead of the origin along the dominant axis (every z of the sign of sz;
/// exact: a - origin and 1 / d keep their signs) has every point at t > 0, and the computed t,
/// a mean of sz z weighted by edge functions of one sign, is >= 0: the bound is then 0 (only
/// t = 0, an underflow, is rejected). The bound proper grows with the triangle's distance
/// (max_z) although that part of it overstates the error of a weighted mean, which stays
/// within the spread of the three sz z: a small triangle far away had a bound above its t and
/// was never hit (a 1 mm triangle of scenes/demo-field-fine.json 240 m from the camera).
inline float triangle_t_error(float ax, float ay, float bx, float by, float cx, float cy, float az,
                              float bz, float cz, float sz, float u, float v, float w, float det) {
  if (sz > 0.0f ? (az > 0.0f && bz > 0.0f && cz > 0.0f) : (az < 0.0f && bz < 0.0f && cz < 0.0f))
    return 0.0f;
  const float max_x = std::max(std::max(std::fabs(ax), std::fabs(bx)), std::fabs(cx));
  const float max_y = std::max(std::max(std::fabs(ay), std::fabs(by)), std::fabs(cy));
  const float max_z = std::max(std::max(std::fabs(az), std::fabs(bz)), std::fabs(cz));
  const float max_zs = max_z * std::fabs(sz);
  const float max_e = std::max(std::max(std::fabs(u), std::fabs(v)), std::fabs(w));
  const float dz = gamma(3) * max_zs;
  const float dx = gamma(5) * (max_x + max_z);
  const float dy = gamma(5) * (max_y + max_z);
  const float de = 2.0f * (gamma(2) * max_x * max_y + dy * max_x + dx * max_y);
  return 3.0f * (gamma(3) * max_e * max_zs + de * max_zs + dz * max_e) * std::fabs(1.0f / det);
}

/// The watertight test proper over [ray.tmin, ray.tmax]; fills `out` on a hit. A hit within
/// the rounding error of t of the origin is rejected (`triangle_t_error`), unless the whole
/// triangle is ahead of the origin.
inline bool triangle_test(const Ray& ray, const TrianglePre& p, Vec3 a, Vec3 b, Vec3 c,
                          TriangleCandidate& out) {
  // Arrays rather than Vec3::operator[] (a chain of selects): one indexed load each.
  const Vec3 a0 = a - ray.origin, b0 = b - ray.origin, c0 = c - ray.origin;
  const float A[3] = {a0.x, a0.y, a0.z}, B[3] = {b0.x, b0.y, b0.z}, C[3] = {c0.x, c0.y, c0.z};
  const float ax = A[p.kx] - p.sx * A[p.kz], ay = A[p.ky] - p.sy * A[p.kz];
  const float bx = B[p.kx] - p.sx * B[p.kz], by = B[p.ky] - p.sy * B[p.kz];
  const float cx = C[p.kx] - p.sx * C[p.kz], cy = C[p.ky] - p.sy * C[p.kz];
  float u = cx * by - cy * bx;
  float v = ax * cy - ay * cx;
  float w = bx * ay - by * ax;
  if (u == 0.0f || v == 0.0f || w == 0.0f) [[unlikely]] {  // edge case: double precision
    u = static_cast<float>(double(cx) * by - double(cy) * bx);
    v = static_cast<float>(double(ax) * cy - double(ay) * cx);
    w = static_cast<float>(double(bx) * ay - double(by) * ax);
  }
  if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return false;
  const float det = u + v + w;
  if (det == 0.0f) return false;
  const float az = p.sz * A[p.kz], bz = p.sz * B[p.kz], cz = p.sz * C[p.kz];
  const float t = (u * az + v * bz + w * cz) / det;
  if (!(t >= ray.tmin && t <= ray.tmax)) return false;
  if (t <= triangle_t_error(ax, ay, bx, by, cx, cy, A[p.kz], B[p.kz], C[p.kz], p.sz, u, v, w, det))
    return false;
  out = {t, u, v, w, det};
  return true;
}

namespace detail {
/// `triangle_normal` in double precision (squared lengths beyond float's range).
Vec3 triangle_normal_double(Vec3 a, Vec3 b, Vec3 c);
}  // namespace detail

/// The unit normal of triangle (a, b, c), (b - a) x (c - a) normalised (in double precision
/// when its squared length would overflow or underflow in float); zero for a degenerate one.
/// `triangle_finish` turns it to face the ray. Inline, with `triangle_finish`: once per ray's
/// closest hit, where a call's argument spills and the square root's latency showed (issue 14).
inline Vec3 triangle_normal(Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 n = cross(b - a, c - a);
  const float l2 = dot(n, n);
  // The squared length overflows for edges beyond about 1e12 and underflows below about 1e-13.
  if (l2 > 0x1.0p-100f && l2 < 0x1.0p100f) [[likely]]
    return n / std::sqrt(l2);
  return detail::triangle_normal_double(a, b, c);
}

/// The full hit of a candidate from `triangle_test` on the same ray and triangle.
inline SurfaceHit triangle_finish(const Ray& ray, Vec3 a, Vec3 b, Vec3 c,
                                  const TriangleCandidate& h) {
  Vec3 n = triangle_normal(a, b, c);
  if (dot(n, ray.dir) > 0) n = -n;
  // Barycentric reconstruction: the error depends on the vertices, not on the ray origin.
  const float inv = 1.0f / h.det;
  const float u = h.u, v = h.v, w = h.w;
  const Vec3 p = a * (u * inv) + b * (v * inv) + c * (w * inv);
  const Vec3 err = (abs(a * (u * inv)) + abs(b * (v * inv)) + abs(c * (w * inv))) * gamma(7);
  return SurfaceHit{h.t, n, p, err, v * inv, w * inv};
}

/// Ray/sphere test with the numerically careful quadratic (Hearn & Baker form).
std::optional<SurfaceHit> intersect_sphere(const Ray& ray, Vec3 center, float radius);

/// Ray/solid-box test: the first crossing of the box surface in [tmin, tmax] (the entry face,
/// or the exit face when the origin is inside).
std::optional<SurfaceHit> intersect_solid_box(const Ray& ray, const Bbox& box);

/// The hit where the ray enters a box at parameter t (from intersect_box): the point snapped
/// onto the entry face, and that face's normal (facing the ray).
SurfaceHit box_entry_hit(const Ray& ray, const Bbox& box, float t);

namespace detail {

/// Unclamped slab interval [t_near, t_far] of the infinite line (Ize 2013: t_far enlarged by
/// 2 gamma(3)); false when the line misses the box. `near_axis`: the axis of t_near.
template <bool kAxis>
inline bool slab(const Ray& ray, const Bbox& box, float& t_near, float& t_far, int& near_axis) {
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
    if (t0 > t_near) {
      t_near = t0;
      if constexpr (kAxis) near_axis = a;
    }
    if (t1 < t_far) t_far = t1;
  }
  return t_near <= t_far;
}

}  // namespace detail

/// `intersect_box` without std::optional: true and [t0, t1] on a hit.
inline bool intersect_box(const Ray& ray, const Bbox& box, float& t0, float& t1) {
  float t_near, t_far;
  int axis;
  if (!detail::slab<false>(ray, box, t_near, t_far, axis)) return false;
  // tmin on a tie: with tmin = +0 an entry of -0 becomes +0, as the SIMD kernels' integer
  // maximum gives it (wide_kernels.h).
  t0 = t_near > ray.tmin ? t_near : ray.tmin;
  t1 = std::min(t_far, ray.tmax);
  return t0 <= t1;
}

inline std::optional<Span> intersect_box(const Ray& ray, const Bbox& box) {
  float t0, t1;
  if (!intersect_box(ray, box, t0, t1)) return std::nullopt;
  return Span{t0, t1};
}

}  // namespace amalgam

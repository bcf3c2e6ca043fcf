#pragma once
/// \file Ray/object intersection kernels (scalar reference versions).
///
/// Each kernel is one "intersection test" in the paper's sense; the traversal counts calls.

#include <optional>

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
std::optional<Span> intersect_box(const Ray& ray, const Bbox& box);

/// A surface hit: parameter, geometric normal (unit length, facing against the ray), the
/// hit point and a per-component bound on its absolute rounding error (for offsetting
/// secondary-ray origins without a fixed epsilon).
struct SurfaceHit {
  float t;
  Vec3 normal;
  Vec3 p;
  Vec3 p_error;
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

/// Ray/sphere test with the numerically careful quadratic (Hearn & Baker form).
std::optional<SurfaceHit> intersect_sphere(const Ray& ray, Vec3 center, float radius);

/// Ray/solid-box test: the first crossing of the box surface in [tmin, tmax] (the entry face,
/// or the exit face when the origin is inside).
std::optional<SurfaceHit> intersect_solid_box(const Ray& ray, const Bbox& box);

/// The hit where the ray enters a box at parameter t (from intersect_box): the point snapped
/// onto the entry face, and that face's normal (facing the ray).
SurfaceHit box_entry_hit(const Ray& ray, const Bbox& box, float t);

}  // namespace amalgam

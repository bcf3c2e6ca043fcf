#pragma once
/// \file Local shading: Lambertian diffuse plus a normalised Blinn-Phong lobe.

#include <numbers>

#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/scene/scene.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// Reflected radiance factor for light arriving from `wi`, seen from `wo` (both unit, pointing
/// away from the surface), with shading normal `n`.
inline Vec3 brdf(const Surface& s, Vec3 n, Vec3 wi, Vec3 wo) {
  constexpr float inv_pi = std::numbers::inv_pi_v<float>;
  Vec3 f = s.colour * inv_pi;
  if (s.reflectance > 0.0f) {
    const Vec3 h = normalize(wi + wo);
    const float c = std::max(0.0f, dot(n, h));
    const float spec =
        s.reflectance * (s.shininess + 8.0f) * (inv_pi / 8.0f) * std::pow(c, s.shininess);
    f += Vec3{spec, spec, spec};
  }
  return f;
}

/// The surface of primitive `id` of `h` at hit `s` (found by the counted test): textured
/// where the hierarchy has textures (`surface_at`), else the primitive's material.
template <Hierarchy H>
inline Surface surface_at(const H& h, PrimId id, const SurfaceHit& s) {
  if constexpr (requires { h.surface_at(id, s); }) {
    return h.surface_at(id, s);
  } else {
    return h.surface(id);
  }
}

/// The normal to shade hit `s` on primitive `id` of `h` with, facing the viewer direction
/// `wo`: the hierarchy's interpolated vertex normal where it has one (`shading_normal`), else
/// the geometric normal. A vertex normal is first put on the viewer's side of the geometric
/// normal; where it still faces away from `wo` (near a silhouette, where interpolation and the
/// facets disagree) the geometric normal is used.
template <Hierarchy H>
inline Vec3 surface_normal(const H& h, PrimId id, const SurfaceHit& s, Vec3 wo) {
  const Vec3 ng = dot(s.normal, wo) < 0 ? -s.normal : s.normal;
  if constexpr (requires { h.shading_normal(id, s); }) {
    Vec3 n = h.shading_normal(id, s);
    if (dot(n, ng) < 0) n = -n;
    return dot(n, wo) > 0 ? n : ng;
  } else {
    return ng;
  }
}

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file Sampling a light from a shading point: the direction and distance of one shadow ray,
/// the light it brings if unoccluded, and the width its cone should reach at the light.
///
/// A point or directional light without size gives one sample, exactly as it always has. A
/// sized light (scene/scene.h) is sampled by solid angle, uniformly over the cone of
/// directions under which it is seen; with n samples each carries 1/n of it:
/// - sphere (centre c, radius r, radiance L = I / (pi r^2)), seen from p at distance d > r
///   within the cone of half-angle asin(r / d): weight L * 2 pi (1 - cos) / n, the exact
///   irradiance of a uniform sphere (I / d^2 for a point facing it) in expectation;
/// - disc of angular diameter a about -direction (a sun): weight E / n.
/// Each shadow ray answers for 1/n of the light's solid angle, so its cone widens from the
/// pixel's footprint to the light's width / sqrt(n) at the light: the shadow rays of a soft
/// shadow see occluders as coarse as the penumbra they blur. The sky has no such width: its
/// shadow rays keep the footprint's (sample_sky).

#include <algorithm>
#include <cmath>
#include <numbers>

#include "amalgam/geometry/ray.h"
#include "amalgam/scene/scene.h"
#include "amalgam/scene/sky.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

struct LightSample {
  Vec3 wi;                 ///< unit direction toward the light
  float dist = 0.0f;       ///< distance to the light along wi (infinity: directional)
  Vec3 e;                  ///< light arriving (irradiance normal to wi), this sample's share
  float end_width = 0.0f;  ///< sphere: the width the shadow ray's cone should have at it
  float spread = 0.0f;     ///< disc (directional): the cone's widening per unit distance
};

/// A direction uniformly distributed in the cone of half-angle acos(cos_max) about unit `w`.
inline Vec3 in_cone(Vec3 w, float cos_max, float u1, float u2) {
  const float c = 1.0f - u1 * (1.0f - cos_max);
  const float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
  const float phi = 2.0f * std::numbers::pi_v<float> * u2;
  Vec3 a, b;
  perpendiculars(w, a, b);
  return normalize(a * (s * std::cos(phi)) + b * (s * std::sin(phi)) + w * c);
}

/// Distance along unit `dir` from `p` to the near surface of the sphere (c, r); negative when
/// the line misses it.
inline float to_sphere(Vec3 p, Vec3 dir, Vec3 c, float r) {
  const Vec3 oc = c - p;
  const float tc = dot(oc, dir);
  const float h2 = dot(oc, oc) - tc * tc;
  const float r2 = r * r;
  if (h2 > r2) return -1.0f;
  return tc - std::sqrt(r2 - h2);
}

/// Sample `u1`, `u2` (in [0, 1)) of a sized light seen from `p`, one of `n`. False when `p` is
/// inside a sphere light (it is not lit then).
inline bool sample_sized_light(const Light& l, Vec3 p, float u1, float u2, int n, LightSample& s) {
  constexpr float pi = std::numbers::pi_v<float>;
  const float share = 1.0f / static_cast<float>(std::max(n, 1));
  const float root = std::sqrt(share);
  if (l.kind == LightKind::kDirectional) {
    const float half = 0.5f * l.angle;
    s.wi = in_cone(-normalize(l.direction), std::cos(half), u1, u2);
    s.dist = kInfinity;
    s.e = l.intensity * share;
    s.spread = 2.0f * std::tan(half) * root;
    return true;
  }
  const Vec3 oc = l.position - p;
  const float d = length(oc);
  if (!(d > l.radius)) return false;
  const float sin_max = l.radius / d;
  const float cos_max = std::sqrt(std::max(0.0f, 1.0f - sin_max * sin_max));
  s.wi = in_cone(oc / d, cos_max, u1, u2);
  s.dist = std::max(0.0f, to_sphere(p, s.wi, l.position, l.radius));
  if (!(s.dist > 0.0f)) s.dist = d - l.radius;  // rounding at the cone's rim
  const float radiance_scale = 1.0f / (pi * l.radius * l.radius);
  s.e = l.intensity * (radiance_scale * 2.0f * pi * (1.0f - cos_max) * share);
  s.end_width = 2.0f * l.radius * root;
  return true;
}

/// Point and spot lights: at a position, their light falling off with the square distance.
inline bool is_positional(const Light& l) {
  return l.kind == LightKind::kPoint || l.kind == LightKind::kSpot;
}

/// A spot light's share of its axial intensity toward unit `wi` (from the shaded point toward
/// the light): glTF's falloff, ((cos - cos_outer) / (cos_inner - cos_outer))^2 in [0, 1].
inline float spot_falloff(const Light& l, Vec3 wi) {
  const float c = -dot(wi, l.direction);
  if (!(l.cos_inner > l.cos_outer)) return c >= l.cos_outer ? 1.0f : 0.0f;
  const float t = std::clamp((c - l.cos_outer) / (l.cos_inner - l.cos_outer), 0.0f, 1.0f);
  return t * t;
}

/// Sample (u1, u2) of the sky `l` (scene/scene.h), one of `n`, seen from a point with unit
/// shading normal `normal` (or the zero vector: no preferred side). With a map: a direction
/// drawn by the map's luminance (scene/sky.h); without, a constant radiance: cosine-weighted
/// about the normal (uniform over the sphere without one). The sample carries radiance /
/// (density x n), so that brdf x e x cos sums to the irradiance-weighted estimate. Its shadow
/// ray is a parallel beam of the footprint's width (spread 0), whatever n: a cone as wide as the
/// sample's share of the sky would read occluders at a level set by the sample count (a
/// hemisphere at n = 2 reads the coarsest cells), and cells read at different levels do not
/// have the same mean transmittance, so the image's mean would depend on n.
inline bool sample_sky(const Light& l, const SkyMap* map, Vec3 normal, float u1, float u2, int n,
                       LightSample& s) {
  constexpr float pi = std::numbers::pi_v<float>;
  const float share = 1.0f / static_cast<float>(std::max(n, 1));
  s.dist = kInfinity;
  s.spread = 0.0f;
  if (map != nullptr) {
    const SkyMap::Sample m = map->sample(u1, u2);
    if (!(m.pdf > 0.0f)) return false;
    s.wi = m.dir;
    s.e = l.intensity * m.radiance * (share / m.pdf);
    return true;
  }
  if (normal == Vec3{}) {  // uniform over the sphere: density 1 / (4 pi)
    const float z = 1.0f - 2.0f * u1, r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * pi * u2;
    s.wi = {r * std::cos(phi), z, r * std::sin(phi)};
    s.e = l.intensity * (4.0f * pi * share);
    return true;
  }
  // Cosine-weighted: density cos / pi, so radiance x pi / (cos n).
  const float r = std::sqrt(u1), phi = 2.0f * pi * u2;
  const float c = std::sqrt(std::max(0.0f, 1.0f - u1));
  if (!(c > 0.0f)) return false;
  Vec3 a, b;
  perpendiculars(normal, a, b);
  s.wi = normalize(a * (r * std::cos(phi)) + b * (r * std::sin(phi)) + normal * c);
  s.e = l.intensity * (pi * share / c);
  return true;
}

/// One light sample seen from `p` (shading normal `normal`, used by the sky only): sized
/// lights and the sky from (u1, u2), one of `n`; a point, spot or directional light without
/// size exactly (u1, u2 unused). False when it brings nothing.
inline bool sample_light(const Light& l, const SkyMap* map, Vec3 p, Vec3 normal, int n, float u1,
                         float u2, LightSample& s) {
  if (l.kind == LightKind::kSky) return sample_sky(l, map, normal, u1, u2, n, s);
  if (l.sized()) return sample_sized_light(l, p, u1, u2, n, s);
  if (is_positional(l)) {
    const Vec3 d = l.position - p;
    s.dist = length(d);
    if (!(s.dist > 0.0f)) return false;
    s.wi = d / s.dist;
    s.e = l.intensity / (s.dist * s.dist);
    if (l.kind == LightKind::kSpot) {
      const float f = spot_falloff(l, s.wi);
      if (!(f > 0.0f)) return false;
      s.e = s.e * f;
    }
    return true;
  }
  s.wi = -normalize(l.direction);
  s.dist = kInfinity;
  s.e = l.intensity;
  return true;
}

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file Direct lighting with shadow rays: the paper's setting (no mirror or refraction rays).
///
/// One primary sample: find the closest hit (a primitive, or a rendered amalgam), light it
/// from every light with one shadow ray each. Under deterministic opacity, every rendered
/// translucent amalgam in front of the hit is also shaded (with its own shadow ray per light)
/// and blended front to back: C = sum_k T_k a_k L_k + T_n L_hit, T_k = prod_{j<k} (1 - a_j).

#include <algorithm>
#include <vector>

#include "amalgam/render/shading.h"
#include "amalgam/traverse/traverse.h"

namespace amalgam {

struct SampleResult {
  Vec3 colour;
  TraceHit hit;
};

template <Hierarchy H, class Lod, OpacityModel kOpacity, bool kSorted, class Stats = Counters>
class Integrator {
 public:
  Integrator(const H& h, const Environment& env, const Lod& lod, Stats& counters)
      : h_(h), env_(env), trav_(h, lod, counters) {}

  /// Radiance along `primary`; `key` derives every random decision of this sample.
  SampleResult li(const Ray& primary, std::uint64_t key) {
    translucent_.clear();
    const TraceHit hit = trav_.intersect(primary, hash_combine(key, 0),
                                         kOpacity == OpacityModel::kDeterministic
                                             ? &translucent_
                                             : nullptr);
    std::uint64_t shadow_stream = 1;
    Vec3 colour{};
    float through = 1.0f;
    if constexpr (kOpacity == OpacityModel::kDeterministic) {
      std::sort(translucent_.begin(), translucent_.end(), [](const auto& a, const auto& b) {
        return a.t < b.t || (a.t == b.t && a.id < b.id);
      });
      for (const TranslucentHit& a : translucent_) {
        const Appearance app = h_.appearance(a.id);
        colour += direct(primary, a.surf, shading_normal(app, a.surf), app.surface, key,
                         shadow_stream) *
                  (through * a.opacity);
        through *= 1.0f - a.opacity;
      }
    }
    Vec3 end = env_.background;
    if (hit.kind == TraceHit::Kind::kPrimitive) {
      end = direct(primary, hit.surf, hit.surf.normal, h_.surface(hit.id), key, shadow_stream);
    } else if (hit.kind == TraceHit::Kind::kAmalgam) {
      const Appearance app = h_.appearance(hit.id);
      end = direct(primary, hit.surf, shading_normal(app, hit.surf), app.surface, key,
                   shadow_stream);
    }
    colour += end * through;
    return {colour, hit};
  }

 private:
  static Vec3 shading_normal(const Appearance& app, const SurfaceHit& s) {
    return (app.normal == Vec3{}) ? s.normal : app.normal;
  }

  /// Light reflected toward the viewer at a hit, one shadow ray per light.
  Vec3 direct(const Ray& primary, const SurfaceHit& s, Vec3 n, const Surface& surf,
              std::uint64_t key, std::uint64_t& stream) {
    Vec3 sum{};
    const Vec3 wo = -primary.dir;
    if (dot(n, wo) < 0) n = -n;
    const Vec3 origin = offset_ray_origin(s.p, s.p_error, s.normal);
    for (const Light& light : env_.lights) {
      Vec3 wi;
      float dist;
      Vec3 e;
      if (light.kind == LightKind::kPoint) {
        const Vec3 d = light.position - origin;
        dist = length(d);
        if (!(dist > 0.0f)) continue;
        wi = d / dist;
        e = light.intensity / (dist * dist);
      } else {
        wi = -normalize(light.direction);
        dist = kInfinity;
        e = light.intensity;
      }
      const float cos = dot(n, wi);
      if (cos <= 0.0f || dot(s.normal, wi) <= 0.0f) continue;
      Ray shadow = Ray::make(origin, wi, 0.0f, dist * (1.0f - 2.0f * gamma(3)));
      shadow.cone_width = primary.footprint(s.t);
      shadow.cone_spread = primary.cone_spread;
      const float tr = trav_.transmittance(shadow, hash_combine(key, stream++));
      if (tr <= 0.0f) continue;
      sum += brdf(surf, n, wi, wo) * e * (cos * tr);
    }
    return sum;
  }

  const H& h_;
  const Environment& env_;
  Traversal<H, Lod, kOpacity, kSorted, Stats> trav_;
  std::vector<TranslucentHit> translucent_;
};

}  // namespace amalgam

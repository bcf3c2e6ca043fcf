#pragma once
/// \file Direct lighting with shadow rays: the paper's setting (no mirror or refraction rays).
///
/// One primary sample: find the closest hit (a primitive, or a rendered amalgam), light it
/// from every light with one shadow ray each. Under deterministic opacity, every rendered
/// translucent amalgam in front of the hit is also shaded (with its own shadow ray per light)
/// and blended front to back: C = sum_k T_k a_k L_k + T_n L_hit, T_k = prod_{j<k} (1 - a_j).

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "amalgam/render/lights.h"
#include "amalgam/render/shading.h"
#include "amalgam/traverse/traverse.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

struct SampleResult {
  Vec3 colour;
  TraceHit hit;
  /// Auxiliary outputs of the sample, blended front to back with the same weights as `colour`
  /// (a miss adds 0): the shading normal turned toward the viewer (for a cloud, the mean
  /// normal of its visible facets, which points at the viewer) and the diffuse colour of the
  /// surface shaded.
  Vec3 normal{};
  Vec3 albedo{};
};

/// `Tracer` finds hits: `intersect(ray, key, translucent*) -> TraceHit` and
/// `transmittance(ray, key) -> float`. It is amalgam's Traversal; the benchmarks substitute
/// Intel Embree (bench/field_bench.cpp) to render the same image with another ray tracer.
template <Hierarchy H, class Lod, class Opacity, class Order = SortedOrder, class Stats = Counters,
          class Tracer = Traversal<H, Lod, Opacity, Order, Stats>>
class Integrator {
 public:
  Integrator(const H& h, const Environment& env, const Lod& lod, Stats& counters)
      : h_(h), env_(env), trav_(h, lod, counters) {}
  Integrator(const H& h, const Environment& env, Tracer tracer)
      : h_(h), env_(env), trav_(std::move(tracer)) {}

  /// Radiance along `primary`; `key` derives every random decision of this sample.
  SampleResult li(const Ray& primary, std::uint64_t key) {
    translucent_.clear();
    const TraceHit hit =
        trav_.intersect(primary, hash_combine(key, 0), Opacity::kBlends ? &translucent_ : nullptr);
    if constexpr (Opacity::kSaturates) return li_composite(primary, key, hit);
    std::uint64_t shadow_stream = 1;
    SampleResult r{{}, hit};
    const Vec3 wo = -primary.dir;
    float through = 1.0f;
    if constexpr (Opacity::kBlends) {
      sort_front_to_back();
      for (const TranslucentHit& a : translucent_) {
        const Appearance app = h_.appearance(a.id);
        const float w = through * a.opacity;
        r.colour += shade(primary, a.id, app, a.surf, key, shadow_stream) * w;
        r.normal += amalgam_normal(app, a.surf, wo) * w;
        r.albedo += app.surface.colour * w;
        through *= 1.0f - a.opacity;
      }
    }
    Vec3 end = env_.seen_toward(primary.dir);
    if (hit.kind == TraceHit::Kind::kPrimitive) {
      const Surface surf = surface_at(h_, hit.id, hit.surf);
      const Vec3 n = surface_normal(h_, hit.id, hit.surf, wo);
      end = direct(primary, hit.surf, n, surf, key, shadow_stream);
      r.normal += n * through;
      r.albedo += surf.colour * through;
    } else if (hit.kind == TraceHit::Kind::kAmalgam) {
      const Appearance app = h_.appearance(hit.id);
      end = shade(primary, hit.id, app, hit.surf, key, shadow_stream);
      r.normal += amalgam_normal(app, hit.surf, wo) * through;
      r.albedo += app.surface.colour * through;
    }
    r.colour += end * through;
    return r;
  }

 private:
  static Vec3 shading_normal(const Appearance& app, const SurfaceHit& s) {
    return (app.normal == Vec3{}) ? s.normal : app.normal;
  }
  /// `n` turned toward the viewer direction `wo`, as direct() shades with it.
  static Vec3 facing(Vec3 n, Vec3 wo) { return dot(n, wo) < 0 ? -n : n; }
  /// The normal output of a rendered amalgam: the one shade() lights it with, or for a cloud
  /// (isotropic facets, cloud_response) the mean normal of its facets seen from `wo`: `wo`.
  static Vec3 amalgam_normal(const Appearance& app, const SurfaceHit& s, Vec3 wo) {
    return app.shading == Shading::kCloud ? wo : facing(shading_normal(app, s), wo);
  }

  /// A rendered amalgam `id` with appearance `app`, entered at `s`.
  /// Without kShadows, as if every shadow ray reached its light (no ray is traced).
  template <bool kShadows = true>
  Vec3 shade(const Ray& primary, NodeId id, const Appearance& app, const SurfaceHit& s,
             std::uint64_t key, std::uint64_t& stream) {
    if (app.shading == Shading::kFace) {
      return direct<false, kShadows>(primary, s, shading_normal(app, s), app.surface, key, stream);
    }
    return direct<true, kShadows>(primary, s, shading_normal(app, s), app.surface, key, stream, &id,
                                  app.shading == Shading::kCloud);
  }

  /// The translucent amalgams met, front to back (ties by id: the same order on any thread).
  void sort_front_to_back() {
    std::sort(translucent_.begin(), translucent_.end(), [](const auto& a, const auto& b) {
      return a.t < b.t || (a.t == b.t && a.id < b.id);
    });
  }

  /// li() under CompositeOpacity: the translucent amalgams in front of the hit blended front
  /// to back with weights w_k = T_k a_k (the hit, or the background, gets what is left), each
  /// shaded without shadows (U_k, no rays); then one member j, chosen with probability
  /// p_j = w_j lum(U_j) / sum_k w_k lum(U_k), is shaded with its shadow rays (D_j) and
  /// counts w_j D_j / p_j. Its expectation is sum_k w_k D_k, the deterministic model's image,
  /// with one set of shadow rays per sample instead of one per member.
  SampleResult li_composite(const Ray& primary, std::uint64_t key, const TraceHit& hit) {
    sort_front_to_back();
    const float t_end = hit.kind == TraceHit::Kind::kNone ? kInfinity : hit.t;
    SampleResult r{{}, hit};
    const Vec3 wo = -primary.dir;
    float through = 1.0f;
    std::uint64_t none = 0;  // unshadowed shading traces no ray
    members_.clear();
    std::size_t saturated_at = translucent_.size();  // the member whose blend saturates
    for (std::size_t k = 0; k < translucent_.size() && translucent_[k].t < t_end; ++k) {
      const TranslucentHit& a = translucent_[k];
      const Appearance app = h_.appearance(a.id);
      const float w = through * a.opacity;
      members_.push_back(
          {w, shade<false>(primary, a.id, app, a.surf, key, none), static_cast<int>(k)});
      r.normal += amalgam_normal(app, a.surf, wo) * w;
      r.albedo += app.surface.colour * w;
      through *= 1.0f - a.opacity;
      if (saturated_at == translucent_.size() && through < kSaturatedTransmittance)
        saturated_at = k;
    }
    if (through < kSaturatedTransmittance) {
      // The ray ended there (the traversal stopped looking beyond that depth): the depth and
      // level outputs are those of the member that saturated the blend.
      const TranslucentHit& e = translucent_[saturated_at];
      r.hit = TraceHit{TraceHit::Kind::kAmalgam, e.t, e.id, e.level, e.surf};
      // Saturated (the traversal stops there): the little left is taken to look like the
      // blend, whose weights are scaled up to sum to 1, rather than like nothing.
      const float scale = 1.0f / (1.0f - through);
      for (Member& m : members_) m.w *= scale;
      r.normal = r.normal * scale;
      r.albedo = r.albedo * scale;
      through = 0.0f;
    }
    Surface hit_surface{};
    Vec3 hit_normal{};
    if (through == 0.0f) {
      // saturated: neither the hit nor the background shows
    } else if (hit.kind == TraceHit::Kind::kPrimitive) {
      hit_surface = surface_at(h_, hit.id, hit.surf);
      hit_normal = surface_normal(h_, hit.id, hit.surf, wo);
      members_.push_back(
          {through, direct<false, false>(primary, hit.surf, hit_normal, hit_surface, key, none),
           -1});
      r.normal += hit_normal * through;
      r.albedo += hit_surface.colour * through;
    } else if (hit.kind == TraceHit::Kind::kAmalgam) {
      const Appearance app = h_.appearance(hit.id);
      members_.push_back({through, shade<false>(primary, hit.id, app, hit.surf, key, none), -1});
      r.normal += amalgam_normal(app, hit.surf, wo) * through;
      r.albedo += app.surface.colour * through;
    } else {
      r.colour += env_.seen_toward(primary.dir) * through;
    }
    auto lum = [](Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; };
    float total = 0.0f;
    for (const Member& m : members_) total += m.w * lum(m.u);
    if (!(total > 0.0f)) return r;  // nothing lit even without shadows
    float x = to_unit_float(hash_combine(key, 0x636f6d70)) * total;  // which member
    std::size_t j = 0;
    while (j + 1 < members_.size() && x >= members_[j].w * lum(members_[j].u))
      x -= members_[j].w * lum(members_[j].u), ++j;
    const Member& m = members_[j];
    const float p = m.w * lum(m.u) / total;
    if (!(p > 0.0f)) return r;
    std::uint64_t stream = 1;
    Vec3 d;
    if (m.k >= 0) {
      const TranslucentHit& a = translucent_[static_cast<std::size_t>(m.k)];
      d = shade(primary, a.id, h_.appearance(a.id), a.surf, key, stream);
    } else if (hit.kind == TraceHit::Kind::kPrimitive) {
      d = direct(primary, hit.surf, hit_normal, hit_surface, key, stream);
    } else {
      d = shade(primary, hit.id, h_.appearance(hit.id), hit.surf, key, stream);
    }
    r.colour += d * (m.w / p);
    return r;
  }

  /// Reflectance x cosine of a cloud of isotropically oriented Lambertian facets (uniform
  /// normals over the sphere, as on a sphere or any convex body with that normal
  /// distribution), lit from `wi` and seen from `wo`: the integral over the facets both lit
  /// and seen of f (n.wi)(n.wo), divided by the projected area seen, pi. With the phase angle
  /// g between wi and wo, the diffuse part is rho/pi * 2/(3 pi) (sin g + (pi - g) cos g) (the
  /// Lambert-sphere phase function: 2/3 when lit from the viewer, 0.212 at 90 degrees, 0
  /// back-lit); the Blinn-Phong lobe, narrow about the half vector h, gives
  /// spec(h) * 2/(s + 1) * cos^2(g/2). Self-shadowing of the facets is part of the formula, so
  /// a cloud's shadow rays leave its box on the light's side (see direct()).
  static Vec3 cloud_response(const Surface& surf, Vec3 wi, Vec3 wo) {
    constexpr float pi = std::numbers::pi_v<float>;
    const float cos_g = std::clamp(dot(wi, wo), -1.0f, 1.0f);
    const float g = std::acos(cos_g);
    const float sin_g = std::sqrt(std::max(0.0f, 1.0f - cos_g * cos_g));
    const float mean_cos = (2.0f / (3.0f * pi)) * (sin_g + (pi - g) * cos_g);
    Vec3 f = surf.colour * (std::max(0.0f, mean_cos) / pi);
    if (surf.reflectance > 0.0f) {
      const float half = 0.5f * (1.0f + cos_g);  // cos^2(g/2)
      const float spec = surf.reflectance * (surf.shininess + 8.0f) / (8.0f * pi) * 2.0f /
                         (surf.shininess + 1.0f) * half;
      f += Vec3{spec, spec, spec};
    }
    return f;
  }

  /// Light reflected toward the viewer at a hit, one shadow ray per light. With `kBaked`,
  /// `amalgam` is a rendered baked amalgam: its contents, not its box, are lit, so the entry
  /// face may be turned from a light that still reaches them; a shadow ray toward such a light
  /// starts where the line toward the light leaves the amalgam's box (the amalgam's own
  /// self-shadowing is in its normal's cosine or, with `cloud`, in cloud_response()).
  template <bool kBaked = false, bool kShadows = true>
  Vec3 direct(const Ray& primary, const SurfaceHit& s, Vec3 n, const Surface& surf,
              std::uint64_t key, std::uint64_t& stream, const NodeId* amalgam = nullptr,
              bool cloud = false) {
    Vec3 sum{};
    const Vec3 wo = -primary.dir;
    if (dot(n, wo) < 0) n = -n;
    const Vec3 n_shade = n;
    const Vec3 origin = offset_ray_origin(s.p, s.p_error, s.normal);
    std::uint64_t light_index = 0;
    for (const Light& light : env_.lights) {
      const int samples = light.sized() ? std::max(light.samples, 1) : 1;
      // A sized light's sample points come from their own streams (light, sample) under the
      // sample's key, apart from the shadow rays' (whose numbering is as without them).
      const std::uint64_t light_key = hash_combine(key, (std::uint64_t{1} << 62) | light_index++);
      for (int k = 0; k < samples; ++k) {
        LightSample ls;
        float u1 = 0.0f, u2 = 0.0f;
        if (light.sized()) {
          Sampler u(hash_combine(light_key, static_cast<std::uint64_t>(k)));
          u1 = u.next(), u2 = u.next();
        }
        if (!sample_light(light, env_.sky_map.get(), origin, n_shade, samples, u1, u2, ls)) {
          if (light.kind == LightKind::kPoint && light.sized()) break;  // inside the sphere
          continue;
        }
        sum += one_shadow_ray<kBaked, kShadows>(primary, s, n_shade, surf, key, stream, amalgam,
                                                cloud, light, ls, origin, wo);
      }
    }
    return sum;
  }

  /// One shadow ray of direct(): light sample `ls` of `light` seen from `origin` (offset from
  /// the hit `s`); what it brings if unoccluded, times the response toward `wo`.
  template <bool kBaked, bool kShadows>
  Vec3 one_shadow_ray(const Ray& primary, const SurfaceHit& s, Vec3 n, const Surface& surf,
                      std::uint64_t key, std::uint64_t& stream, const NodeId* amalgam, bool cloud,
                      const Light& light, const LightSample& ls, Vec3 origin, Vec3 wo) {
    const Vec3 wi = ls.wi;
    float dist = ls.dist;
    Vec3 from = origin;
    const float f_cos = cloud ? 1.0f : dot(n, wi);  // a cloud has it in its response
    if (f_cos <= 0.0f) return {};
    if constexpr (kBaked) {
      // (Without a shadow ray, no origin is needed.)
      if (kShadows && dot(s.normal, wi) <= 0.0f) {
        // Leave the box on the light's side: enter it backwards from beyond.
        const Bbox box = h_.bounds(*amalgam);
        const float reach = 2.0f * length(box.hi - box.lo) + 1e-6f;
        const auto exit = intersect_solid_box(Ray::make(s.p + wi * reach, -wi), box);
        if (!exit) return {};
        from = offset_ray_origin(exit->p, exit->p_error, exit->normal);
        if (is_positional(light)) {
          if (light.sized()) {
            dist = to_sphere(from, wi, light.position, light.radius);
            if (!(dist > 0.0f)) return {};  // the light is inside the box
          } else {
            const Vec3 d = light.position - from;
            dist = length(d);
            if (!(dist > 0.0f) || dot(d, wi) <= 0.0f) return {};  // light inside the box
          }
        }
      }
    } else if (dot(s.normal, wi) <= 0.0f) {
      return {};
    }
    float tr = 1.0f;
    if constexpr (kShadows) {
      Ray shadow = Ray::make(from, wi, 0.0f, dist * (1.0f - 2.0f * gamma(3)));
      // The shadow rays of one pixel leave its footprint on the surface and travel to the
      // light: a parallel beam of the footprint's width toward a directional light, a beam
      // narrowing to nothing at a point light. (Spreading it like the camera cone made distant
      // occluders render as amalgams although their shadows span many pixels.) Toward a sized
      // light the beam ends as wide as its share of the light (render/lights.h).
      shadow.cone_width = primary.footprint(s.t);
      if (is_positional(light))
        shadow.cone_spread = (ls.end_width - shadow.cone_width) / std::max(dist, 1e-30f);
      else
        shadow.cone_spread = ls.spread;
      tr = trav_.transmittance(shadow, hash_combine(key, stream++));
    }
    if (tr <= 0.0f) return {};
    return (cloud ? cloud_response(surf, wi, wo) : brdf(surf, n, wi, wo)) * ls.e * (f_cos * tr);
  }

  const H& h_;
  const Environment& env_;
  Tracer trav_;
  std::vector<TranslucentHit> translucent_;
  /// A member of a composite (li_composite): its weight, unshadowed radiance, and index in
  /// translucent_ (-1: the hit).
  struct Member {
    float w;
    Vec3 u;
    int k;
  };
  std::vector<Member> members_;
};

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file Direct lighting with shadow rays: the paper's setting (no mirror or refraction rays).
///
/// One primary sample: find the closest hit (a primitive, or a rendered amalgam), light it
/// from every light with one shadow ray each. Under deterministic opacity, every rendered
/// translucent amalgam in front of the hit is also shaded (with its own shadow ray per light)
/// and blended front to back: C = sum_k T_k a_k L_k + T_n L_hit, T_k = prod_{j<k} (1 - a_j).

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "amalgam/render/lights.h"
#include "amalgam/render/shading.h"
#include "amalgam/traverse/traverse.h"
#include "amalgam/util/probe.h"

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
    if constexpr (Opacity::kSaturates) {
      OneMemberShadowed how{*this, primary, key};
      return blend(primary, hit, how);
    } else {
      EachShadowed how{*this, primary, key};
      return blend(primary, hit, how);
    }
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

  /// The one front-to-back blend of a primary sample: the translucent amalgams in front of
  /// the hit (under an opacity model that blends), with weights w_k = T_k a_k, T_k =
  /// prod_{j<k} (1 - a_j), then the hit, or the background, with what is left (T_n); the normal
  /// and albedo outputs blended with the same weights. How each member and the end are shaded
  /// is the opacity model's strategy `how`: EachShadowed (every member with its own shadow
  /// rays) or OneMemberShadowed (CompositeOpacity).
  template <class How>
  SampleResult blend(const Ray& primary, const TraceHit& hit, How& how) {
    SampleResult r{{}, hit};
    const Vec3 wo = -primary.dir;
    float through = 1.0f;
    if constexpr (Opacity::kBlends) {
      sort_front_to_back();
      const float t_end = hit.kind == TraceHit::Kind::kNone ? kInfinity : hit.t;
      for (std::size_t k = 0; k < translucent_.size() && translucent_[k].t < t_end; ++k) {
        const TranslucentHit& a = translucent_[k];
        const Appearance app = h_.appearance(a.id);
        const float w = through * a.opacity;
        how.member(r, a, app, w, k);
        r.normal += amalgam_normal(app, a.surf, wo) * w;
        r.albedo += app.surface.colour * w;
        through *= 1.0f - a.opacity;
        if constexpr (Opacity::kSaturates) how.passed(k, through);
      }
    }
    if constexpr (Opacity::kSaturates) {
      if (through < kSaturatedTransmittance) {
        how.saturate(r, through);
        through = 0.0f;
      }
    }
    if (Opacity::kSaturates && through == 0.0f) {
      // saturated: neither the hit nor the background shows
    } else if (hit.kind == TraceHit::Kind::kPrimitive) {
      const Surface surf = surface_at(h_, hit.id, hit.surf);
      const Vec3 n = surface_normal(h_, hit.id, hit.surf, wo);
      how.end_primitive(r, hit, surf, n, through);
      r.normal += n * through;
      r.albedo += surf.colour * through;
    } else if (hit.kind == TraceHit::Kind::kAmalgam) {
      const Appearance app = h_.appearance(hit.id);
      how.end_amalgam(r, hit, app, through);
      r.normal += amalgam_normal(app, hit.surf, wo) * through;
      r.albedo += app.surface.colour * through;
    } else {
      r.colour += env_.seen_toward(primary.dir) * through;
    }
    how.finish(r, hit);
    return r;
  }

  /// The blend's strategy under the paper's models (and every model that does not saturate):
  /// each member, and the end, shaded with its own shadow rays (the deterministic model's
  /// O(n^2l1) worst case), numbered in blend order.
  struct EachShadowed {
    Integrator& in;
    const Ray& primary;
    std::uint64_t key;
    std::uint64_t stream = 1;

    void member(SampleResult& r, const TranslucentHit& a, const Appearance& app, float w,
                std::size_t) {
      r.colour += in.shade(primary, a.id, app, a.surf, key, stream) * w;
    }
    void end_primitive(SampleResult& r, const TraceHit& hit, const Surface& surf, Vec3 n,
                       float through) {
      r.colour += in.direct(primary, hit.surf, n, surf, key, stream) * through;
    }
    void end_amalgam(SampleResult& r, const TraceHit& hit, const Appearance& app, float through) {
      r.colour += in.shade(primary, hit.id, app, hit.surf, key, stream) * through;
    }
    void finish(SampleResult&, const TraceHit&) {}
  };

  /// The blend's strategy under CompositeOpacity: each member (and the end) shaded without
  /// shadows (U_k, no rays); then one of them, chosen with probability p_j = w_j lum(U_j) /
  /// sum_k w_k lum(U_k), is shaded with its shadow rays (D_j) and counts w_j D_j / p_j. Its
  /// expectation is sum_k w_k D_k, the deterministic model's image, with one set of shadow rays
  /// per sample instead of one per member. A blend that saturates (the traversal stopped
  /// looking beyond that depth) ends at the member that saturated it.
  struct OneMemberShadowed {
    Integrator& in;
    const Ray& primary;
    std::uint64_t key;
    std::uint64_t none = 0;  ///< unshadowed shading traces no ray
    std::size_t saturated_at = std::numeric_limits<std::size_t>::max();
    Surface hit_surface{};
    Vec3 hit_normal{};

    OneMemberShadowed(Integrator& i, const Ray& p, std::uint64_t k) : in(i), primary(p), key(k) {
      in.members_.clear();
    }
    void member(SampleResult&, const TranslucentHit& a, const Appearance& app, float w,
                std::size_t k) {
      in.members_.push_back({w, in.template shade<false>(primary, a.id, app, a.surf, key, none),
                             static_cast<int>(k)});
    }
    void passed(std::size_t k, float through) {
      if (saturated_at == std::numeric_limits<std::size_t>::max() &&
          through < kSaturatedTransmittance)
        saturated_at = k;
    }
    /// The depth and level outputs become those of the member that saturated the blend; the
    /// little light left is taken to look like the blend, whose weights are scaled up to sum
    /// to 1, rather than like nothing.
    void saturate(SampleResult& r, float through) {
      const TranslucentHit& e = in.translucent_[saturated_at];
      r.hit = TraceHit{TraceHit::Kind::kAmalgam, e.t, e.id, e.level, e.surf};
      const float scale = 1.0f / (1.0f - through);
      for (Member& m : in.members_) m.w *= scale;
      r.normal = r.normal * scale;
      r.albedo = r.albedo * scale;
    }
    void end_primitive(SampleResult&, const TraceHit& hit, const Surface& surf, Vec3 n,
                       float through) {
      hit_surface = surf;
      hit_normal = n;
      in.members_.push_back(
          {through, in.template direct<false, false>(primary, hit.surf, n, surf, key, none), -1});
    }
    void end_amalgam(SampleResult&, const TraceHit& hit, const Appearance& app, float through) {
      in.members_.push_back(
          {through, in.template shade<false>(primary, hit.id, app, hit.surf, key, none), -1});
    }
    void finish(SampleResult& r, const TraceHit& hit) {
      auto lum = [](Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; };
      const std::vector<Member>& ms = in.members_;
      float total = 0.0f;
      for (const Member& m : ms) total += m.w * lum(m.u);
      if (!(total > 0.0f)) return;  // nothing lit even without shadows
      float x = to_unit_float(hash_combine(key, 0x636f6d70)) * total;  // which member
      std::size_t j = 0;
      while (j + 1 < ms.size() && x >= ms[j].w * lum(ms[j].u)) x -= ms[j].w * lum(ms[j].u), ++j;
      const Member& m = ms[j];
      const float p = m.w * lum(m.u) / total;
      if (!(p > 0.0f)) return;
      std::uint64_t stream = 1;
      Vec3 d;
      if (m.k >= 0) {
        const TranslucentHit& a = in.translucent_[static_cast<std::size_t>(m.k)];
        d = in.shade(primary, a.id, in.h_.appearance(a.id), a.surf, key, stream);
      } else if (hit.kind == TraceHit::Kind::kPrimitive) {
        d = in.direct(primary, hit.surf, hit_normal, hit_surface, key, stream);
      } else {
        d = in.shade(primary, hit.id, in.h_.appearance(hit.id), hit.surf, key, stream);
      }
      r.colour += d * (m.w / p);
    }
  };

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
      const std::uint64_t shadow_key = hash_combine(key, stream++);
      if (shadows_) tr = trav_.transmittance(shadow, shadow_key);
    }
    if (tr <= 0.0f) return {};
    return (cloud ? cloud_response(surf, wi, wo) : brdf(surf, n, wi, wo)) * ls.e * (f_cos * tr);
  }

  const H& h_;
  const Environment& env_;
  Tracer trav_;
  /// false under the light probe's no-shadows (util/probe.h): every shadow ray passes.
  bool shadows_ = light_probe().shadows;
  std::vector<TranslucentHit> translucent_;
  /// A member of a composite (OneMemberShadowed): its weight, unshadowed radiance, and index in
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

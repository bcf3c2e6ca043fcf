#pragma once
/// \file Direct lighting with volumetric amalgams (hierarchy/volume/cells.h) over the
/// instanced hierarchy (docs/volumetric.md).
///
/// A camera sample: the BVH walk (ObjectLod, traverse/object_lod.h) finds the closest
/// full-detail hit and defers every instance whose cells its cone is wide enough for; each
/// deferred instance is marched through the cells of its chosen level (traverse/cone_march.h)
/// as the walk meets it, and the cells met, of every instance, sorted by depth, are composited
/// front to back: a cell takes its coverage (conditioned on the rest of its object: cells.h) of
/// what is left, T <- T (1 - coverage), so the cells of one object keep their correlation and
/// different objects are independent. Once what is left falls below kOpaque the walk is told
/// to look no deeper. What is left lights the full-detail hit or shows the background.
///
/// Shading of a cell: its normal histogram weighted by each bin's projected area toward the
/// viewer and its response to the light (Lambert plus the Blinn-Phong lobe), at the depth
/// where its surfaces are seen (the mean depth of a hit in its segment, the cells overlapping
/// there taken as one homogeneous medium). Shadows: one shadow query per light per camera
/// sample, from one member of the blend drawn in proportion to its unshadowed share, returning
/// the transmittance through the full-detail geometry (0 or 1) and the cells of every instance
/// it crosses (its own too, for an open object; a closed object's self-shadowing is in its
/// cells' first-hit coverage from the light), each at the level its own cone chooses. Where the
/// shadow ray's cone still overlaps the camera cone that reached its origin (the hot spot) a
/// cell attenuates it only for the part of its chord beside that cone.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "amalgam/render/cell_blend.h"
#include "amalgam/render/cell_shading.h"
#include "amalgam/render/integrator.h"
#include "amalgam/traverse/object_lod.h"
#include "amalgam/util/probe.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

class VolumeIntegrator final : private DeferSink {
 public:
  using IH = InstancedHierarchy;
  using Trav = Traversal<IH, ObjectLod, DeferredOpacity, SortedOrder, Counters>;

  VolumeIntegrator(const IH& h, const VolumeSet& v, const Environment& env, float cell_pixels,
                   Counters& counters)
      : h_(h), v_(v), env_(env), trav_(h, ObjectLod{&h, &v, cell_pixels}, counters) {
    trav_.opacity().sink = this;
  }
  VolumeIntegrator(const VolumeIntegrator& o)
      : DeferSink(), h_(o.h_), v_(o.v_), env_(o.env_), trav_(o.trav_) {
    trav_.opacity().sink = this;
  }
  VolumeIntegrator& operator=(const VolumeIntegrator&) = delete;

  SampleResult li(const Ray& primary, std::uint64_t key) {
    ObjectLod& lod = trav_.lod();
    lod.self = 0, lod.self_full = false, lod.defer_inside = false;
    lod.cells = probe_.camera_cells;
    objects_.clear();
    blend_.clear();
    const std::uint64_t walk_key = hash_combine(key, 0);
    Ray camera = primary;
    world_camera(camera, walk_key);
    const TraceHit hit = trav_.intersect(camera, walk_key);
    const float t_end = hit.kind == TraceHit::Kind::kNone ? kInfinity : hit.t;

    // Composite front to back what lies before the full-detail hit. Each member is shaded
    // where its surfaces are seen: within its segment, at the mean depth of a hit when the
    // cells overlapping there (of every object) are taken as one homogeneous medium.
    members_.clear();
    rates_.resize(blend_.items.size());
    float through = 1.0f;  // what is left
    for (std::size_t k = 0; k < blend_.items.size() && blend_.items[k].t0 < t_end; ++k) {
      Segment& s = blend_.items[k];
      s.t1 = std::min(s.t1, t_end);
      // Its extinction per unit t as a homogeneous segment, once (its t1 is final now).
      rates_[k] = s.t1 > s.t0 ? -std::log(std::max(1.0f - s.alpha, 1e-6f)) / (s.t1 - s.t0) : 0.0f;
      float sigma = 0.0f;  // extinction per unit t of the segments over s.t0
      for (std::size_t q = k + 1; q-- > 0 && k - q <= 64;) {
        const Segment& o = blend_.items[q];
        if (o.t1 > s.t0 && o.t1 > o.t0) sigma += rates_[q];
      }
      const float len = s.t1 - s.t0, x = sigma * len;
      // The mean of an exponential of rate sigma truncated to [0, len].
      const float depth =
          x < 1e-3f ? 0.5f * len : len * (1.0f / x - std::exp(-x) / (1.0f - std::exp(-x)));
      members_.push_back({through * s.alpha, static_cast<int>(k), s.t0 + depth});
      through *= 1.0f - s.alpha;
      if (through <= kOpaque) {
        through = 0.0f;
        break;
      }
    }

    SampleResult r{{}, hit};
    const Vec3 wo = -primary.dir;
    Surface end_surface{};
    const bool end_lit = through > 0.0f && hit.kind == TraceHit::Kind::kPrimitive;
    if (end_lit) {
      end_surface = surface_at(h_, hit.id, hit.surf);
      r.normal += surface_normal(h_, hit.id, hit.surf, wo) * through;
      r.albedo += end_surface.colour * through;
    } else if (through > 0.0f) {
      r.colour += env_.seen_toward(primary.dir) * through;
    }
    blend_outputs(primary.dir, through, r);
    if (members_.empty() && !end_lit) return r;

    // Lights: for each light sample, every member's unshadowed radiance, then one shadow query
    // from one member drawn in proportion to it.
    std::uint64_t light_index = 0;
    std::uint64_t stream = 1;
    for (const Light& light : env_.lights) {
      const int samples = light.sized() ? std::max(light.samples, 1) : 1;
      const std::uint64_t light_key = hash_combine(key, (std::uint64_t{1} << 62) | light_index++);
      for (int k = 0; k < samples; ++k) {
        Sampler u(hash_combine(light_key, static_cast<std::uint64_t>(k)));
        const float u1 = u.next(), u2 = u.next();
        shade_light(primary, hit, end_surface, end_lit, through, light, samples, u1, u2,
                    hash_combine(key, stream++), r.colour);
      }
    }
    return r;
  }

 private:
  /// Below this transmittance a ray ends: nothing behind can show.
  static constexpr float kOpaque = 1e-4f;
  /// Segment::obj of a world cell of level L: kWorld + L.
  static constexpr std::uint32_t kWorld = 0xffffff00u;

  struct Object {
    std::uint64_t slot;  ///< instance index + 1
    const CellGrid* g;
    int level;       ///< the cell level chosen for this ray
    int root_level;  ///< the instance root's level in the hierarchy
    Ray ray;         ///< the ray in object space (direction unnormalised: the same t)
    Vec3 dir;        ///< the ray's unit direction in object space
  };
  /// CellSegment::obj: an index in objects_, or kWorld + level: a world cell.
  using Segment = CellSegment;
  struct Member {
    float w;
    int seg;
    float t;  ///< where along the camera ray its surfaces are seen
  };
  /// A member of the blend lit by one light sample.
  struct Lit {
    Vec3 u;     ///< unshadowed radiance
    Vec3 from;  ///< its shadow ray's origin
    LightSample ls;
    float w;  ///< its weight in the blend
    int seg;  ///< its segment, or -1: the full-detail hit
  };
  /// What the shadow query in flight needs in deferred(): the instance it leaves and how, and
  /// the direction back to the viewer along the camera ray that reached its origin.
  struct ShadowQuery {
    std::uint64_t self = 0;
    bool self_full = false;
    float sin_apart = 1.0f;  ///< sine of the angle between the shadow ray and `to_viewer`
  };

  Object object_of(NodeId root, int root_level, float t, const Ray& ray, std::uint64_t key) {
    Object ob;
    ob.slot = IH::slot(root);
    const IH::InstanceData& in = h_.instances[ob.slot - 1];
    ob.g = v_.grid(in.mesh);
    ob.level = std::min(trav_.lod().level_for(*ob.g, ob.slot, ray, t, key), ob.g->levels - 1);
    ob.root_level = root_level;
    ob.ray = in.identity ? ray : IH::object_ray(in, ray);
    ob.dir = normalize(ob.ray.dir);
    return ob;
  }

  /// The walk met instance `root` (DeferSink): a camera ray marches it, adds its cells to the
  /// blend and lowers the walk's tmax to where the blend saturates; a shadow ray multiplies its
  /// transmittance by the instance's and ends once nothing passes.
  void deferred(NodeId root, int level, float t, Ray& ray, std::uint64_t key, bool shadow,
                bool& done, float& transmittance) override {
    if (IH::slot(root) == 0 || trav_.lod().absorbed(root, ray, t, key))
      return;  // the world cells stand for it (world_camera, world_shadow)
    Object ob = object_of(root, level, t, ray, key);
    float t0 = ray.tmin, t1 = ray.tmax;
    if (!clip_to_grid(*ob.g, ob.ray.origin, ob.ray.dir, t0, t1)) return;
    if (shadow) {
      if (ob.slot == query_.self && (ob.g->oriented || !probe_.march_self))
        return;  // in its cells' shading
      if (!(ob.slot == query_.self ? probe_.self_cells : probe_.other_cells)) return;
      transmittance *= shadow_march(ob, ray, t0, t1, level);
      if (!(transmittance > kOpaque)) transmittance = 0.0f, done = true;
      return;
    }
    const auto index = static_cast<std::uint32_t>(objects_.size());
    objects_.push_back(ob);
    const OctahedralLerp lerp = ob.g->lerp(ob.dir);
    const std::size_t first = blend_.items.size();
    float left = 1.0f;  // this object's own transmittance so far
    const int steps = march_cells(*ob.g, ob.level, ob.ray.origin, ob.ray.dir, t0, t1,
                                  [&](std::uint32_t cell, float a, float b) {
                                    const float alpha = ob.g->coverage_of(cell, lerp);
                                    if (alpha > 0.0f)
                                      blend_.items.push_back({a, b, cell, index, alpha});
                                    left *= 1.0f - alpha;
                                    return left > kOpaque;
                                  });
    trav_.count_cells(RayKind::kPrimary, level + 1 + ob.level, static_cast<std::uint64_t>(steps));
    // Merge the new cells (in depth order already) into the sorted blend, then find where it
    // saturates: nothing beyond can show, whatever the walk still finds.
    ray.tmax = std::min(ray.tmax, blend_.merge(first, kOpaque));
  }

  /// The members' share of the albedo and normal outputs, and the hit output: the nearest
  /// member when the members outweigh what is left (`through`) behind them.
  void blend_outputs(Vec3 dir, float through, SampleResult& r) const {
    float amalgam_weight = 0.0f;
    for (const Member& m : members_) {
      const Segment& s = blend_.items[static_cast<std::size_t>(m.seg)];
      if (s.obj >= kWorld) {
        r.albedo += v_.world.surface[s.cell].albedo * m.w;
        r.normal += world_normal(s.cell, dir) * m.w;
      } else {
        const Object& ob = objects_[s.obj];
        r.albedo += ob.g->surface[s.cell].albedo * m.w;
        r.normal += cell_normal(ob, s.cell) * m.w;
      }
      amalgam_weight += m.w;
    }
    if (!members_.empty() && amalgam_weight >= through) {
      const Member& m = members_.front();
      const Segment& s = blend_.items[static_cast<std::size_t>(m.seg)];
      if (s.obj >= kWorld) {
        r.hit = TraceHit{TraceHit::Kind::kAmalgam, m.t, IH::id(0, 0),
                         static_cast<int>(s.obj - kWorld), SurfaceHit{}};
      } else {
        const Object& ob = objects_[s.obj];
        r.hit = TraceHit{TraceHit::Kind::kAmalgam, m.t, IH::id(ob.slot, 0),
                         ob.root_level + 1 + ob.level, SurfaceHit{}};
      }
    }
  }

  /// The world cells along camera ray `ray` (walk key `walk_key`), front to back, into the
  /// blend; lowers the ray's tmax to where they alone saturate it.
  void world_camera(Ray& ray, std::uint64_t walk_key) {
    const WorldCells& w = v_.world;
    if (w.empty() || !probe_.camera_cells) return;
    const OctahedralLerp lerp = OctahedralLerp::of(ray.dir, w.dir_res);
    float left = 1.0f;
    march_world(
        w, ray, ray.tmin, ray.tmax, trav_.lod().cell_pixels, world_level_u(walk_key),
        [&](std::uint32_t cell, float a, float b, int level) {
          const float alpha = 1.0f - std::exp(-w.sigma_of(cell, lerp) * (b - a));
          if (alpha > 0.0f)
            blend_.items.push_back({a, b, cell, kWorld + static_cast<std::uint32_t>(level), alpha});
          left *= 1.0f - alpha;
          if (left > kOpaque) return true;
          ray.tmax = std::min(ray.tmax, a);
          return false;
        },
        [&](int level, int steps) {
          trav_.count_cells(RayKind::kPrimary, level, static_cast<std::uint64_t>(steps));
        });
  }

  /// The transmittance of the world cells along shadow ray `ray` (keyed `key`), with a hot spot
  /// as in shadow_march but as wide as the cells' grain, not the cone: the instances in a world
  /// cell are smaller than the cone, and the gap a camera ray came through is as wide as their
  /// pieces (a blade, a leaf). A chord attenuates by its distance from the camera ray over two
  /// grains (at most 1): a linear ramp with the integral of a correlation exp(-distance /
  /// grain) (docs/volumetric.md, "World cells").
  float world_shadow(const Ray& ray, std::uint64_t key) {
    const WorldCells& w = v_.world;
    if (w.empty() || !probe_.world_cells || !probe_.shadow_cells) return 1.0f;
    const OctahedralLerp lerp = OctahedralLerp::of(ray.dir, w.dir_res);
    float tr = 1.0f;
    march_world(
        w, ray, ray.tmin, ray.tmax, trav_.lod().cell_pixels, world_level_u(key),
        [&](std::uint32_t cell, float a, float b, int) {
          const float beside = !probe_.hot_spot || !probe_.other_hot_spot
                                   ? 1.0f
                                   : std::min(1.0f, 0.5f * (a + b) * query_.sin_apart /
                                                        std::max(2.0f * w.grain[cell], 1e-30f));
          tr *= std::exp(-w.sigma_of(cell, lerp) * (b - a) * beside);
          return tr > kOpaque;
        },
        [&](int level, int steps) {
          trav_.count_cells(RayKind::kShadow, level, static_cast<std::uint64_t>(steps));
        });
    return tr > kOpaque ? tr : 0.0f;
  }

  /// The transmittance of object `ob` along shadow ray `ray` over [t0, t1] (clipped to its
  /// grid): the product of 1 - coverage (seen from the light) over its cells crossed. A cell
  /// that holds the ray's origin attenuates it by the share of the cell's mean chord still
  /// ahead (as a homogeneous cell would); where the shadow ray's cone still overlaps the camera
  /// cone that reached its origin (both one cone width wide there: the hot spot), only the
  /// share of the chord beside that cone counts.
  float shadow_march(const Object& ob, const Ray& ray, float t0, float t1, int root_level) {
    const bool starts_inside = t0 == ray.tmin;
    const OctahedralLerp lerp = ob.g->lerp(-ob.dir);
    const Vec3 cs = ob.g->cell_size(ob.level);
    const float chord = cs.x * cs.y * cs.z / ob.g->projected_area(ob.level, ob.dir);
    const float width = probe_.cone_hot_spot
                            ? std::max(ray.cone_width, 1e-30f)
                            : std::max(2.0f * ob.g->grain * v_.instance_scale[ob.slot - 1], 1e-30f);
    const float apart_per_t = query_.sin_apart * length(ray.dir) / width;
    const bool hot_spot = probe_.hot_spot && (probe_.other_hot_spot || ob.slot == query_.self);
    float tr = 1.0f;
    const int steps = march_cells(
        *ob.g, ob.level, ob.ray.origin, ob.ray.dir, t0, t1,
        [&](std::uint32_t cell, float a, float b) {
          const float pass = 1.0f - ob.g->coverage_of(cell, lerp);
          const float beside = hot_spot ? std::min(1.0f, 0.5f * (a + b) * apart_per_t) : 1.0f;
          const float share = starts_inside && a == t0 ? std::min(1.0f, (b - a) / chord) : 1.0f;
          tr *= std::pow(pass, beside * share);
          return tr > kOpaque;
        });
    trav_.count_cells(RayKind::kShadow, root_level + 1 + ob.level,
                      static_cast<std::uint64_t>(steps));
    return tr;
  }

  /// A direction of world space in the object space of instance `slot`, normalised.
  Vec3 to_object(std::uint64_t slot, Vec3 w) const {
    const IH::InstanceData& in = h_.instances[slot - 1];
    return in.identity ? w : normalize(in.to_object.vector(w));
  }

  /// The cell's mean normal as seen (for the normal output), in world space.
  Vec3 cell_normal(const Object& ob, std::uint32_t cell) const {
    const CellGrid& g = *ob.g;
    Vec3 sum = seen_normal(g.normals.data() + static_cast<std::size_t>(cell) * g.normal_bins(),
                           g.normal_dirs, g.oriented, -ob.dir);
    const IH::InstanceData& in = h_.instances[ob.slot - 1];
    if (!in.identity)
      sum = Vec3{dot(in.normal_rows[0], sum), dot(in.normal_rows[1], sum),
                 dot(in.normal_rows[2], sum)};
    const float len = length(sum);
    return len > 0.0f ? sum / len : Vec3{};
  }

  /// World cell `cell`'s mean normal seen along world direction `dir`.
  Vec3 world_normal(std::uint32_t cell, Vec3 dir) const {
    const WorldCells& w = v_.world;
    const Vec3 sum =
        seen_normal(w.normals.data() + static_cast<std::size_t>(cell) * w.normal_bins(),
                    w.normal_dirs, false, -dir);
    const float len = length(sum);
    return len > 0.0f ? sum / len : Vec3{};
  }

  /// Radiance toward the viewer per unit of the cell's weight, lit from world direction `wi`
  /// with irradiance `e`, without shadows (for a closed object, with its own).
  Vec3 cell_radiance(const Object& ob, std::uint32_t cell, Vec3 wi, Vec3 e) const {
    const CellGrid& g = *ob.g;
    const CellSurface& s = g.surface[cell];
    const Vec3 l = to_object(ob.slot, wi);
    float facing_light;
    Vec3 f = reflected(g.normals.data() + static_cast<std::size_t>(cell) * g.normal_bins(),
                       g.normal_dirs, g.oriented, s, g.shininess, -ob.dir, l, facing_light);
    if (g.oriented) {
      // A closed object shadows itself as a solid: its surfaces in the cell facing the light
      // are lit where they are the first surfaces the light meets, i.e. the share of their
      // unoccluded projected area toward the light that the cell's first-hit coverage seen
      // from the light holds (all of it on a convex object).
      if (!(facing_light > 0.0f)) return {};
      const float reached = g.first_hit_of(cell, g.lerp(-l)) * g.projected_area(ob.level, l);
      f = f * std::min(1.0f, reached / (s.area * facing_light * (1.0f / 65535.0f)));
    } else if (!probe_.march_self) {
      f = f * open_lit(ob, cell, l);
    }
    return f * e;
  }

  /// The share of the surfaces of open object `ob`'s `cell` seen along its ray that object
  /// direction `l` lights past the object itself: their lit share toward l from the bake,
  /// corrected by the mesh's seen-and-lit correction at the cell's level and the angle between
  /// the viewer and the light (CellGrid::seen_lit, traverse/lit_ratio.h: the hot spot and where
  /// in a cell the seen surfaces lie).
  float open_lit(const Object& ob, std::uint32_t cell, Vec3 l) const {
    const CellGrid& g = *ob.g;
    const float share = g.lit_share(ob.level, cell, l);
    if (!probe_.hot_spot) return share;
    return g.seen_lit(ob.level, ob.dir.y, dot(-ob.dir, l), share);
  }

  /// The radiance of segment `s`'s cell (an object's or a world cell) toward the viewer along
  /// camera direction `dir`, as cell_radiance.
  Vec3 segment_radiance(const Segment& s, Vec3 dir, Vec3 wi, Vec3 e) const {
    if (s.obj < kWorld) return cell_radiance(objects_[s.obj], s.cell, wi, e);
    const WorldCells& w = v_.world;
    float facing_light;
    return reflected(w.normals.data() + static_cast<std::size_t>(s.cell) * w.normal_bins(),
                     w.normal_dirs, false, w.surface[s.cell], w.shininess, -dir, wi, facing_light) *
           e;
  }

  /// The light sample (u1, u2) of `light` seen from `p`; false if it brings nothing.
  /// (No shading normal: a cell's facets face every way, so the sky is sampled over the whole
  /// sphere; the surface hit takes its normal's hemisphere.)
  bool light_sample(const Light& light, Vec3 p, Vec3 normal, int samples, float u1, float u2,
                    LightSample& ls) const {
    return sample_light(light, env_.sky_map.get(), p, normal, samples, u1, u2, ls);
  }

  /// One light sample: each member's unshadowed radiance, one shadow query from a member drawn
  /// by its share; adds the estimate to `colour`.
  void shade_light(const Ray& primary, const TraceHit& hit, const Surface& end_surface,
                   bool end_lit, float end_w, const Light& light, int samples, float u1, float u2,
                   std::uint64_t key, Vec3& colour) {
    lits_.clear();
    const Vec3 wo = -primary.dir;
    for (const Member& m : members_) {
      const Segment& s = blend_.items[static_cast<std::size_t>(m.seg)];
      const Vec3 p = primary.at(m.t);
      LightSample ls;
      if (!light_sample(light, p, Vec3{}, samples, u1, u2, ls)) continue;
      const Vec3 u = segment_radiance(s, primary.dir, ls.wi, ls.e);
      if (luminance(u) > 0.0f) lits_.push_back({u, p, ls, m.w, m.seg});
    }
    if (end_lit) {
      const SurfaceHit& sh = hit.surf;
      const Vec3 origin = offset_ray_origin(sh.p, sh.p_error, sh.normal);
      LightSample ls;
      const Vec3 n = surface_normal(h_, hit.id, sh, wo);
      if (light_sample(light, origin, n, samples, u1, u2, ls)) {
        const float f_cos = dot(n, ls.wi);
        if (f_cos > 0.0f && dot(sh.normal, ls.wi) > 0.0f) {
          const Vec3 u = brdf(end_surface, n, ls.wi, wo) * ls.e * f_cos;
          if (luminance(u) > 0.0f) lits_.push_back({u, origin, ls, end_w, -1});
        }
      }
    }
    float total = 0.0f;
    for (const Lit& l : lits_) total += l.w * luminance(l.u);
    if (!(total > 0.0f)) return;
    float x = to_unit_float(hash_combine(key, 0x766f6c)) * total;
    std::size_t j = 0;
    while (j + 1 < lits_.size() && x >= lits_[j].w * luminance(lits_[j].u))
      x -= lits_[j].w * luminance(lits_[j].u), ++j;
    const Lit& c = lits_[j];
    const float p = c.w * luminance(c.u) / total;
    if (!(p > 0.0f)) return;
    Ray shadow = Ray::make(c.from, c.ls.wi, 0.0f, c.ls.dist * (1.0f - 2.0f * gamma(3)));
    const bool from_cell = c.seg >= 0;
    const float t_from = from_cell ? members_t(c.seg) : hit.t;
    shadow.cone_width = primary.footprint(t_from);
    if (is_positional(light))
      shadow.cone_spread = (c.ls.end_width - shadow.cone_width) / std::max(c.ls.dist, 1e-30f);
    else
      shadow.cone_spread = c.ls.spread;
    const std::uint32_t from_obj =
        from_cell ? blend_.items[static_cast<std::size_t>(c.seg)].obj : 0;
    query_.self = !from_cell ? IH::slot(hit.id) : from_obj < kWorld ? objects_[from_obj].slot : 0;
    query_.self_full = !from_cell;
    const float cos_apart = std::clamp(dot(wo, c.ls.wi), -1.0f, 1.0f);
    query_.sin_apart = !probe_.march_self && cos_apart < 0.0f
                           ? 1.0f
                           : std::sqrt(std::max(0.0f, 1.0f - cos_apart * cos_apart));
    ObjectLod& lod = trav_.lod();
    lod.self = query_.self, lod.self_full = query_.self_full, lod.defer_inside = true;
    lod.cells = probe_.shadow_cells;
    float tr = 1.0f;
    if (probe_.shadows) {
      tr = world_shadow(shadow, key);
      if (tr > 0.0f) tr *= trav_.transmittance(shadow, key);
    }
    lod.self = 0, lod.self_full = false, lod.defer_inside = false;
    lod.cells = true;
    if (tr > 0.0f) colour += c.u * (c.w * tr / p);
  }

  /// The depth along the camera ray where the member of segment `seg` is seen.
  float members_t(int seg) const {
    for (const Member& m : members_)
      if (m.seg == seg) return m.t;
    return blend_.items[static_cast<std::size_t>(seg)].t0;
  }

  const IH& h_;
  const VolumeSet& v_;
  const Environment& env_;
  Trav trav_;
  ShadowQuery query_;
  LightProbe probe_ = light_probe();  ///< measurement switches (util/probe.h)
  std::vector<Object> objects_;
  CellBlend blend_;
  std::vector<float> rates_;  ///< per segment: its extinction per unit t (li)
  std::vector<Member> members_;
  std::vector<Lit> lits_;
};

AMALGAM_ISA_END
}  // namespace amalgam

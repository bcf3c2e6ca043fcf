// Embree as the Integrator's tracer (embree_tracer.h). Compiled once, for the portable
// baseline: Embree chooses its own instruction set at run time, and the shading around it is
// the same code as amalgam's portable copy (the two copies give the same bits, util/isa.h).

#include "amalgam/render/embree_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "amalgam/render/integrator.h"
#include "amalgam/render/passes.h"
#include "amalgam/util/error.h"

namespace amalgam {

namespace {

using Clock = std::chrono::steady_clock;

/// Embree's scene of one set of primitives: geometry 0 the triangles, geometry 1 the spheres
/// and boxes (user geometry); ids[g][primID] is the primitive's id in the hierarchy (for an
/// instanced scene, its index in the mesh).
struct UserGeometry;
struct EmbreeMesh {
  RTCScene scene = nullptr;
  std::vector<std::uint64_t> ids[2];
  std::unique_ptr<UserGeometry> user, triangles;
};

/// What a user-geometry callback or the triangles' occlusion filter needs: the hierarchy (of
/// type H, see user_intersect), the ids of its primitives and (user geometry) their
/// object-space bounds.
struct UserGeometry {
  const void* hierarchy = nullptr;
  /// The mesh's ids vector's data: unlike the vector itself (an element of Impl::meshes, which
  /// moves as that grows), its buffer stays put once filled.
  const std::uint64_t* ids = nullptr;
  std::vector<Bbox> bounds;
};

/// The intersect context passed to rtcIntersect1/rtcOccluded1, extended (as Embree documents:
/// the callbacks receive this pointer) with amalgam's world-space ray, so that user geometry
/// is tested with exactly the ray the traditional renderer would test.
struct QueryContext {
  RTCIntersectContext base;
  const Ray* ray;
};

constexpr unsigned kTriangles = 0, kUser = 1;

template <class H>
constexpr bool kInstanced = std::is_same_v<H, InstancedHierarchy>;

/// The hierarchy's own test of user primitive `prim` against the world ray of `ctx`, up to
/// `tfar` (Embree's current closest hit; t is the same parameter in object and world space).
template <class H>
std::optional<SurfaceHit> user_test(const UserGeometry& g, const RTCIntersectContext* ctx,
                                    unsigned prim, float tfar) {
  const auto* q = reinterpret_cast<const QueryContext*>(ctx);
  std::uint64_t id = g.ids[prim];
  if constexpr (kInstanced<H>) {
    id = InstancedHierarchy::id(ctx->instID[0] + 1ull, static_cast<std::uint32_t>(id));
  }
  Ray r = *q->ray;
  r.tmax = std::min(r.tmax, tfar);
  return static_cast<const H*>(g.hierarchy)->intersect(id, r);
}

template <class H>
void user_intersect(const RTCIntersectFunctionNArguments* a) {
  const auto& g = *static_cast<const UserGeometry*>(a->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(a->rayhit, a->N);
  RTCHitN* hit = RTCRayHitN_HitN(a->rayhit, a->N);
  for (unsigned i = 0; i < a->N; ++i) {
    if (!a->valid[i]) continue;
    float& tfar = RTCRayN_tfar(ray, a->N, i);
    const auto s = user_test<H>(g, a->context, a->primID, tfar);
    if (!s) continue;
    tfar = s->t;
    RTCHitN_Ng_x(hit, a->N, i) = s->normal.x;
    RTCHitN_Ng_y(hit, a->N, i) = s->normal.y;
    RTCHitN_Ng_z(hit, a->N, i) = s->normal.z;
    RTCHitN_u(hit, a->N, i) = 0.0f;
    RTCHitN_v(hit, a->N, i) = 0.0f;
    RTCHitN_primID(hit, a->N, i) = a->primID;
    RTCHitN_geomID(hit, a->N, i) = a->geomID;
    RTCHitN_instID(hit, a->N, i, 0) = a->context->instID[0];
  }
}

template <class H>
void user_occluded(const RTCOccludedFunctionNArguments* a) {
  const auto& g = *static_cast<const UserGeometry*>(a->geometryUserPtr);
  for (unsigned i = 0; i < a->N; ++i) {
    if (!a->valid[i]) continue;
    float& tfar = RTCRayN_tfar(a->ray, a->N, i);
    if (user_test<H>(g, a->context, a->primID, tfar)) tfar = -kInfinity;  // Embree: occluded
  }
}

/// The triangles' occlusion filter: a shadow ray's hit on a triangle counts only if amalgam's
/// own test of that triangle, with amalgam's world-space ray, accepts it too. Embree takes the
/// ray into an instance's object space with its own float inverse of the transform, off by the
/// rounding of the ray origin's distance from the world origin (1e-5 m at 100 m), more than the
/// shadow ray's offset from its surface: it then meets the triangle it leaves again, behind its
/// origin (docs/embree.md). amalgam's test, with its nearly exact transform, rejects such a hit
/// (one that may lie behind the origin within its rounding bound). Otherwise the filter only
/// drops a hit amalgam's test places just outside the triangle (a ray through an edge).
template <class H>
void triangle_occlusion_filter(const RTCFilterFunctionNArguments* a) {
  const auto& g = *static_cast<const UserGeometry*>(a->geometryUserPtr);
  const auto* q = reinterpret_cast<const QueryContext*>(a->context);
  for (unsigned i = 0; i < a->N; ++i) {
    if (a->valid[i] == 0) continue;
    std::uint64_t id = g.ids[RTCHitN_primID(a->hit, a->N, i)];
    if constexpr (kInstanced<H>) {
      id = InstancedHierarchy::id(a->context->instID[0] + 1ull, static_cast<std::uint32_t>(id));
    }
    if (!static_cast<const H*>(g.hierarchy)->intersect(id, *q->ray)) a->valid[i] = 0;
  }
}

void user_bounds(const RTCBoundsFunctionArguments* a) {
  const Bbox b = static_cast<const UserGeometry*>(a->geometryUserPtr)->bounds[a->primID];
  // A few ulps wider: Embree's BVH must never cull a ray our own test would accept.
  auto pad = [](float x) { return (std::fabs(x) + 1e-30f) * (8.0f * gamma(1)); };
  *a->bounds_o = {b.lo.x - pad(b.lo.x), b.lo.y - pad(b.lo.y), b.lo.z - pad(b.lo.z), 0.0f,
                  b.hi.x + pad(b.hi.x), b.hi.y + pad(b.hi.y), b.hi.z + pad(b.hi.z), 0.0f};
}

/// The first error Embree reported on a device (its callback cannot throw).
struct DeviceErrors {
  std::string first;
};
void on_embree_error(void* user, RTCError code, const char* message) {
  auto* e = static_cast<DeviceErrors*>(user);
  if (e->first.empty())
    e->first = "Embree error " + std::to_string(static_cast<int>(code)) + ": " +
               (message ? message : "(no message)");
}

/// Embree's device and BVHs of one loaded scene.
struct EmbreeBvh {
  const LoadedScene* loaded = nullptr;
  DeviceErrors errors;
  RTCDevice device = nullptr;
  std::vector<EmbreeMesh> meshes;  ///< one per mesh (instanced scenes), else one: the scene
  RTCScene top = nullptr;          ///< the scene rays are traced in
  double build_seconds = 0.0;

  ~EmbreeBvh() {
    if (top && (meshes.empty() || top != meshes.front().scene)) rtcReleaseScene(top);
    for (EmbreeMesh& m : meshes)
      if (m.scene) rtcReleaseScene(m.scene);
    if (device) rtcReleaseDevice(device);
  }

  void check(const char* what) const {
    if (!errors.first.empty())
      throw RuntimeError(std::string("embree: ") + what + ": " + errors.first);
  }

  EmbreeBuild build_options;

  RTCScene new_scene() const {
    RTCScene s = rtcNewScene(device);
    rtcSetSceneFlags(s, build_options.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(
        s, build_options.quality == EmbreeBuild::Quality::kHigh     ? RTC_BUILD_QUALITY_HIGH
           : build_options.quality == EmbreeBuild::Quality::kMedium ? RTC_BUILD_QUALITY_MEDIUM
                                                                    : RTC_BUILD_QUALITY_LOW);
    return s;
  }

  /// Embree's scene of the primitives `each(f)` lists as f(id, primitive) (object space),
  /// tested by hierarchy `h` of type H.
  template <class H, class Each>
  void add_mesh(const H& h, Each&& each) {
    EmbreeMesh& m = meshes.emplace_back();
    m.user = std::make_unique<UserGeometry>();
    std::vector<float> v;
    each([&](std::uint64_t id, const Primitive& p) {
      if (p.kind == PrimKind::kTriangle) {
        for (Vec3 q : {p.a, p.b, p.c}) v.insert(v.end(), {q.x, q.y, q.z});
        m.ids[kTriangles].push_back(id);
      } else {
        m.ids[kUser].push_back(id);
        m.user->bounds.push_back(bounds(p));
      }
    });
    m.scene = new_scene();
    const std::size_t tris = m.ids[kTriangles].size();
    if (tris > 0) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * tris));
      auto* ib = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), tris));
      check("triangle buffers");
      std::copy(v.begin(), v.end(), vb);
      for (std::size_t i = 0; i < 3 * tris; ++i) ib[i] = static_cast<std::uint32_t>(i);
      m.triangles = std::make_unique<UserGeometry>();
      m.triangles->hierarchy = &h;
      m.triangles->ids = m.ids[kTriangles].data();
      rtcSetGeometryUserData(g, m.triangles.get());
      rtcSetGeometryOccludedFilterFunction(g, triangle_occlusion_filter<H>);
      rtcCommitGeometry(g);
      rtcAttachGeometryByID(m.scene, g, kTriangles);
      rtcReleaseGeometry(g);
    }
    if (!m.ids[kUser].empty()) {
      m.user->hierarchy = &h;
      m.user->ids = m.ids[kUser].data();
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(m.ids[kUser].size()));
      rtcSetGeometryUserData(g, m.user.get());
      rtcSetGeometryBoundsFunction(g, user_bounds, nullptr);
      rtcSetGeometryIntersectFunction(g, user_intersect<H>);
      rtcSetGeometryOccludedFunction(g, user_occluded<H>);
      rtcCommitGeometry(g);
      rtcAttachGeometryByID(m.scene, g, kUser);
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(m.scene);
    check("building a BVH");
  }

  void build(const ExplicitHierarchy& h) {
    add_mesh(h, [&](auto&& f) {
      for (std::size_t i = 0; i < h.prims.size(); ++i) f(i, h.prims[i]);
    });
    top = meshes.front().scene;
  }

  /// An implicit builtin: its primitives, listed by walking the hierarchy once.
  template <class H>
  void build(const H& h) {
    if (h.info().primitives > kMaxEmbreeListedPrimitives)
      throw InputError(loaded->name + ": " + std::to_string(h.info().primitives) +
                       " primitives, more than --tracer embree lists (" +
                       std::to_string(static_cast<long long>(kMaxEmbreeListedPrimitives)) + ")");
    add_mesh(h, [&](auto&& f) {
      std::vector<NodeId> stack{h.root()};
      while (!stack.empty()) {
        const NodeId n = stack.back();
        stack.pop_back();
        h.for_each_child(n, [&](Child c) {
          if (c.is_primitive)
            f(c.id, h.primitive(c.id));
          else
            stack.push_back(c.id);
          return true;
        });
      }
    });
    top = meshes.front().scene;
  }

  void build(const InstancedHierarchy& h) {
    for (const ExplicitHierarchy& mesh : h.meshes) {
      add_mesh(h, [&](auto&& f) {
        for (std::size_t i = 0; i < mesh.prims.size(); ++i) f(i, mesh.prims[i]);
      });
    }
    top = new_scene();
    for (std::size_t i = 0; i < h.instances.size(); ++i) {
      const InstancedHierarchy::InstanceData& in = h.instances[i];
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g, meshes[in.mesh].scene);
      rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &in.to_world.m[0][0]);
      rtcCommitGeometry(g);
      rtcAttachGeometryByID(top, g, static_cast<unsigned>(i));
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(top);
    check("building the instance BVH");
  }
};

/// The Integrator's tracer over Embree (full detail: every primitive opaque, no amalgams).
/// Counts rays (as amalgam's traversal does), no tests.
template <class H>
class EmbreeHits {
 public:
  EmbreeHits(const H& h, const EmbreeBvh& s, Counters& c) : h_(&h), s_(&s), c_(&c) {}

  TraceHit intersect(const Ray& ray, std::uint64_t, std::vector<TranslucentHit>*) {
    c_->count_ray(RayKind::kPrimary);
    QueryContext q{{}, &ray};
    rtcInitIntersectContext(&q.base);
    RTCRayHit rh{};
    fill(rh.ray, ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(s_->top, &q.base, &rh);
    TraceHit hit;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
    hit.kind = TraceHit::Kind::kPrimitive;
    hit.t = rh.ray.tfar;
    const unsigned inst = rh.hit.instID[0];
    if constexpr (kInstanced<H>) {
      const std::uint64_t local =
          s_->meshes[h_->instances[inst].mesh].ids[rh.hit.geomID][rh.hit.primID];
      hit.id = InstancedHierarchy::id(inst + 1ull, static_cast<std::uint32_t>(local));
    } else {
      hit.id = s_->meshes.front().ids[rh.hit.geomID][rh.hit.primID];
    }
    // The hierarchy's own test of the one primitive Embree found gives the surface (point,
    // normal, error bound) exactly as the traditional renderer sees it (for user geometry it
    // is the test Embree's callback ran).
    if (auto s = h_->intersect(hit.id, ray)) {
      hit.surf = *s;
      hit.t = s->t;
      return hit;
    }
    // Embree's and amalgam's watertight triangle tests disagree on an edge: Embree's hit.
    Vec3 n{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    if constexpr (kInstanced<H>) {
      const InstancedHierarchy::InstanceData& in = h_->instances[inst];
      n = Vec3{dot(in.normal_rows[0], n), dot(in.normal_rows[1], n), dot(in.normal_rows[2], n)};
    }
    n = normalize(n);
    if (dot(n, ray.dir) > 0.0f) n = -n;
    hit.surf.t = hit.t;
    hit.surf.normal = n;
    hit.surf.p = ray.at(hit.t);
    hit.surf.p_error = abs(hit.surf.p) * (64.0f * gamma(1));
    return hit;
  }

  float transmittance(const Ray& ray, std::uint64_t) {
    c_->count_ray(RayKind::kShadow);
    QueryContext q{{}, &ray};
    rtcInitIntersectContext(&q.base);
    RTCRay r{};
    fill(r, ray);
    rtcOccluded1(s_->top, &q.base, &r);
    return r.tfar < 0.0f ? 0.0f : 1.0f;
  }

 private:
  static void fill(RTCRay& r, const Ray& ray) {
    r.org_x = ray.origin.x;
    r.org_y = ray.origin.y;
    r.org_z = ray.origin.z;
    r.dir_x = ray.dir.x;
    r.dir_y = ray.dir.y;
    r.dir_z = ray.dir.z;
    r.tnear = ray.tmin;
    r.tfar = ray.tmax;
    r.mask = 0xffffffffu;
    r.time = 0.0f;
    r.flags = 0;
  }

  const H* h_;
  const EmbreeBvh* s_;
  Counters* c_;
};

template <class H>
using EmbreeIntegrator =
    Integrator<H, TraditionalLod, StochasticOpacity, SortedOrder, Counters, EmbreeHits<H>>;

/// The Tracer over Embree's BVHs of one scene.
class EmbreeTracer final : public Tracer {
 public:
  EmbreeTracer(const LoadedScene& scene, int threads, const EmbreeBuild& build) : Tracer(scene) {
    const auto t0 = Clock::now();
    bvh_.loaded = &scene;
    bvh_.build_options = build;
    const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
    bvh_.device = rtcNewDevice(config.c_str());
    if (!bvh_.device)
      throw RuntimeError("embree: no device (error " +
                         std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(bvh_.device, on_embree_error, &bvh_.errors);
    std::visit([&](const auto& h) { bvh_.build(h); }, scene.hierarchy);
    bvh_.build_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  }

  RenderOutput render_view(const Environment& env, const RenderOptions& o, FilmState* resume,
                           const RenderControl& control) const override {
    check(o);
    const LoadedScene& scene = *bvh_.loaded;
    const auto t0 = Clock::now();
    FilmState local;
    FilmState& st = resume ? *resume : local;
    start_film(st, o);
    const bool interrupted = std::visit(
        [&](const auto& h) {
          using H = std::decay_t<decltype(h)>;
          return render_passes(env.camera, o, st, control, [&](Counters& c) {
            return EmbreeIntegrator<H>(h, env, EmbreeHits<H>(h, bvh_, c));
          });
        },
        scene.hierarchy);
    RenderOutput out = finish(st);
    out.interrupted = interrupted;
    out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return out;
  }

  bool render_tile(const RenderOptions& o, FilmTile& tile, int s0, int s1,
                   const std::atomic<bool>* cancel) const override {
    check(o);
    const LoadedScene& scene = *bvh_.loaded;
    const bool interrupted = std::visit(
        [&](const auto& h) {
          using H = std::decay_t<decltype(h)>;
          return render_tile_passes(scene.env.camera, o, tile, s0, s1, cancel, [&](Counters& c) {
            return EmbreeIntegrator<H>(h, scene.env, EmbreeHits<H>(h, bvh_, c));
          });
        },
        scene.hierarchy);
    return !interrupted;
  }

  TraceOutput trace(const RenderOptions& o, const Ray& ray) const override {
    check(o);
    const LoadedScene& scene = *bvh_.loaded;
    TraceOutput out;
    std::visit(
        [&](const auto& h) {
          using H = std::decay_t<decltype(h)>;
          EmbreeIntegrator<H> integrator(h, scene.env, EmbreeHits<H>(h, bvh_, out.counters));
          const SampleResult r = integrator.li(ray, hash_combine(hash_combine(o.seed, 0), 0));
          out.hit = r.hit;
          out.colour = r.colour;
        },
        scene.hierarchy);
    out.per_primary.add(out.counters.total());
    return out;
  }

  double build_seconds() const override { return bvh_.build_seconds; }
  bool counts_tests() const override { return false; }

 private:
  void check(const RenderOptions& o) const {
    check_options(*bvh_.loaded, o);
    if (o.tracer != TracerKind::kEmbree)
      throw InputError("the Embree tracer: expected options with --tracer embree");
  }

  EmbreeBvh bvh_;
};

}  // namespace

std::unique_ptr<Tracer> make_embree_tracer(const LoadedScene& scene, int threads,
                                           const EmbreeBuild& build) {
  return std::make_unique<EmbreeTracer>(scene, threads, build);
}

}  // namespace amalgam

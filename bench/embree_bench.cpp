// Side-by-side kernel benchmarks: amalgam's traditional traversal vs Intel Embree 3, in one
// process, on the same triangles and the same rays (issue 5, items 2a-2d).
//
//   ./build/bench/amalgam_embree_bench                       (all scenes; see scripts/bench.sh)
//   ./build/bench/amalgam_embree_bench --benchmark_filter=tiny --benchmark_min_time=0.01
//                                                             (smoke run, a few seconds)
//
// Ours: Traversal<ExplicitHierarchy, TraditionalLod, kStochastic, sorted, NullCounters>;
// `intersect` for closest hit, `transmittance` for any hit, over `build_explicit` with its
// default BuildConfig. Embree: rtcIntersect1 / rtcOccluded1 (single-ray API) on two scenes
// over one triangle geometry holding the same triangle soup (3 vertices per triangle, shared
// buffers): Embree's default configuration (what `rtcCommitScene` builds when nothing is set:
// RTC_BUILD_QUALITY_MEDIUM, no scene flags: BVH8 + Triangle4, Moeller-Trumbore, not
// watertight) and, beside it, the same with RTC_SCENE_FLAG_ROBUST (Pluecker test, robust box
// tests: like-for-like with our watertight triangle test). Builds are compared with the default.
//
// Each ray benchmark traces the whole ray set with ours, then with Embree (default), then with
// Embree (robust) in every iteration, timing each separately, so all see the same machine
// state; the counters give Mrays/s of each, per thread, speed_ratio = ours / Embree default
// and speed_ratio_robust = ours / Embree robust (> 1: ours is faster).
// Multi-threaded variants split the rays over a TBB arena of T threads for both.
//
// Before timing, every ray set is traced once by both and compared: same hit/miss (or
// occluded / unoccluded) and closest t within 1e-4 relative; the agreement is printed to
// stderr and reported as a counter.

#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "amalgam/hierarchy/bake/bake.h"
#include "amalgam/hierarchy/bake/orientation.h"
#include "amalgam/hierarchy/build/build.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/traverse/lod.h"
#include "amalgam/traverse/traverse.h"

namespace amalgam {
namespace {

using Clock = std::chrono::steady_clock;
using OurTraversal =
    Traversal<ExplicitHierarchy, TraditionalLod, StochasticOpacity, SortedOrder, NullCounters>;
/// The product path: what `amalgam render` and the experiments trace with (exact counters).
using CountedTraversal =
    Traversal<ExplicitHierarchy, TraditionalLod, StochasticOpacity, SortedOrder, Counters>;

const char* const kWuson = "/usr/share/assimp/models/PLY/Wuson.ply";
const char* const kEngine =
    "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

// ---- scenes -------------------------------------------------------------------------------

struct SceneSpec {
  std::string name;
  std::string mesh;          ///< file imported
  std::uint64_t target = 0;  ///< 0: the mesh itself; else a grid of copies of about this many
};

/// The triangles of a spec: the mesh, or a square grid (in x and z) of translated copies.
std::vector<Primitive> make_triangles(const SceneSpec& spec, std::vector<Surface>& materials) {
  ImportConfig ic;
  ic.max_triangles = 1'000'000'000;
  ImportedMesh m = import_mesh(spec.mesh, ic);
  materials = m.materials;
  if (spec.target == 0) return std::move(m.triangles);
  const std::uint64_t base = m.triangles.size();
  const std::uint64_t copies = std::max<std::uint64_t>(1, (spec.target + base / 2) / base);
  const auto k = static_cast<std::uint64_t>(std::ceil(std::sqrt(static_cast<double>(copies))));
  const Vec3 ext = m.bounds.hi - m.bounds.lo;
  const float sx = ext.x * 1.25f, sz = ext.z * 1.25f;
  std::vector<Primitive> out;
  out.reserve(copies * base);
  for (std::uint64_t c = 0; c < copies; ++c) {
    const Vec3 off{sx * static_cast<float>(c % k), 0.0f, sz * static_cast<float>(c / k)};
    for (Primitive p : m.triangles) {
      p.a += off, p.b += off, p.c += off;
      out.push_back(p);
    }
  }
  return out;
}

Bbox bounds_of(const std::vector<Primitive>& prims) {
  Bbox b;
  for (const Primitive& p : prims) b.extend(bounds(p));
  return b;
}

/// Sums the bytes an Embree device allocates (net of frees).
struct MemoryMonitor {
  std::atomic<std::int64_t> bytes{0};
  static bool callback(void* self, ssize_t bytes, bool /*post*/) {
    static_cast<MemoryMonitor*>(self)->bytes += bytes;
    return true;
  }
};

void embree_error(void*, RTCError code, const char* str) {
  std::fprintf(stderr, "embree error %d: %s\n", static_cast<int>(code), str ? str : "");
  std::abort();
}

/// Embree's copy of the triangles: one device, one geometry over shared buffers.
struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCGeometry geometry = nullptr;
  RTCScene scene = nullptr;            ///< default configuration
  RTCScene robust = nullptr;           ///< RTC_SCENE_FLAG_ROBUST
  std::vector<float> vertices;         ///< 3 per triangle, plus one float of padding at the end
  std::vector<std::uint32_t> indices;  ///< 0, 1, 2, 3, ...
  MemoryMonitor monitor;

  explicit EmbreeScene(const std::vector<Primitive>& prims) {
    device = rtcNewDevice(std::getenv("AMALGAM_EMBREE_CONFIG"));
    rtcSetDeviceErrorFunction(device, embree_error, nullptr);
    rtcSetDeviceMemoryMonitorFunction(device, &MemoryMonitor::callback, &monitor);
    vertices.reserve(prims.size() * 9 + 1);
    for (const Primitive& p : prims)
      for (Vec3 v : {p.a, p.b, p.c}) vertices.insert(vertices.end(), {v.x, v.y, v.z});
    vertices.push_back(0.0f);  // Embree may read 16 bytes at the last float3
    indices.resize(prims.size() * 3);
    for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<std::uint32_t>(i);
    geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               vertices.data(), 0, 3 * sizeof(float), prims.size() * 3);
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices.data(),
                               0, 3 * sizeof(std::uint32_t), prims.size());
    rtcCommitGeometry(geometry);
  }
  /// Builds a fresh scene over the geometry in Embree's default configuration (nothing set:
  /// RTC_BUILD_QUALITY_MEDIUM, RTC_SCENE_FLAG_NONE); returns the seconds rtcCommitScene took.
  double commit() {
    if (scene) rtcReleaseScene(scene);
    scene = rtcNewScene(device);
    rtcAttachGeometry(scene, geometry);
    const auto t0 = Clock::now();
    rtcCommitScene(scene);
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }
  /// The same geometry with RTC_SCENE_FLAG_ROBUST (built once, for the ray benchmarks).
  void commit_robust() {
    if (robust) return;
    robust = rtcNewScene(device);
    rtcSetSceneFlags(robust, RTC_SCENE_FLAG_ROBUST);
    rtcAttachGeometry(robust, geometry);
    rtcCommitScene(robust);
  }
  /// Bytes of the input buffers (shared, so not seen by the monitor).
  std::size_t buffer_bytes() const {
    return vertices.size() * sizeof(float) + indices.size() * sizeof(std::uint32_t);
  }
  ~EmbreeScene() {
    if (scene) rtcReleaseScene(scene);
    if (robust) rtcReleaseScene(robust);
    rtcReleaseGeometry(geometry);
    rtcReleaseDevice(device);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;
};

/// What both ray tracers agree on for one ray set.
struct Agreement {
  std::size_t rays = 0, same_hit = 0, same_t = 0, both_hit = 0;
  double fraction() const { return rays ? static_cast<double>(same_hit) / rays : 1.0; }
};

struct RaySet {
  std::vector<Ray> ours;
  std::vector<RTCRay> embree;  ///< the same rays in Embree's form
  Agreement agreement;
  double hit_fraction = 0;
};

RTCRay to_embree(const Ray& r) {
  RTCRay e{};
  e.org_x = r.origin.x, e.org_y = r.origin.y, e.org_z = r.origin.z;
  e.dir_x = r.dir.x, e.dir_y = r.dir.y, e.dir_z = r.dir.z;
  e.tnear = r.tmin;
  e.tfar = r.tmax;
  e.mask = 0xFFFFFFFFu;
  e.flags = 0;
  e.time = 0;
  e.id = 0;
  return e;
}

struct LoadedBenchScene {
  SceneSpec spec;
  ExplicitHierarchy ours;
  std::unique_ptr<EmbreeScene> embree;
  std::vector<Primitive> prims;  ///< input order, for the build benchmark
  std::vector<Surface> materials;
  Bbox box;
  double ours_build_s = 0, embree_build_s = 0;
  std::int64_t embree_bvh_bytes = 0;
  RaySet primary, shadow, random;
};

float embree_closest(RTCScene scene, const RTCRay& r, RTCIntersectContext* ctx) {
  RTCRayHit rh;
  rh.ray = r;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, ctx, &rh);
  return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? kInfinity : rh.ray.tfar;
}

bool embree_occluded(RTCScene scene, const RTCRay& r, RTCIntersectContext* ctx) {
  RTCRay ray = r;
  rtcOccluded1(scene, ctx, &ray);
  return ray.tfar < 0.0f;
}

/// Traces `set` with both and fills its agreement (closest hit or any hit).
void check_agreement(LoadedBenchScene& sc, RaySet& set, bool any_hit, const char* what) {
  NullCounters stats;
  OurTraversal tr(sc.ours, TraditionalLod{}, stats);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  Agreement a;
  std::size_t hits = 0;
  for (std::size_t i = 0; i < set.ours.size(); ++i) {
    ++a.rays;
    if (any_hit) {
      const bool o = tr.transmittance(set.ours[i], i) == 0.0f;
      const bool e = embree_occluded(sc.embree->scene, set.embree[i], &ctx);
      hits += o;
      if (o == e) ++a.same_hit, ++a.same_t;
    } else {
      const TraceHit h = tr.intersect(set.ours[i], i);
      const float te = embree_closest(sc.embree->scene, set.embree[i], &ctx);
      const bool o = h.kind != TraceHit::Kind::kNone, e = te != kInfinity;
      hits += o;
      if (o != e) continue;
      ++a.same_hit;
      if (!o) {
        ++a.same_t;
      } else {
        ++a.both_hit;
        if (std::fabs(h.t - te) <= 1e-4f * std::max(std::fabs(te), 1e-30f)) ++a.same_t;
      }
    }
  }
  set.agreement = a;
  set.hit_fraction = a.rays ? static_cast<double>(hits) / a.rays : 0.0;
  std::fprintf(stderr,
               "agreement %-12s %-8s rays %zu  same hit/miss %.4f%%  t within 1e-4 rel %.4f%%  "
               "(hits %.1f%%)\n",
               sc.spec.name.c_str(), what, a.rays, 100.0 * a.fraction(),
               100.0 * (a.rays ? static_cast<double>(a.same_t) / a.rays : 1.0),
               100.0 * set.hit_fraction);
}

void finish_set(RaySet& s) {
  s.embree.clear();
  s.embree.reserve(s.ours.size());
  for (const Ray& r : s.ours) s.embree.push_back(to_embree(r));
}

constexpr int kImageW = 256, kImageH = 256;
constexpr std::size_t kRandomRays = 65536;

/// Primary rays of a pinhole camera looking at the scene's centre from above a corner.
void make_primary(LoadedBenchScene& sc) {
  const Vec3 c = (sc.box.lo + sc.box.hi) * 0.5f;
  const Vec3 ext = sc.box.hi - sc.box.lo;
  const float diag = length(ext);
  const Vec3 eye = c + normalize(Vec3{0.6f, 0.7f, 1.0f}) * (0.6f * diag);
  const Vec3 fwd = normalize(c - eye);
  const Vec3 right = normalize(cross(fwd, Vec3{0, 1, 0}));
  const Vec3 up = cross(right, fwd);
  const float half = std::tan(0.5f * 50.0f * 3.14159265f / 180.0f);
  sc.primary.ours.clear();
  for (int y = 0; y < kImageH; ++y)
    for (int x = 0; x < kImageW; ++x) {
      const float u = (2.0f * (x + 0.5f) / kImageW - 1.0f) * half;
      const float v = (1.0f - 2.0f * (y + 0.5f) / kImageH) * half;
      sc.primary.ours.push_back(Ray::make(eye, normalize(fwd + right * u + up * v)));
    }
  finish_set(sc.primary);
}

/// Shadow rays from our primary hits toward a point light above the scene (rays that miss
/// make no shadow ray). Origins are offset along the normal by the hit's error bound.
void make_shadow(LoadedBenchScene& sc) {
  const Vec3 c = (sc.box.lo + sc.box.hi) * 0.5f;
  const float diag = length(sc.box.hi - sc.box.lo);
  const Vec3 light = c + Vec3{0.3f, 1.0f, 0.2f} * diag;
  NullCounters stats;
  OurTraversal tr(sc.ours, TraditionalLod{}, stats);
  sc.shadow.ours.clear();
  for (std::size_t i = 0; i < sc.primary.ours.size(); ++i) {
    const TraceHit h = tr.intersect(sc.primary.ours[i], i);
    if (h.kind == TraceHit::Kind::kNone) continue;
    const Vec3 o = offset_ray_origin(h.surf.p, h.surf.p_error, h.surf.normal);
    const Vec3 d = light - o;
    const float dist = length(d);
    sc.shadow.ours.push_back(Ray::make(o, d / dist, 0.0f, dist * (1.0f - 1e-4f)));
  }
  finish_set(sc.shadow);
}

/// Incoherent rays: uniform origins in the scene bounds, uniform directions.
void make_random(LoadedBenchScene& sc) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  sc.random.ours.clear();
  const Vec3 ext = sc.box.hi - sc.box.lo;
  for (std::size_t i = 0; i < kRandomRays; ++i) {
    const Vec3 o = sc.box.lo + Vec3{u(rng) * ext.x, u(rng) * ext.y, u(rng) * ext.z};
    const float z = 1.0f - 2.0f * u(rng), phi = 6.28318531f * u(rng);
    const float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
    sc.random.ours.push_back(Ray::make(o, Vec3{s * std::cos(phi), s * std::sin(phi), z}));
  }
  finish_set(sc.random);
}

std::size_t our_bytes(const ExplicitHierarchy& h) {
  return h.nodes.size() * sizeof(ExplicitNode) + h.appearances.size() * sizeof(Appearance) +
         h.prims.bytes() + h.materials.size() * sizeof(Surface) +
         h.wide.bytes();  // SoA child boxes of the SIMD traversal (hierarchy/wide.h)
}

/// One scene at a time stays in memory: asking for another frees the current one.
LoadedBenchScene& scene_for(const SceneSpec& spec) {
  static std::unique_ptr<LoadedBenchScene> current;
  if (current && current->spec.name == spec.name) return *current;
  current.reset();
  auto sc = std::make_unique<LoadedBenchScene>();
  sc->spec = spec;
  sc->prims = make_triangles(spec, sc->materials);
  sc->box = bounds_of(sc->prims);
  auto t0 = Clock::now();
  sc->ours = build_explicit(sc->prims, sc->materials);
  sc->ours_build_s = std::chrono::duration<double>(Clock::now() - t0).count();
  sc->embree = std::make_unique<EmbreeScene>(sc->prims);
  const std::int64_t before = sc->embree->monitor.bytes;
  sc->embree_build_s = sc->embree->commit();
  sc->embree_bvh_bytes = sc->embree->monitor.bytes - before;
  std::fprintf(stderr,
               "scene %-12s %zu triangles: build ours %.3f s, embree %.3f s; bytes/tri ours %.1f, "
               "embree bvh %.1f (+ %.1f input buffers)\n",
               spec.name.c_str(), sc->prims.size(), sc->ours_build_s, sc->embree_build_s,
               static_cast<double>(our_bytes(sc->ours)) / sc->prims.size(),
               static_cast<double>(sc->embree_bvh_bytes) / sc->prims.size(),
               static_cast<double>(sc->embree->buffer_bytes()) / sc->prims.size());
  make_primary(*sc);
  make_shadow(*sc);
  make_random(*sc);
  check_agreement(*sc, sc->primary, false, "primary");
  check_agreement(*sc, sc->shadow, true, "shadow");
  check_agreement(*sc, sc->random, false, "random");
  current = std::move(sc);
  return *current;
}

// ---- benchmarks ---------------------------------------------------------------------------

enum class RayKindB { kPrimary, kShadow, kRandom };

/// Runs body(begin, end) over [0, n) on `threads` threads (the calling thread alone for 1).
void run_split(tbb::task_arena* arena, std::size_t n,
               const std::function<void(std::size_t, std::size_t)>& body) {
  if (!arena) return body(0, n);
  arena->execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  });
}

void bm_rays(benchmark::State& state, SceneSpec spec, RayKindB kind, int threads) {
  LoadedBenchScene& sc = scene_for(spec);
  RaySet& set = kind == RayKindB::kPrimary  ? sc.primary
                : kind == RayKindB::kShadow ? sc.shadow
                                            : sc.random;
  const bool any_hit = kind == RayKindB::kShadow;
  std::unique_ptr<tbb::task_arena> arena;
  if (threads > 1) arena = std::make_unique<tbb::task_arena>(threads);
  const std::size_t n = set.ours.size();
  std::atomic<std::uint64_t> sink{0};

  // The counted pass's totals (nodes reached, box and primitive tests: the work per ray).
  std::atomic<std::uint64_t> reached{0}, box_tests{0}, prim_tests{0};
  auto ours_with = [&]<class Tr, class Stats>(std::size_t b, std::size_t e) {
    Stats stats;
    Tr tr(sc.ours, TraditionalLod{}, stats);
    std::uint64_t hits = 0;
    for (std::size_t i = b; i < e; ++i) {
      if (any_hit)
        hits += tr.transmittance(set.ours[i], i) == 0.0f;
      else
        hits += tr.intersect(set.ours[i], i).kind != TraceHit::Kind::kNone;
    }
    sink += hits;
    if constexpr (std::is_same_v<Stats, Counters>) {
      reached += stats.reached[0] + stats.reached[1];
      box_tests +=
          stats.tests_of(ObjectKind::kBoundingVolume) + stats.tests_of(ObjectKind::kAmalgam);
      prim_tests += stats.tests_of(ObjectKind::kPrimitive);
    }
  };
  auto ours = [&](std::size_t b, std::size_t e) {
    ours_with.template operator()<OurTraversal, NullCounters>(b, e);
  };
  auto counted = [&](std::size_t b, std::size_t e) {
    ours_with.template operator()<CountedTraversal, Counters>(b, e);
  };
  sc.embree->commit_robust();
  auto embree_in = [&](RTCScene scene) {
    return [&, scene](std::size_t b, std::size_t e) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      std::uint64_t hits = 0;
      for (std::size_t i = b; i < e; ++i) {
        if (any_hit)
          hits += embree_occluded(scene, set.embree[i], &ctx);
        else
          hits += embree_closest(scene, set.embree[i], &ctx) != kInfinity;
      }
      sink += hits;
    };
  };
  const auto embree = embree_in(sc.embree->scene), robust = embree_in(sc.embree->robust);

  // Ours, Embree, ours counted, Embree robust: each of our passes follows one of Embree's (on
  // the large scenes the caches then hold the other structure), as each of Embree's follows
  // one of ours.
  // AMALGAM_BENCH_ONLY=ours|embree|counted|robust runs that pass alone, to profile one side
  // with perf or callgrind (the ratios are then meaningless).
  const char* only_env = std::getenv("AMALGAM_BENCH_ONLY");
  const std::string only = only_env ? only_env : "";
  auto pass = [&](const char* name, const auto& body) {
    if (only.empty() || only == name) run_split(arena.get(), n, body);
  };
  double t_ours = 0, t_embree = 0, t_robust = 0, t_counted = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    pass("ours", ours);
    const auto t1 = Clock::now();
    pass("embree", embree);
    const auto t2 = Clock::now();
    pass("counted", counted);
    const auto t3 = Clock::now();
    pass("robust", robust);
    const auto t4 = Clock::now();
    t_ours += std::chrono::duration<double>(t1 - t0).count();
    t_embree += std::chrono::duration<double>(t2 - t1).count();
    t_counted += std::chrono::duration<double>(t3 - t2).count();
    t_robust += std::chrono::duration<double>(t4 - t3).count();
    state.SetIterationTime(std::chrono::duration<double>(t4 - t0).count());
  }
  benchmark::DoNotOptimize(sink.load());
  const double rays = static_cast<double>(n) * static_cast<double>(state.iterations());
  const double m_ours = rays / t_ours * 1e-6, m_embree = rays / t_embree * 1e-6;
  const double m_robust = rays / t_robust * 1e-6;
  state.counters["embree_robust_Mrays_s"] = m_robust;
  // The counted traversal's throughput over the uncounted one's (issue 14: within 10 %).
  state.counters["counted_Mrays_s"] = rays / t_counted * 1e-6;
  state.counters["counted_ratio"] = t_ours / t_counted;
  state.counters["speed_ratio_robust"] = m_ours / m_robust;
  state.counters["rays"] = static_cast<double>(n);
  if (t_counted > 0) {
    state.counters["nodes_per_ray"] = static_cast<double>(reached.load()) / rays;
    state.counters["box_tests_per_ray"] = static_cast<double>(box_tests.load()) / rays;
    state.counters["prim_tests_per_ray"] = static_cast<double>(prim_tests.load()) / rays;
  }
  state.counters["threads"] = threads;
  state.counters["triangles"] = static_cast<double>(sc.prims.size());
  state.counters["ours_Mrays_s"] = m_ours;
  state.counters["embree_Mrays_s"] = m_embree;
  state.counters["ours_Mrays_s_per_thread"] = m_ours / threads;
  state.counters["embree_Mrays_s_per_thread"] = m_embree / threads;
  state.counters["speed_ratio"] = m_ours / m_embree;
  state.counters["agreement"] = set.agreement.fraction();
  state.counters["hit_fraction"] = set.hit_fraction;
}

void bm_build(benchmark::State& state, SceneSpec spec) {
  LoadedBenchScene& sc = scene_for(spec);
  double t_ours = 0, t_bake = 0, t_orient = 0, t_embree = 0;
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::vector<Primitive> prims = sc.prims;  // build_explicit consumes its input
    std::vector<Surface> mats = sc.materials;
    auto t0 = Clock::now();
    ExplicitHierarchy h = build_explicit(std::move(prims), std::move(mats));
    const auto t_built = Clock::now();
    h.prims.edit();  // untimed: back to the whole form the bake starts from in build_explicit
    auto t1 = Clock::now();
    bake(h);  // again, alone: the bake's share of build_explicit
    const auto t_baked = Clock::now();
    const std::vector<Primitive> whole = h.prims.to_vector();  // untimed, as above
    auto t2 = Clock::now();
    benchmark::DoNotOptimize(closed_orientation(whole));  // the bake's closed-surface check
    t_orient += std::chrono::duration<double>(Clock::now() - t2).count();
    bytes = our_bytes(h);
    const double te = sc.embree->commit();
    t_ours += std::chrono::duration<double>(t_built - t0).count();
    t_bake += std::chrono::duration<double>(t_baked - t1).count();
    t_embree += te;
    state.SetIterationTime(std::chrono::duration<double>(t_built - t0).count() + te);
  }
  const double it = static_cast<double>(state.iterations());
  const double tris = static_cast<double>(sc.prims.size());
  state.counters["triangles"] = tris;
  state.counters["ours_build_s"] = t_ours / it;
  state.counters["ours_bake_s"] = t_bake / it;
  state.counters["ours_closed_check_s"] = t_orient / it;
  state.counters["embree_build_s"] = t_embree / it;
  state.counters["time_ratio"] = t_ours / t_embree;
  state.counters["ours_bytes_per_tri"] = static_cast<double>(bytes) / tris;
  // By structure (the hierarchy of the last iteration is the scene's own build's twin).
  const ExplicitHierarchy& o = sc.ours;
  state.counters["ours_nodes_bytes_per_tri"] =
      static_cast<double>(o.nodes.size() * sizeof(ExplicitNode)) / tris;
  state.counters["ours_appearances_bytes_per_tri"] =
      static_cast<double>(o.appearances.size() * sizeof(Appearance)) / tris;
  state.counters["ours_simd_nodes_bytes_per_tri"] = static_cast<double>(o.wide.bytes()) / tris;
  state.counters["ours_prims_bytes_per_tri"] = static_cast<double>(o.prims.bytes()) / tris;
  state.counters["embree_bvh_bytes_per_tri"] = static_cast<double>(sc.embree_bvh_bytes) / tris;
  state.counters["embree_total_bytes_per_tri"] =
      static_cast<double>(sc.embree_bvh_bytes +
                          static_cast<std::int64_t>(sc.embree->buffer_bytes())) /
      tris;
}

std::vector<SceneSpec> scenes() {
  // "tiny_wuson" (the mesh itself, 3732 triangles) is also the smoke test's scene.
  std::vector<SceneSpec> s = {{"tiny_wuson", kWuson, 0}, {"engine", kEngine, 0}};
  const char* max_env = std::getenv("AMALGAM_BENCH_MAX_TRIANGLES");
  const double max_tris = max_env ? std::atof(max_env) : 1e7;
  for (double n : {1e4, 1e5, 1e6, 1e7, 1e8})
    if (n <= max_tris)
      s.push_back({"grid_1e" + std::to_string(static_cast<int>(std::lround(std::log10(n)))), kWuson,
                   static_cast<std::uint64_t>(n)});
  return s;
}

void register_all() {
  const int hw = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  for (const SceneSpec& spec : scenes()) {
    std::vector<int> thread_counts{1};
    if (hw > 1) thread_counts.push_back(hw);
    for (auto [kind, label] :
         {std::pair{RayKindB::kPrimary, "primary"}, std::pair{RayKindB::kShadow, "shadow"},
          std::pair{RayKindB::kRandom, "random"}})
      for (int t : thread_counts)
        benchmark::RegisterBenchmark(
            ("Rays/" + spec.name + "/" + label + "/threads:" + std::to_string(t)).c_str(),
            [spec, kind, t](benchmark::State& st) { bm_rays(st, spec, kind, t); })
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("Build/" + spec.name).c_str(),
                                 [spec](benchmark::State& st) { bm_build(st, spec); })
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond)
        ->Iterations(spec.target >= 10'000'000 ? 1 : (spec.target >= 1'000'000 ? 2 : 5));
  }
}

}  // namespace
}  // namespace amalgam

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  amalgam::register_all();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

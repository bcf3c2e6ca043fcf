// Differential tests of the fast traversal (traverse.h: SIMD child boxes and triangle packs
// from hierarchy/wide.h, iterative stack, per-ray triangle setup, deferred SurfaceHit): the
// SIMD kernels against the scalar ones lane by lane, and the traversal against the scalar
// reference (reference.h, the original recursive traversal): on random rays over a real mesh
// and over the builtins, the same hit (kind, id, level; t within 1e-6 relative; the same
// surface), the same transmittance and the same counts per ray kind, object kind and level,
// for every combination of LOD policy, opacity model and child order.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <type_traits>

#include "amalgam/builtin/prisms.h"
#include "amalgam/builtin/tube.h"
#include "amalgam/hierarchy/build/build.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/flatten.h"
#include "amalgam/hierarchy/instanced.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/traverse/lod.h"
#include "amalgam/traverse/reference.h"
#include "amalgam/traverse/traverse.h"
#include "amalgam/util/error.h"
#include "amalgam/util/isa.h"
#include "avx2_kernels.h"

namespace amalgam {
namespace {

const char* const kWuson = "/usr/share/assimp/models/PLY/Wuson.ply";

/// Random rays: origins uniform in `box` grown by half its size, directions uniform on the
/// sphere; every 8th ray axis-parallel (zero direction components: the slab test's special
/// case), every 8th starts inside the box, all with a random cone for footprint decisions.
std::vector<Ray> random_rays(const Bbox& box, int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const Vec3 ext = box.extent();
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    const float g = i % 8 == 1 ? 0.0f : 0.5f;
    const Vec3 o = box.lo - ext * g + Vec3{u(rng), u(rng), u(rng)} * ext * (1.0f + 2.0f * g);
    Vec3 d;
    if (i % 8 == 0) {
      d = Vec3{};
      d[static_cast<int>(u(rng) * 3.0f) % 3] = u(rng) < 0.5f ? -1.0f : 1.0f;
    } else if (i % 8 == 4) {  // one zero component
      const float phi = 6.2831853f * u(rng);
      d = {std::cos(phi), std::sin(phi), 0.0f};
    } else {
      const float z = 2.0f * u(rng) - 1.0f, phi = 6.2831853f * u(rng);
      const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      d = {r * std::cos(phi), r * std::sin(phi), z};
    }
    Ray ray = Ray::make(o, d);
    ray.cone_spread = 0.02f * u(rng);
    rays.push_back(ray);
  }
  return rays;
}

void expect_same_counts(const Counters& a, const Counters& b, const std::string& what) {
  EXPECT_EQ(a.tests, b.tests) << what;
  EXPECT_EQ(a.by_level, b.by_level) << what;
  EXPECT_EQ(a.reached, b.reached) << what << ": objects traversed (the paper's counting)";
  EXPECT_EQ(a.rays, b.rays) << what;
}

void expect_same_hit(const TraceHit& a, const TraceHit& b, const std::string& what) {
  ASSERT_EQ(a.kind, b.kind) << what;
  if (a.kind == TraceHit::Kind::kNone) return;
  EXPECT_EQ(a.id, b.id) << what;
  EXPECT_EQ(a.level, b.level) << what;
  EXPECT_LE(std::fabs(a.t - b.t), 1e-6f * std::fabs(b.t)) << what;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.surf.normal[k], b.surf.normal[k]) << what;
    EXPECT_EQ(a.surf.p[k], b.surf.p[k]) << what;
    EXPECT_EQ(a.surf.p_error[k], b.surf.p_error[k]) << what;
  }
}

/// Fast vs reference on `rays`, closest hit and shadow, one policy combination.
template <class H, class Lod, class Opacity, class Order>
void compare(const H& h, const Lod& lod, const std::vector<Ray>& rays, const std::string& name) {
  Counters cf, cr;
  Traversal<H, Lod, Opacity, Order> fast(h, lod, cf);
  ReferenceTraversal<H, Lod, Opacity, Order> ref(h, lod, cr);
  std::vector<TranslucentHit> tf, tr;
  int hits = 0;
  const bool failed_before = ::testing::Test::HasFailure();
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const std::string what = name + " ray " + std::to_string(i);
    tf.clear(), tr.clear();
    const TraceHit a = fast.intersect(rays[i], i, &tf);
    const TraceHit b = ref.intersect(rays[i], i, &tr);
    expect_same_hit(a, b, what);
    hits += b.kind != TraceHit::Kind::kNone;
    ASSERT_EQ(tf.size(), tr.size()) << what;
    for (std::size_t k = 0; k < tf.size(); ++k) EXPECT_EQ(tf[k].id, tr[k].id) << what;
    EXPECT_EQ(fast.transmittance(rays[i], i + 7), ref.transmittance(rays[i], i + 7)) << what;
    if (!failed_before && ::testing::Test::HasFailure()) break;  // one ray's report is enough
  }
  expect_same_counts(cf, cr, name);
  if constexpr (std::is_same_v<Lod, TraditionalLod>) {
    EXPECT_GT(hits, 0) << name << ": the rays must hit something";
  }
  EXPECT_GE(cr.total(), 2 * rays.size()) << name << ": every ray tests the root, twice";
}

template <class H>
void compare_all(const H& h, const std::vector<Ray>& rays, int levels, const std::string& name) {
  auto each_order = [&]<class Lod, class Opacity>(const Lod& lod, const std::string& n) {
    compare<H, Lod, Opacity, SortedOrder>(h, lod, rays, n + " sorted");
    compare<H, Lod, Opacity, StoredOrder>(h, lod, rays, n + " unsorted");
  };
  auto each_opacity = [&]<class Lod>(const Lod& lod, const std::string& n) {
    each_order.template operator()<Lod, StochasticOpacity>(lod, n + " stochastic");
    each_order.template operator()<Lod, DeterministicOpacity>(lod, n + " deterministic");
  };
  each_opacity(TraditionalLod{}, name + " traditional");
  for (int l : {0, 1, levels / 2, levels - 2})
    each_opacity(ScaleSensitiveLod::on_level(l), name + " level " + std::to_string(l));
  for (float k : {1.0f, 8.0f})
    each_opacity(ScaleSensitiveLod::by_footprint(k), name + " footprint " + std::to_string(k));
}

std::uint32_t bits(float f) {
  return std::bit_cast<std::uint32_t>(f);
}

/// The box kernel on `lanes` boxes (4: the portable copy, on either half of a node's 8-lane
/// rows; 8: the AVX2 copy's kernel on whole rows) against the scalar test: same hit mask and
/// the same entry t, bit for bit, in both of its modes (kNonZero only for the rays
/// `box_rays_simple` admits).
void check_box_kernel(int lanes) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  int hits = 0, simple_rays = 0;
  for (int i = 0; i < 20000; ++i) {
    WideBox8 blk;
    Bbox boxes[kBoxLanes];
    // The 4-lane kernel reads the lower half of the block or, every other case, the upper.
    const int c0 = lanes == kWideLanes && i % 2 ? kWideLanes : 0;
    for (int lane = 0; lane < lanes; ++lane) {
      // Some degenerate (flat) boxes, some sharing a plane with the ray origin, some empty.
      boxes[lane] = Bbox::of({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)});
      if (i % 5 == 0) boxes[lane].hi.y = boxes[lane].lo.y;
      if (i % 11 == 0 && lane == 1) boxes[lane] = Bbox{};
      for (int a = 0; a < 3; ++a)
        blk.lo[a][c0 + lane] = boxes[lane].lo[a], blk.hi[a][c0 + lane] = boxes[lane].hi[a];
    }
    Vec3 o{u(rng), u(rng), u(rng)}, d{u(rng), u(rng), u(rng)};
    if (i % 3 == 0) d[i % 2] = 0.0f;
    if (i % 13 == 0) d.z = i % 2 ? 1e-40f : -0.0f;  // an infinite inverse; a negative zero
    if (i % 7 == 0) o.x = boxes[0].lo.x;
    if (i % 17 == 0) o.y = boxes[0].hi.y;
    Ray ray = Ray::make(o, d, i % 4 == 0 ? 0.5f : 0.0f, i % 6 == 0 ? 1.0f : kInfinity);
    const bool simple = box_rays_simple(ray);
    simple_rays += simple;
    for (const bool fast : {false, true}) {
      if (fast && !simple) continue;
      float t[kBoxLanes];
      unsigned m;
#if defined(AMALGAM_BUILD_AVX2_COPY)
      if (lanes > kWideLanes)
        m = test::avx2_box_test8(blk.rows(), ray, lanes, t, fast);
      else
#endif
        m = fast ? intersect_wide4<false>(blk.rows(), c0, WideRay::of(ray), ray.tmin, ray.tmax,
                                          lanes, t)
                 : intersect_wide4(blk.rows(), c0, WideRay::of(ray), ray.tmin, ray.tmax, lanes, t);
      ASSERT_EQ(m >> lanes, 0u) << "case " << i;
      for (int lane = 0; lane < lanes; ++lane) {
        const auto s = intersect_box(ray, boxes[lane]);
        ASSERT_EQ(((m >> lane) & 1u) != 0, s.has_value())
            << "case " << i << " lane " << lane << " simple " << fast;
        if (s) {
          EXPECT_EQ(bits(t[lane]), bits(s->t0)) << "case " << i << " lane " << lane;
          hits += !fast;
        }
      }
    }
  }
  EXPECT_GT(hits, 250 * lanes);
  EXPECT_GT(simple_rays, 10000);
  EXPECT_LT(simple_rays, 15000);
}

TEST(SimdTraversal, WideBoxKernelMatchesScalarBoxTest) {
  check_box_kernel(kWideLanes);
}

#if defined(AMALGAM_BUILD_AVX2_COPY)
TEST(SimdTraversal, EightLaneBoxKernelMatchesScalarBoxTest) {
  if (!simd_avx2_supported()) GTEST_SKIP() << "this CPU has no AVX2";
  check_box_kernel(kBoxLanes);
}
#endif

TEST(SimdTraversal, TriangleSplitMatchesWholeTest) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)}, c{u(rng), u(rng), u(rng)};
    const Ray ray = Ray::make({u(rng), u(rng), 3.0f}, {u(rng) * 0.3f, u(rng) * 0.3f, -1.0f});
    const auto whole = intersect_triangle(ray, a, b, c);
    TriangleCandidate h;
    const bool hit = triangle_test(ray, TrianglePre::of(ray), a, b, c, h);
    ASSERT_EQ(hit, whole.has_value());
    if (!hit) continue;
    const SurfaceHit s = triangle_finish(ray, a, b, c, h);
    EXPECT_EQ(s.t, whole->t);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(s.p[k], whole->p[k]);
      EXPECT_EQ(s.normal[k], whole->normal[k]);
    }
  }
}

/// Packs of four triangles for the pack kernel: on a coarse integer lattice (so triangles
/// share edges and vertices exactly and rays through lattice points cross edges and vertices
/// exactly: u, v or w is 0, the double-precision case), some degenerate (a repeated vertex,
/// three collinear vertices, all three equal), some duplicated (equal t in two lanes), the
/// rest random.
TrianglePack4 random_pack(std::mt19937& rng, int i, Vec3 tri[kWideLanes][3]) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::uniform_int_distribution<int> grid(-2, 2);
  auto lattice = [&] { return Vec3{float(grid(rng)), float(grid(rng)), float(grid(rng))}; };
  TrianglePack4 p;
  for (int lane = 0; lane < kWideLanes; ++lane) {
    Vec3* t = tri[lane];
    switch ((i + lane) % 6) {
      case 0:  // lattice triangles: shared edges and vertices between lanes and packs
      case 1:
        t[0] = lattice(), t[1] = lattice(), t[2] = lattice();
        break;
      case 2:  // degenerate: repeated vertex, collinear, or a point
        t[0] = lattice(), t[1] = lattice();
        t[2] = i % 3 == 0 ? t[0] : i % 3 == 1 ? t[0] + (t[1] - t[0]) * 2.0f : t[0];
        if (i % 3 == 2) t[1] = t[0];
        break;
      case 3:  // a copy of the previous lane (ties in t), or of lane 0 with its edge reversed
        if (lane > 0) {
          t[0] = tri[lane - 1][0], t[1] = tri[lane - 1][1], t[2] = tri[lane - 1][2];
          if (i % 2) std::swap(t[1], t[2]);
          break;
        }
        [[fallthrough]];
      default:
        for (int k = 0; k < 3; ++k) t[k] = {u(rng), u(rng), u(rng)};
    }
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) p.v[k][a][lane] = t[k][a];
  }
  return p;
}

/// The pack kernel on `lanes` triangles (4: one pack, the portable copy; 8: two packs at once,
/// the AVX2 copy's kernel for leaves of 5..8 triangles) against the scalar test: same hit mask,
/// bit-identical t, u, v, w, det per lane.
void check_triangle_kernel(int lanes, int cases) {
  std::mt19937 rng(lanes == kWideLanes ? 11 : 13);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::uniform_int_distribution<int> grid(-2, 2);
  int hits = 0, edge_hits = 0, high_lane_hits = 0;
  for (int i = 0; i < cases; ++i) {
    Vec3 tri[2 * kWideLanes][3];
    const TrianglePack4 packs[2] = {random_pack(rng, i, tri), random_pack(rng, i + 1, tri + 4)};
    Vec3 o{u(rng), u(rng), u(rng)}, d{u(rng), u(rng), u(rng)};
    if (i % 4 == 0) {  // axis-parallel through lattice points: exactly through edges, vertices
      const int axis = i / 4 % 3;
      o = {float(grid(rng)), float(grid(rng)), float(grid(rng))};
      o[axis] = 3.0f;
      d = {};
      d[axis] = i % 8 == 0 ? -1.0f : 1.0f;
    } else if (i % 4 == 1) {  // aimed at a vertex or an edge's midpoint
      const Vec3* t = tri[i / 4 % lanes];
      o = o * 3.0f;
      d = (i % 8 == 1 ? t[0] : (t[1] + t[2]) * 0.5f) - o;
    } else if (i % 4 == 2) {  // diagonal through lattice points
      o = {float(grid(rng)), float(grid(rng)), 3.0f};
      d = {0.5f * float(grid(rng)), 0.5f * float(grid(rng)), -1.0f};
    }
    const float tmin = i % 5 == 0 ? 0.5f : 0.0f, tmax = i % 7 == 0 ? 1.5f : kInfinity;
    const Ray ray = Ray::make(o, d, tmin, tmax);
    const TrianglePre pre = TrianglePre::of(ray);
    const int n = 1 + i % lanes;
    float out[5][2 * kWideLanes];
    unsigned mask;
#if defined(AMALGAM_BUILD_AVX2_COPY)
    if (lanes > kWideLanes) {
      mask = test::avx2_triangle_test8(packs, ray, tmin, tmax, n, out);
    } else
#endif
    {
      TrianglePackHits h;
      mask = triangle_test4(packs[0], WideRay::of(ray), tmin, tmax, n, h);
      for (int l = 0; l < kWideLanes; ++l)
        out[0][l] = h.t[l], out[1][l] = h.u[l], out[2][l] = h.v[l], out[3][l] = h.w[l],
        out[4][l] = h.det[l];
    }
    ASSERT_EQ(mask >> n, 0u) << "case " << i << ": lanes beyond n";
    for (int lane = 0; lane < n; ++lane) {
      TriangleCandidate h;
      const bool hit = triangle_test(ray, pre, tri[lane][0], tri[lane][1], tri[lane][2], h);
      ASSERT_EQ(((mask >> lane) & 1u) != 0, hit) << "case " << i << " lane " << lane;
      if (!hit) continue;
      ++hits;
      high_lane_hits += lane >= kWideLanes;
      edge_hits += h.u == 0.0f || h.v == 0.0f || h.w == 0.0f;
      EXPECT_EQ(bits(out[0][lane]), bits(h.t)) << "case " << i << " lane " << lane;
      EXPECT_EQ(bits(out[1][lane]), bits(h.u)) << "case " << i << " lane " << lane;
      EXPECT_EQ(bits(out[2][lane]), bits(h.v)) << "case " << i << " lane " << lane;
      EXPECT_EQ(bits(out[3][lane]), bits(h.w)) << "case " << i << " lane " << lane;
      EXPECT_EQ(bits(out[4][lane]), bits(h.det)) << "case " << i << " lane " << lane;
    }
  }
  EXPECT_GT(hits, cases / 8);
  if (lanes > kWideLanes) {
    EXPECT_GT(high_lane_hits, cases / 20) << "the second pack's lanes";
  }
  EXPECT_GT(edge_hits, cases / 80) << "rays through edges and vertices must be covered";
}

TEST(SimdTraversal, TrianglePackKernelMatchesScalarTriangleTest) {
  check_triangle_kernel(kWideLanes, 40000);
}

#if defined(AMALGAM_BUILD_AVX2_COPY)
TEST(SimdTraversal, EightLaneTriangleKernelMatchesScalarTriangleTest) {
  if (!simd_avx2_supported()) GTEST_SKIP() << "this CPU has no AVX2";
  check_triangle_kernel(2 * kWideLanes, 20000);
}
#endif

/// Triangle-only leaves of several packs (leaf sizes 5..9), duplicated triangles (ties in t
/// inside a leaf and across its packs) and rays along lattice lines through shared edges and
/// vertices: the pack path's closest-hit choice and counts against the reference.
TEST(SimdTraversal, TriangleLeavesMatchReference) {
  std::vector<Primitive> prims;
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y)
      for (int z = 0; z < 3; ++z) {
        const Vec3 p{float(x), float(y), float(2 * z)};
        prims.push_back(Primitive::triangle(p, p + Vec3{1, 0, 0}, p + Vec3{0, 1, 0}));
        prims.push_back(
            Primitive::triangle(p + Vec3{1, 0, 0}, p + Vec3{1, 1, 0}, p + Vec3{0, 1, 0}));
        if ((x + y + z) % 3 == 0) prims.push_back(prims.back());  // an exact duplicate
        if ((x + y) % 4 == 1) prims.push_back(Primitive::triangle(p, p, p + Vec3{1, 1, 0}));
      }
  const Bbox box = Bbox::of({0, 0, 0}, {8, 8, 5});
  std::vector<Ray> rays = random_rays(box, 600, 23);
  std::mt19937 rng(29);
  std::uniform_int_distribution<int> grid(0, 8);
  for (int i = 0; i < 600; ++i) {  // through lattice points: shared edges and vertices
    const Vec3 o{0.5f * float(grid(rng)), 0.5f * float(grid(rng)), 7.0f};
    rays.push_back(Ray::make(o, i % 2 ? Vec3{0, 0, -1} : Vec3{0.5f, 0.25f, -1.0f}));
  }
  for (int leaf : {5, 8, 9}) {
    BuildConfig bc;
    bc.arity = 4;
    bc.leaf_size = leaf;
    bc.parallel = false;
    const ExplicitHierarchy h = build_explicit(prims, {Surface{}}, bc);
    ASSERT_NE(h.wide_nodes(), nullptr);
    int multi_pack = 0;  // leaves of more than one pack
    for (const WideHeader& hd : h.wide.headers)
      multi_pack += hd.leaf == kWideTriangleLeaf && hd.count > kWideLanes;
    ASSERT_GT(multi_pack, 0) << "leaf size " << leaf;
    compare_all(h, rays, h.levels, "lattice leaf " + std::to_string(leaf));
  }
}

class SimdMesh : public ::testing::TestWithParam<int> {};

TEST_P(SimdMesh, WusonMatchesReference) {
  ASSERT_TRUE(std::filesystem::exists(kWuson))
      << kWuson << " missing (assimp-testmodels, scripts/deps.sh)";
  const ImportedMesh m = import_mesh(kWuson);
  BuildConfig bc;
  bc.arity = GetParam();
  bc.parallel = false;
  const ExplicitHierarchy h = build_explicit(m.triangles, m.materials, bc);
  ASSERT_NE(h.wide_nodes(), nullptr) << "build_explicit builds the SoA boxes";
  compare_all(h, random_rays(m.bounds, 2000, 17 + GetParam()), h.levels,
              "wuson arity " + std::to_string(GetParam()));
}

INSTANTIATE_TEST_SUITE_P(Arity, SimdMesh, ::testing::Values(2, 4, 8, 13));

TEST(SimdTraversal, BuiltinsMatchReference) {
  PrismsHierarchy::Config pc;
  pc.split = 3, pc.depth = 3, pc.leaf = 2;
  const PrismsHierarchy prisms(pc);
  const Bbox pb = prisms.bounds(prisms.root());
  compare_all(prisms, random_rays(pb, 300, 3), pc.depth + 1, "prisms");
  // The same scene flattened to explicit form, with the SoA boxes: the wide path with
  // spheres/boxes as primitives and amalgams rendered on every level.
  ExplicitHierarchy flat = flatten(prisms, pc.depth + 1);
  EXPECT_EQ(flat.wide_nodes(), nullptr) << "flatten does not bake; no SoA boxes yet";
  EXPECT_TRUE(flat.wide_stale());
  Counters unused;
  EXPECT_THROW((Traversal<ExplicitHierarchy, TraditionalLod, StochasticOpacity>(flat, {}, unused)),
               InternalError)
      << "a hierarchy without its SIMD form is refused, not walked slowly";
  build_wide(flat);
  EXPECT_FALSE(flat.wide_stale());
  ASSERT_NE(flat.wide_nodes(), nullptr);
  compare_all(flat, random_rays(pb, 300, 4), pc.depth + 1, "prisms flattened");

  TubeHierarchy::Config tc;
  tc.mode = TubeHierarchy::Mode::kPoisson;
  tc.n = 4, tc.depth = 4, tc.p = 40.0;
  const TubeHierarchy tube(tc);
  std::vector<Ray> rays = random_rays(tube.bounds(tube.root()), 300, 6);
  compare_all(tube, rays, tc.depth + 1, "poisson");
  ExplicitHierarchy tflat = flatten(tube, tc.depth + 1);
  build_wide(tflat);
  compare_all(tflat, rays, tc.depth + 1, "poisson flattened");
}

/// The instanced fast path (world boxes of transformed boxes computed four at a time)
/// against the reference's generic path: rotated, non-uniformly scaled and mirrored instances
/// of Wuson.ply, an identity instance, and a mesh with a box primitive.
TEST(SimdTraversal, InstancedMatchesReference) {
  ASSERT_TRUE(std::filesystem::exists(kWuson))
      << kWuson << " missing (assimp-testmodels, scripts/deps.sh)";
  const ImportedMesh m = import_mesh(kWuson);
  BuildConfig bc;
  bc.parallel = false;
  std::vector<ExplicitHierarchy> meshes;
  meshes.push_back(build_explicit(m.triangles, m.materials, bc));
  std::vector<Primitive> other = {Primitive::box({0, 0, 0}, {0.3f, 0.1f, 0.2f}),
                                  Primitive::triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0})};
  meshes.push_back(build_explicit(other, m.materials, bc));
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Instance> instances;
  for (int i = 0; i < 60; ++i) {
    Instance in;
    in.mesh = i % 7 == 3 ? 1u : 0u;
    if (i != 0) {  // instance 0 keeps the identity
      const float a = 3.1415927f * u(rng), b = 3.1415927f * u(rng);
      const float ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b);
      const float rot[3][3] = {{ca, -sa * cb, sa * sb}, {sa, ca * cb, -ca * sb}, {0, sb, cb}};
      const float scale[3] = {1.0f + 0.5f * u(rng), 1.0f + 0.5f * u(rng),
                              (i % 5 == 0 ? -1.0f : 1.0f) * (1.0f + 0.5f * u(rng))};
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) in.to_world.m[r][c] = rot[r][c] * scale[c];
        in.to_world.m[r][3] = 4.0f * u(rng);
      }
    }
    instances.push_back(in);
  }
  BuildConfig tc;
  tc.parallel = false;
  const InstancedHierarchy h = build_instanced(std::move(meshes), std::move(instances), tc);
  const std::vector<Ray> rays = random_rays(h.bounds(h.root()), 1500, 23);
  ASSERT_NE(h.top_wide_nodes(), nullptr);
  compare_all(h, rays, h.levels, "instanced");

  // A mesh left without its SIMD form by design (more records than references address; here
  // simulated): the instanced source cannot walk it, so the whole hierarchy goes to the
  // generic source, with the same hits and counts.
  InstancedHierarchy big = h;
  big.meshes[0].wide = WideNodes{};
  big.meshes[0].wide.unaddressable_nodes = big.meshes[0].nodes.size();
  build_wide(big);
  EXPECT_EQ(big.meshes[0].wide_nodes(), nullptr) << "a mesh left out by design is not rebuilt";
  EXPECT_EQ(big.top_wide_nodes(), nullptr);
  EXPECT_FALSE(big.wide_stale());
  compare_all(big, rays, big.levels, "instanced, a mesh without SIMD form");

  // A top tree whose SIMD form is missing is refused, not walked slowly.
  InstancedHierarchy stale = h;
  stale.top_wide = WideNodes{};
  EXPECT_TRUE(stale.wide_stale());
  Counters unused;
  EXPECT_THROW(
      (Traversal<InstancedHierarchy, TraditionalLod, StochasticOpacity>(stale, {}, unused)),
      InternalError);
}

}  // namespace
}  // namespace amalgam

// The build and bake give the same bytes whatever runs in parallel: the SAH's parallel binning
// and subtrees, the bake's levels, build_wide's passes; and the bake's shortcuts draw the same
// numbers as the plain forms they replace.

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "amalgam/geometry/intersect.h"
#include "amalgam/hierarchy/bake/combine.h"
#include "amalgam/hierarchy/bake/lines.h"
#include "amalgam/hierarchy/build/build.h"
#include "amalgam/hierarchy/build/sah.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/math/random.h"

namespace amalgam {
namespace {

/// Small triangles in a few clusters, every 97th primitive a sphere (non-triangle leaves), and
/// a closed box of 12 triangles (so that the bake orients flat amalgams).
std::vector<Primitive> scene(int n) {
  std::vector<Primitive> out;
  Sampler s(17);
  for (int i = 0; i < n; ++i) {
    const Vec3 c{static_cast<float>(i % 5) * 4.0f + s.next(), s.next() * 3.0f, s.next()};
    if (i % 97 == 0) {
      out.push_back(Primitive::sphere(c, 0.02f, static_cast<std::uint32_t>(i % 3)));
      continue;
    }
    const auto r = [&] { return Vec3{s.next(), s.next(), s.next()} * 0.04f; };
    out.push_back(Primitive::triangle(c, c + r() + Vec3{0.04f, 0, 0}, c + r() + Vec3{0, 0.04f, 0},
                                      static_cast<std::uint32_t>(i % 3)));
  }
  const Vec3 v[8] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                     {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                        {2, 3, 7}, {2, 7, 6}, {1, 2, 6}, {1, 6, 5}, {0, 4, 7}, {0, 7, 3}};
  for (const auto& t : f) out.push_back(Primitive::triangle(v[t[0]], v[t[1]], v[t[2]], 1));
  return out;
}

/// Every byte that a build produces, padding excluded.
void expect_same(const ExplicitHierarchy& a, const ExplicitHierarchy& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  ASSERT_EQ(a.prims.size(), b.prims.size());
  EXPECT_EQ(a.levels, b.levels);
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    const ExplicitNode &x = a.nodes[i], &y = b.nodes[i];
    ASSERT_TRUE(x.bounds == y.bounds && x.first == y.first && x.count == y.count &&
                x.leaf == y.leaf)
        << "node " << i;
    const Appearance &p = a.appearances[i], &q = b.appearances[i];
    ASSERT_EQ(std::memcmp(&p.surface.colour, &q.surface.colour, sizeof(Vec3)), 0) << i;
    ASSERT_EQ(std::memcmp(&p.normal, &q.normal, sizeof(Vec3)), 0) << "node " << i;
    ASSERT_TRUE(std::memcmp(&p.opacity, &q.opacity, 4) == 0 && p.shading == q.shading &&
                std::memcmp(&p.surface.reflectance, &q.surface.reflectance, 4) == 0 &&
                std::memcmp(&p.surface.shininess, &q.surface.shininess, 4) == 0)
        << "node " << i;
  }
  for (std::size_t i = 0; i < a.prims.size(); ++i) {
    const Primitive &x = a.prims[i], &y = b.prims[i];
    ASSERT_TRUE(x.kind == y.kind && x.material == y.material && x.a == y.a && x.b == y.b &&
                x.c == y.c && x.radius == y.radius)
        << "primitive " << i;
  }
  EXPECT_EQ(std::memcmp(&a.root_normals, &b.root_normals, sizeof(NormalTensor)), 0);
  ASSERT_EQ(a.wide.headers.size(), b.wide.headers.size());
  ASSERT_EQ(a.wide.pool.size(), b.wide.pool.size());
  ASSERT_EQ(a.prims.packs().size(), b.prims.packs().size());
  EXPECT_EQ(std::memcmp(a.wide.headers.data(), b.wide.headers.data(),
                        a.wide.headers.size() * sizeof(WideHeader)),
            0);
  EXPECT_EQ(
      std::memcmp(a.wide.pool.data(), b.wide.pool.data(), a.wide.pool.size() * sizeof(WideUnit)),
      0);
  EXPECT_EQ(a.wide.record_node, b.wide.record_node);
  EXPECT_EQ(a.wide.pack_node, b.wide.pack_node);
  EXPECT_EQ(a.wide.root, b.wide.root);
  EXPECT_EQ(std::memcmp(a.prims.packs().data(), b.prims.packs().data(),
                        a.prims.packs().size() * sizeof(TrianglePack4)),
            0);
}

TEST(BuildParallel, SerialParallelAndOneThreadGiveTheSameBytes) {
  // Above every parallel threshold: the SAH's parallel binning (2^16 items), its parallel
  // subtrees, the bake's parallel levels, build_wide's parallel passes (16,384 nodes).
  const std::vector<Primitive> prims = scene(90000);
  const std::vector<Surface> materials = {Surface{{1, 0, 0}}, Surface{{0, 1, 0}, 0.5f, 8.0f},
                                          Surface{{0, 0, 1}}};
  for (int exact : {4, 16}) {  // 16: interior nodes baked exactly too (the stack path)
    SCOPED_TRACE("exact_prims " + std::to_string(exact));
    BuildConfig parallel;
    parallel.bake.exact_prims = exact;
    BuildConfig serial = parallel;
    serial.parallel = false;
    const ExplicitHierarchy a = build_explicit(prims, materials, parallel);
    ASSERT_GT(a.nodes.size(), 16384u);
    expect_same(a, build_explicit(prims, materials, serial));
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      expect_same(a, build_explicit(prims, materials, parallel));
    }
    // build_wide again on the built hierarchy (one thread or many): the same blocks.
    ExplicitHierarchy c = a;
    c.wide = {};
    build_wide(c);
    expect_same(a, c);
  }
}

TEST(BuildParallel, NonFiniteBoxesKeepEveryItemOnceAndParallelEqualsSerial) {
  std::vector<Bbox> boxes;
  Sampler s(5);
  const float nan = std::nanf(""), inf = kInfinity;
  for (int i = 0; i < 70000; ++i) {
    const Vec3 c{s.next() * 10.0f, s.next() * 10.0f, s.next()};
    Bbox b = Bbox::of(c, c + Vec3{0.01f, 0.01f, 0.01f});
    if (i % 501 == 0) b.lo.x = nan;
    if (i % 703 == 0) b.hi.y = inf;
    if (i % 907 == 0) b.lo.z = -inf;
    boxes.push_back(b);
  }
  SahConfig serial;
  serial.parallel = false;
  const SahTree a = build_sah(boxes), b = build_sah(boxes, serial);
  EXPECT_EQ(a.order, b.order);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i)
    EXPECT_EQ(std::memcmp(&a.nodes[i].bounds, &b.nodes[i].bounds, sizeof(Bbox)), 0) << i;
  const std::set<std::uint32_t> items(a.order.begin(), a.order.end());
  EXPECT_EQ(items.size(), boxes.size());
  EXPECT_EQ(a.order.size(), boxes.size());
}

TEST(BakeLines, UniformsAreTheSamplersDraws) {
  const Bbox boxes[] = {Bbox::of({0, 0, 0}, {1, 2, 3}), Bbox::of({-1, 5, 2}, {-1, 5, 2.5f}),
                        Bbox::of({3, 3, 3}, {3, 3, 3})};
  for (std::uint64_t key : {0ull, 0x6a6bull, 0xffffffffffffffffull})
    for (int r = 0; r < 16; ++r) {
      float u[6], w[6];
      line_uniforms(key, r, 16, u);
      Sampler s(hash_combine(key, static_cast<std::uint64_t>(r)));
      for (float& x : w) x = s.next();
      w[0] = (static_cast<float>(r) + w[0]) / 16.0f;
      for (int d = 0; d < 6; ++d) ASSERT_EQ(u[d], w[d]) << key << " " << r << " " << d;
      for (const Bbox& b : boxes) {  // a unit direction, from outside a box with faces
        const Ray x = LineSampler(b)(u);
        EXPECT_NEAR(length(x.dir), 1.0f, 1e-5f);
        if (surface_area(b) > 0.0f) {
          EXPECT_FALSE(b.contains(x.origin));
        }
      }
    }
}

// The bake's test of a line against a node's children four at a time gives, lane by lane, the
// scalar intersect_box's hit and entry bit for bit: random boxes and rays with shared and
// signed zero coordinates, infinities, NaN, flat and empty boxes, zero direction components
// (containment tests), tmin and tmax other than [0, inf), and 1 to 64 children.
TEST(BakeChildren, BoxEntriesMatchTheScalarTest) {
  std::mt19937_64 rng(0xb0c5);
  std::uniform_real_distribution<float> uniform(-2.0f, 2.0f);
  std::uniform_int_distribution<int> pick(0, 99);
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto value = [&](float shared) {
    const int c = pick(rng);
    return c < 3    ? 0.0f
           : c < 5  ? -0.0f
           : c < 6  ? inf
           : c < 7  ? -inf
           : c < 8  ? nan
           : c < 20 ? shared
                    : uniform(rng);
  };
  std::vector<BakeChild> kids(kMaxChildren);
  std::uint64_t lanes = 0, hits = 0, flat_hits = 0;
  for (int it = 0; it < 100000; ++it) {
    const int count = 1 + pick(rng) % (it % 10 == 0 ? kMaxChildren : 9);
    const float shared = uniform(rng);
    for (int k = 0; k < count; ++k) {
      Bbox b;
      for (int a = 0; a < 3; ++a) {
        float x = value(shared), y = value(shared);
        if (pick(rng) < 80 && x > y) std::swap(x, y);
        if (pick(rng) < 10) y = x;
        b.lo[a] = x, b.hi[a] = y;
      }
      if (pick(rng) < 3) b = Bbox{};
      kids[static_cast<std::size_t>(k)].bounds = b;
    }
    const Vec3 o{value(shared), value(shared), value(shared)};
    const Vec3 d{value(0.0f), value(0.0f), value(0.0f)};
    const Ray ray =
        Ray::make(o, d, pick(rng) < 80 ? 0.0f : value(0.5f), pick(rng) < 80 ? inf : value(1.0f));
    const ChildBoxes boxes(
        std::span<const BakeChild>(kids.data(), static_cast<std::size_t>(count)));
    alignas(16) float t0[kMaxChildren];
    const std::uint64_t mask = boxes.entries(ray, t0);
    for (int k = 0; k < count; ++k) {
      const Bbox& b = kids[static_cast<std::size_t>(k)].bounds;
      float s0 = 0, s1 = 0;
      const bool hit = intersect_box(ray, b, s0, s1);
      ++lanes;
      ASSERT_EQ(hit, ((mask >> k) & 1u) != 0) << it << " child " << k;
      if (!hit) continue;
      ++hits;
      if (b.lo.x == b.hi.x || b.lo.y == b.hi.y || b.lo.z == b.hi.z) ++flat_hits;
      ASSERT_EQ(std::memcmp(&s0, &t0[k], sizeof s0), 0)
          << it << " child " << k << ": " << s0 << " vs " << t0[k];
    }
  }
  EXPECT_GT(hits, lanes / 20);  // the cases test hits, not only misses
  EXPECT_GT(flat_hits, 1000u);
}

}  // namespace
}  // namespace amalgam

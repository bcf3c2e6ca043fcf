// Binned SAH builder and the bake: structural validity and opacity sanity.

#include "amalgam/hierarchy/build/sah.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <set>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/math/random.h"

namespace amalgam {
namespace {

bool inside(const Bbox& in, const Bbox& out) {
  return in.lo.x >= out.lo.x && in.lo.y >= out.lo.y && in.lo.z >= out.lo.z && in.hi.x <= out.hi.x &&
         in.hi.y <= out.hi.y && in.hi.z <= out.hi.z;
}

/// Small random triangles in clusters (so the SAH has structure to find).
std::vector<Primitive> random_triangles(int n, std::uint64_t seed) {
  std::vector<Primitive> out;
  Sampler s(seed);
  for (int i = 0; i < n; ++i) {
    const float cluster = static_cast<float>(i % 7) * 3.0f;
    const Vec3 c{cluster + s.next(), s.next() * 2.0f, s.next() * 0.5f};
    const auto r = [&] { return Vec3{s.next(), s.next(), s.next()} * 0.05f; };
    out.push_back(Primitive::triangle(c, c + r() + Vec3{0.05f, 0, 0}, c + r() + Vec3{0, 0.05f, 0},
                                      static_cast<std::uint32_t>(i)));
  }
  return out;
}

void check_valid(const ExplicitHierarchy& h, std::size_t n, const BuildConfig& cfg) {
  ASSERT_EQ(h.prims.size(), n);
  ASSERT_EQ(h.appearances.size(), h.nodes.size());
  std::vector<int> seen(n, 0);  // material == original index
  std::vector<int> parents(h.nodes.size(), 0);
  parents[0] = 1;
  int max_level = 0;
  std::vector<int> level(h.nodes.size(), 0);
  for (std::size_t i = 0; i < h.nodes.size(); ++i) {
    const ExplicitNode& node = h.nodes[i];
    ASSERT_GT(node.count, 0u) << "node " << i;
    if (node.leaf) {
      EXPECT_LE(node.count, cfg.leaf_size);
      max_level = std::max(max_level, level[i] + 1);
      for (std::uint32_t p = node.first; p < node.first + node.count; ++p) {
        ASSERT_LT(p, n);
        EXPECT_TRUE(inside(bounds(h.prims[p]), node.bounds)) << "prim " << p << " node " << i;
        ++seen[h.prims[p].material];
      }
    } else {
      EXPECT_LE(node.count, cfg.arity);
      EXPECT_GE(node.count, 2u);
      for (std::uint32_t c = node.first; c < node.first + node.count; ++c) {
        ASSERT_LT(c, h.nodes.size());
        ASSERT_GT(c, i);  // children after their parent
        EXPECT_TRUE(inside(h.nodes[c].bounds, node.bounds)) << "child " << c << " node " << i;
        ++parents[c];
        level[c] = level[i] + 1;
      }
    }
  }
  for (std::size_t i = 0; i < h.nodes.size(); ++i) EXPECT_EQ(parents[i], 1) << "node " << i;
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(seen[i], 1) << "prim " << i;
  EXPECT_EQ(h.levels, max_level + 1);
}

TEST(SahBuild, EveryPrimitiveOnceAndChildBoxesInsideParents) {
  for (int arity : {2, 4, 8}) {
    BuildConfig cfg;
    cfg.arity = arity;
    cfg.leaf_size = arity == 8 ? 8 : 4;
    const int n = 20000;  // above the parallel thresholds
    std::vector<Surface> materials(n);
    const ExplicitHierarchy h = build_explicit(random_triangles(n, 3), materials, cfg);
    SCOPED_TRACE("arity " + std::to_string(arity));
    check_valid(h, n, cfg);
  }
}

TEST(SahBuild, ParallelEqualsSerialAndEdgeCases) {
  std::vector<Bbox> boxes;
  for (const Primitive& p : random_triangles(70000, 9)) boxes.push_back(bounds(p));
  SahConfig serial;
  serial.parallel = false;
  const SahTree a = build_sah(boxes), b = build_sah(boxes, serial);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(a.order, b.order);
  for (std::size_t i = 0; i < a.nodes.size(); ++i) EXPECT_EQ(a.nodes[i].bounds, b.nodes[i].bounds);
  // Empty input: one empty leaf. Identical boxes: still a valid tree.
  const SahTree e = build_sah(std::span<const Bbox>{});
  ASSERT_EQ(e.nodes.size(), 1u);
  EXPECT_TRUE(e.nodes[0].leaf);
  EXPECT_EQ(e.nodes[0].count, 0u);
  const std::vector<Bbox> same(100, Bbox::of({0, 0, 0}, {1, 1, 1}));
  const SahTree s = build_sah(same);
  std::set<std::uint32_t> items(s.order.begin(), s.order.end());
  EXPECT_EQ(items.size(), 100u);
  const SahConfig def;
  for (const auto& node : s.nodes)
    EXPECT_LE(node.count, node.leaf ? def.leaf_size : def.arity) << (node.leaf ? "leaf" : "node");
  // Identical boxes cannot be split by SAH: the tree still ends in leaves of at most leaf_size
  // items, so it is not one leaf of 100.
  EXPECT_GT(s.nodes.size(), 1u);
}

TEST(SahBuild, SahBeatsMedianOnClusteredInput) {
  // Two far clusters of different sizes: the root split must separate them.
  std::vector<Bbox> boxes;
  for (int i = 0; i < 90; ++i)
    boxes.push_back(Bbox::of({i * 0.01f, 0, 0}, {i * 0.01f + 0.01f, 0.01f, 0.01f}));
  for (int i = 0; i < 10; ++i)
    boxes.push_back(Bbox::of({100.0f + i * 0.01f, 0, 0}, {100.01f + i * 0.01f, 0.01f, 0.01f}));
  SahConfig c;
  c.arity = 2;
  const SahTree t = build_sah(boxes, c);
  ASSERT_FALSE(t.nodes[0].leaf);
  const Bbox l = t.nodes[t.nodes[0].first].bounds, r = t.nodes[t.nodes[0].first + 1].bounds;
  EXPECT_TRUE((l.hi.x < 2 && r.lo.x > 99) || (r.hi.x < 2 && l.lo.x > 99));
}

/// A quad (two triangles) spanning the box [-1, 1]^3 through its centre, normal on `axis`.
void add_plane(std::vector<Primitive>& out, int axis) {
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  Vec3 p[4];
  for (int k = 0; k < 4; ++k) {
    p[k][i] = (k == 1 || k == 2) ? 1.0f : -1.0f;
    p[k][j] = k >= 2 ? 1.0f : -1.0f;
  }
  out.push_back(Primitive::triangle(p[0], p[1], p[2]));
  out.push_back(Primitive::triangle(p[0], p[2], p[3]));
}

TEST(Bake, OpacityOfCoveredAndEmptyNodes) {
  BuildConfig cfg;
  cfg.bake.rays = 64;
  // Three orthogonal planes through the centre of [-1, 1]^3. By Cauchy's formula a line
  // crossing the cube crosses one plane with probability S(square) / S(cube) = 8 / 24; it
  // misses all three only within one octant. Exact bake (all six triangles traced) and the
  // combination of the two leaves' estimates must agree on clearly more than 1/3.
  std::vector<Primitive> planes;
  for (int a = 0; a < 3; ++a) add_plane(planes, a);
  BuildConfig exact = cfg;
  exact.bake.exact_prims = 100;
  exact.bake.rays = 4096;
  const ExplicitHierarchy full = build_explicit(planes, {Surface{{1, 0, 0}}}, exact);
  const float truth = full.appearances[0].opacity;
  EXPECT_GT(truth, 0.55f);
  EXPECT_NEAR(full.appearances[0].surface.colour.x, 1.0f, 1e-6f);
  const ExplicitHierarchy combined = build_explicit(planes, {Surface{{1, 0, 0}}}, cfg);
  EXPECT_NEAR(combined.appearances[0].opacity, truth, 0.12f);
  // One plane alone: 1/3.
  std::vector<Primitive> single;
  add_plane(single, 0);
  single.push_back(Primitive::triangle({-1, -1, -1}, {-1, -1, -0.999f}, {-1, -0.999f, -1}));
  single.push_back(Primitive::triangle({1, 1, 1}, {1, 1, 0.999f}, {1, 0.999f, 1}));
  EXPECT_NEAR(build_explicit(single, {}, exact).appearances[0].opacity, 1.0f / 3.0f, 0.03f);
  // A single plane filling a flat box: every line crossing the box hits it.
  std::vector<Primitive> one;
  add_plane(one, 1);
  const ExplicitHierarchy flat = build_explicit(one, {}, cfg);
  EXPECT_GT(flat.appearances[0].opacity, 0.99f);
  EXPECT_NEAR(std::fabs(flat.appearances[0].normal.y), 1.0f, 1e-4f);  // baked mean normal
  // Two tiny triangles at opposite corners of a big box: nearly empty.
  std::vector<Primitive> sparse;
  for (float s : {-10.0f, 10.0f})
    sparse.push_back(Primitive::triangle({s, s, s}, {s + 0.01f, s, s}, {s, s + 0.01f, s}));
  BuildConfig one_leaf = cfg;
  one_leaf.leaf_size = 2;
  const ExplicitHierarchy empty = build_explicit(sparse, {}, one_leaf);
  EXPECT_LT(empty.appearances[0].opacity, 0.05f);
  // A cloud: the bottom-up combination stays close to tracing the whole subtree exactly.
  const auto tris = random_triangles(600, 5);
  const ExplicitHierarchy cloud = build_explicit(tris, std::vector<Surface>(600), cfg);
  const ExplicitHierarchy cloud_exact = build_explicit(tris, std::vector<Surface>(600), exact);
  EXPECT_NEAR(cloud.appearances[0].opacity, cloud_exact.appearances[0].opacity, 0.1f);
  for (const Appearance& a : cloud.appearances) {
    EXPECT_GE(a.opacity, 0.0f);
    EXPECT_LE(a.opacity, 1.0f);
  }
  std::printf("three planes: exact %.3f combined %.3f; cloud: exact %.3f combined %.3f\n", truth,
              combined.appearances[0].opacity, cloud_exact.appearances[0].opacity,
              cloud.appearances[0].opacity);
}

}  // namespace
}  // namespace amalgam

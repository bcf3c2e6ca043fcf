// Intersection counts on the paper's worst-case scene (builtin:line), asserted exactly
// against the closed forms of the paper (and, for deterministic opacity, of our scene).

#include <gtest/gtest.h>

#include <cmath>

#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

namespace amalgam {
namespace {

std::uint64_t geometric_sum(std::uint64_t n, int top) {  // sum_{i=0}^{top} n^i
  std::uint64_t s = 0, p = 1;
  for (int i = 0; i <= top; ++i) s += p, p *= n;
  return s;
}

LoadedScene line(int n, int depth, double alpha = 0.0, int lights = 1) {
  Params p("builtin:line");
  p.set("n", std::to_string(n));
  p.set("depth", std::to_string(depth));
  p.set("alpha", std::to_string(alpha));
  p.set("lights", std::to_string(lights));
  return load_scene("builtin:line", p);
}

TraceOutput trace_centre(const LoadedScene& s, const RenderOptions& o) {
  return trace(s, o, s.env.camera.centre_ray(o.width, o.height));
}

struct LineCase {
  int n, depth;
};

class TraditionalLine : public ::testing::TestWithParam<LineCase> {};

TEST_P(TraditionalLine, PrimaryAndShadowRayExamineEveryObject) {
  const auto [n, depth] = GetParam();
  const LoadedScene s = line(n, depth);
  for (bool sorted : {true, false}) {
    RenderOptions o;
    o.lod = FullDetail{};
    o.sorted = sorted;
    const TraceOutput t = trace_centre(s, o);
    const std::uint64_t c_t0 = geometric_sum(n, depth);  // (n^(l_max+1) - 1) / (n - 1)
    EXPECT_EQ(t.counters.tests_of(RayKind::kPrimary), c_t0) << "n=" << n << " depth=" << depth;
    EXPECT_EQ(t.counters.tests_of(RayKind::kShadow), c_t0) << "the light lies on the line too";
    EXPECT_EQ(t.counters.tests_of(ObjectKind::kAmalgam), 0u);
    EXPECT_EQ(t.counters.tests[0][static_cast<int>(ObjectKind::kPrimitive)],
              static_cast<std::uint64_t>(std::pow(n, depth)));
    ASSERT_EQ(t.hit.kind, TraceHit::Kind::kPrimitive);
    EXPECT_EQ(t.hit.id + 1, static_cast<std::uint64_t>(std::pow(n, depth)))
        << "only the last primitive is hit";
    for (int l = 0; l <= depth; ++l)
      EXPECT_EQ(t.counters.by_level[l], 2 * static_cast<std::uint64_t>(std::pow(n, l)));
  }
}

INSTANTIATE_TEST_SUITE_P(Paper, TraditionalLine,
                         ::testing::Values(LineCase{2, 1}, LineCase{2, 5}, LineCase{2, 12},
                                           LineCase{3, 2}, LineCase{3, 6}, LineCase{3, 9},
                                           LineCase{4, 3}, LineCase{4, 7}, LineCase{8, 2},
                                           LineCase{8, 5}));

TEST(TraditionalLine, ContractExample) {
  RenderOptions o;
  o.lod = FullDetail{};
  EXPECT_EQ(trace_centre(line(3, 6), o).counters.tests_of(RayKind::kPrimary), 1093u);
}

// Eq. 1 and Eq. 3: scale-sensitive at level l1, stochastic opacity; the ray meets all n^l1
// amalgams on level l1 and only the last is opaque. Cost C_s0 for the primary ray and the
// same for its one shadow ray, whatever l_max.
TEST(ScaleSensitiveLine, StochasticCostIsIndependentOfDepth) {
  for (int n : {2, 3, 4, 8}) {
    for (int l1 : {0, 1, 2, 3}) {
      const std::uint64_t c_s0 = geometric_sum(n, l1);
      for (int depth : {l1 + 1, l1 + 3, 12, 19}) {
        if (std::pow(n, depth) >= 0x1.0p58) continue;
        RenderOptions o;
        o.lod = OnLevel{l1};
        const TraceOutput t = trace_centre(line(n, depth), o);
        EXPECT_EQ(t.counters.tests_of(RayKind::kPrimary), c_s0)
            << "Eq. 1, n=" << n << " l1=" << l1 << " l_max=" << depth;
        EXPECT_EQ(t.counters.total(), 2 * c_s0) << "Eq. 3";
        EXPECT_EQ(t.counters.rays[1], 1u) << "one shadow ray";
        ASSERT_EQ(t.hit.kind, TraceHit::Kind::kAmalgam);
        EXPECT_EQ(t.hit.level, l1);
      }
    }
  }
}

// Exact shadow cost of deterministic opacity in builtin:line: the shadow ray from the k-th
// amalgam on level l1 (k = 0 nearest the camera) runs back to the light at the camera and
// tests 1 + sum_{m=0}^{l1-1} n * ceil(k / n^(l1-m)) objects. Summed over all b = n^l1
// amalgams this is b + n sum_m (b (n^m + 1) / 2 - n^m), which grows as n^(2 l1 + 1) / (2 (n-1)):
// the O(n^(2 l1)) of Eq. 2, about half the bound C_sd1 = n^l1 C_s0 because a shadow ray
// crosses on average half of the line.
std::uint64_t line_deterministic_shadow_tests(std::uint64_t n, int l1) {
  std::uint64_t b = 1;
  for (int i = 0; i < l1; ++i) b *= n;
  std::uint64_t total = b, nm = 1;
  for (int m = 0; m < l1; ++m, nm *= n) total += n * (b * (nm + 1) / 2 - nm);
  return total;
}

TEST(ScaleSensitiveLine, DeterministicShadowCostGrowsAsNToTheTwoL1) {
  for (int n : {2, 3, 4}) {
    double previous = 0;
    for (int l1 = 1; l1 <= 5; ++l1) {
      RenderOptions o;
      o.lod = OnLevel{l1};
      o.opacity = OpacityKind::kDeterministic;
      const TraceOutput t = trace_centre(line(n, l1 + 2, 0.5), o);
      const std::uint64_t b = static_cast<std::uint64_t>(std::pow(n, l1));
      EXPECT_EQ(t.counters.tests_of(RayKind::kPrimary), geometric_sum(n, l1));
      EXPECT_EQ(t.counters.rays[1], b) << "one shadow ray per rendered amalgam";
      const std::uint64_t shadow = t.counters.tests_of(RayKind::kShadow);
      EXPECT_EQ(shadow, line_deterministic_shadow_tests(n, l1)) << "n=" << n << " l1=" << l1;
      // Eq. 2 is an upper bound here: C_sd1 = n^l1 C_s0.
      EXPECT_LE(shadow, b * geometric_sum(n, l1));
      if (previous > 0 && l1 >= 3) {
        const double ratio = static_cast<double>(shadow) / previous;
        EXPECT_NEAR(ratio, n * n, 0.35 * n * n) << "growth per level ~ n^2";
      }
      previous = static_cast<double>(shadow);
    }
  }
}

TEST(ScaleSensitiveLine, LightsScaleShadowCost) {
  for (int lights : {1, 2, 5}) {
    RenderOptions o;
    o.lod = OnLevel{2};
    const TraceOutput t = trace_centre(line(3, 6, 0.0, lights), o);
    EXPECT_EQ(t.counters.tests_of(RayKind::kShadow), lights * geometric_sum(3, 2));
  }
}

// The paper's counting of "objects traversed" (Counters::traversed_of): children reached in
// sorted order until the first hit. Where every amalgam of level l1 lets the ray through
// (builtin:line, alpha 0: nothing stops it) every object above and on l1 is reached: C_s0
// (Eq. 1), the same as the intersection tests. Where the first amalgam stops the ray
// (builtin:poisson with p/b huge) only the left edge and that amalgam are reached,
// l1 + 1 = Eq. 4 with i = 1, while the renderer tests all n children of each entered node,
// 1 + n l1.
TEST(ObjectsTraversed, WorstCaseIsCs0AndFirstHitIsEq4) {
  for (int n : {2, 3, 8}) {
    for (int l1 = 1; l1 <= (n == 8 ? 3 : 6); ++l1) {
      RenderOptions o;
      o.lod = OnLevel{l1};
      const TraceOutput w = trace_centre(line(n, l1 + 1), o);
      EXPECT_EQ(w.counters.traversed_of(RayKind::kPrimary), geometric_sum(n, l1))
          << "n=" << n << " l1=" << l1;
      Params p("builtin:poisson");
      p.set("n", std::to_string(n));
      p.set("depth", std::to_string(l1 + 1));
      p.set("p", "1e12");
      const TraceOutput f = trace_centre(load_scene("builtin:poisson", p), o);
      EXPECT_EQ(f.hit.kind, TraceHit::Kind::kAmalgam);
      EXPECT_EQ(f.counters.traversed_of(RayKind::kPrimary), std::uint64_t(l1 + 1))
          << "n=" << n << " l1=" << l1;
      EXPECT_EQ(f.counters.tests_of(RayKind::kPrimary), std::uint64_t(1 + n * l1))
          << "n=" << n << " l1=" << l1;
    }
  }
}

}  // namespace
}  // namespace amalgam

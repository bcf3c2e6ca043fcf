/// \file Experiment sorting: the paper's remark that sorting a node's children costs little
/// next to the intersection tests ("the renderer can use a linear-time bucket sort ... the
/// sort has the same asymptotic cost as examining the objects"). On builtin:line, traditional
/// renderer, worst case, a ray tests every object whatever the order, so sorted and stored
/// order make exactly the same tests and the difference in wall time is the ordering work
/// (this renderer: insertion sort of the hit children of each entered node). The primary ray
/// meets the children in stored order (the sort's best case), its shadow ray in reverse order
/// (the insertion sort's worst case, O(n^2) per node). In the expected case (builtin:poisson
/// seen from its far end, so a ray meets every node's children in the reverse of their stored
/// order) order matters: the sorted traversal stops at the nearest hit, the stored one finds
/// far hits first and keeps testing nearer objects; both are timed.

#include <array>
#include <chrono>
#include <cmath>

#include "amalgam/analysis/experiments/common.h"

namespace amalgam::experiments {
using namespace detail;
// Named: a unity build compiles several experiments in one translation unit.
namespace sorting_parts {
namespace {

struct Case {
  int n, depth;
};

/// Best of 3 wall times, in us per pass, of tracing `ray` through every scene of `scenes` in
/// sorted [0] and stored [1] order, alternating; `tests[o]` is one pass's tests in that order,
/// and each timing repeats the pass to make about `min_tests` tests.
std::array<double, 2> best_times(const std::vector<LoadedScene>& scenes, const Ray& ray,
                                 const double tests[2], int min_tests) {
  RenderOptions sorted = traditional(), stored = traditional();
  stored.sorted = false;
  std::array<double, 2> best = {1e300, 1e300};
  for (int round = 0; round < 3; ++round)
    for (int o = 0; o < 2; ++o) {
      const int reps = std::max(1, int(min_tests / std::max(1.0, tests[o])));
      const auto t0 = std::chrono::steady_clock::now();
      std::uint64_t sink = 0;
      for (int i = 0; i < reps; ++i)
        for (const LoadedScene& s : scenes)
          sink += trace(s, o ? stored : sorted, ray).counters.total();
      best[o] = std::min(best[o], seconds_since(t0) * 1e6 / reps);
      if (sink == 0) best[o] = NAN;  // keeps the loop from being optimised away
    }
  return best;
}

/// One pass's tests in sorted [0] and stored [1] order.
void count_tests(const std::vector<LoadedScene>& scenes, const Ray& ray, double tests[2]) {
  RenderOptions sorted = traditional(), stored = traditional();
  stored.sorted = false;
  tests[0] = tests[1] = 0;
  for (int o = 0; o < 2; ++o)
    for (const LoadedScene& s : scenes)
      tests[o] += u(trace(s, o ? stored : sorted, ray).counters.total());
}

/// Worst case: builtin:line, where both orders make the same tests. Returns whether they did.
bool worst_case(const Config& c, ExperimentResult& r, int min_tests) {
  // About 10^5 tests per ray pair at full size.
  const std::vector<Case> cases =
      c.quick ? std::vector<Case>{{2, 6}, {8, 3}, {64, 2}}
              : std::vector<Case>{{2, 12}, {2, 15}, {3, 8},  {3, 10}, {8, 4},
                                  {8, 5},  {16, 3}, {16, 4}, {64, 2}, {64, 3}};
  bool same_tests = true;
  for (const Case& k : cases) {
    std::vector<LoadedScene> s;
    s.push_back(scene("line", {{"n", str(k.n)}, {"depth", str(k.depth)}}));
    const Ray ray = s[0].env.camera.centre_ray(RenderOptions{}.width, RenderOptions{}.height);
    double tests[2];
    count_tests(s, ray, tests);
    const std::array<double, 2> best = best_times(s, ray, tests, min_tests);
    r.table.add({0.0, double(k.n), double(k.depth), tests[0], tests[1], best[0], best[1],
                 best[0] * 1e3 / tests[0], best[1] * 1e3 / tests[1],
                 100 * (best[0] / best[1] - 1)});
    same_tests &= tests[0] == tests[1];
  }
  return same_tests;
}

/// Expected case: builtin:poisson with p = n^depth (one expected hit per unit cell), many
/// realisations, traced from beyond its far end towards the camera's side, so that a ray meets
/// every node's children in the reverse of their stored order. Returns the findings' text.
std::string expected_case(const Config& c, ExperimentResult& r, int min_tests, int realisations) {
  const std::vector<Case> cases =
      c.quick ? std::vector<Case>{{2, 8}, {8, 3}} : std::vector<Case>{{2, 12}, {4, 6}, {8, 4}};
  std::string text;
  for (const Case& k : cases) {
    const double width = std::pow(k.n, k.depth);
    std::vector<LoadedScene> scenes;
    for (int i = 0; i < realisations; ++i)
      scenes.push_back(
          scene("poisson",
                {{"n", str(k.n)}, {"depth", str(k.depth)}, {"p", str(width)}, {"seed", str(i)}}));
    const Ray ray = Ray::make({static_cast<float>(2 * width), 0, 0}, {-1, 0, 0});
    double tests[2];
    count_tests(scenes, ray, tests);
    std::array<double, 2> best = best_times(scenes, ray, tests, min_tests);
    for (double& b : best) b /= realisations;  // per ray pair
    const double mean[2] = {tests[0] / realisations, tests[1] / realisations};
    const double ns[2] = {best[0] * 1e3 / mean[0], best[1] * 1e3 / mean[1]};
    r.table.add({1.0, double(k.n), double(k.depth), mean[0], mean[1], best[0], best[1], ns[0],
                 ns[1], 100 * (ns[0] / ns[1] - 1)});
    text += "n = " + str(k.n) + ", depth " + str(k.depth) + ": " + fmt(mean[0]) +
            " tests per ray pair sorted against " + fmt(mean[1]) + " stored, " + fmt(best[0]) +
            " us against " + fmt(best[1]) + " us (" + fmt(ns[0]) + " and " + fmt(ns[1]) +
            " ns per test); ";
  }
  return text;
}

}  // namespace
}  // namespace sorting_parts

ExperimentResult sorting(const Config& c) {
  using namespace sorting_parts;
  ExperimentResult r;
  r.title = "Sorting children: its cost next to the intersection tests";
  r.claim =
      "\"In practice, however, the cost of this sorting is insignificant compared to the cost "
      "of performing intersection tests ... the renderer sorts exactly n objects at a time. "
      "The renderer can use a linear-time bucket sort for this operation, which means the "
      "sort has the same asymptotic cost as examining the objects in the first place.\"";
  r.prediction =
      "Same tests in sorted and stored order (worst case: everything is tested); wall time of "
      "the sorted traversal at most a constant factor above the stored one, that factor not "
      "growing with the depth (the sort is O(n) or O(n^2) per node for fixed n: a constant "
      "per test). Expected case (builtin:poisson, children met in reverse stored order): "
      "fewer tests in sorted order, and a time per test close to the stored order's.";
  r.table.columns = {"case",
                     "n",
                     "depth",
                     "tests",
                     "tests_stored",
                     "us_sorted",
                     "us_stored",
                     "ns_per_test_sorted",
                     "ns_per_test_stored",
                     "overhead_pct"};
  const int min_tests = c.quick ? 1000 : 3000000;  // per timing, summed over repetitions
  const bool same_tests = worst_case(c, r, min_tests);
  // No check: the claim is about time, which is measured here but depends on the machine and
  // its load, so the verdict is "not checked" (tests/analysis/experiments_test.cpp asserts the
  // like-for-like test counts).
  double lo = 1e300, hi = -1e300;
  for (const auto& row : r.table.rows) lo = std::min(lo, row[9]), hi = std::max(hi, row[9]);
  const int realisations = c.quick ? 20 : 200;
  const std::string expected_text = expected_case(c, r, min_tests, realisations);
  r.summary_columns = r.table.columns;
  r.panels.push_back({"Wall time per test, traditional worst case (builtin:line)",
                      "n (children a ray meets per node)",
                      "ns per intersection test (primary + shadow ray)",
                      Scale::kLog,
                      Scale::kLinear,
                      {{"n", "ns_per_test_sorted", "sorted order", Draw::kPoints, "case", 0},
                       {"n", "ns_per_test_stored", "stored order", Draw::kPoints, "case", 0}}});
  r.panels.push_back({"Expected case (builtin:poisson, children met in reverse stored order)",
                      "n (children per node)",
                      "us per ray pair (primary + shadow ray)",
                      Scale::kLog,
                      Scale::kLog,
                      {{"n", "us_sorted", "sorted order", Draw::kPoints, "case", 1},
                       {"n", "us_stored", "stored order", Draw::kPoints, "case", 1}}});
  r.findings =
      std::string(same_tests ? "Both orders make exactly the same tests here, so the time "
                               "difference is the ordering work. "
                             : "**The two orders do not make the same tests here** (see the "
                               "CSV), so the comparison is not like for like. ") +
      "The sorted traversal takes " + fmt(lo) + "% to " + fmt(hi) +
      "% more time than the stored one over n = 2 .. 64 (best of 3, per ray pair; the shadow "
      "ray meets the children in reverse order, the insertion sort's worst case). A constant "
      "factor per test, as the paper says, as long as it does not grow with the depth at "
      "fixed n (compare the two depths of each n).\n\nIn the expected case order matters "
      "(builtin:poisson with p = n^depth, " +
      str(realisations) +
      " realisations, the ray "
      "meeting every node's children in the reverse of their stored order): " +
      expected_text +
      "sorting lets the traversal stop at the nearest hit, so it saves far more time than it "
      "costs. Per test the sorted traversal is dearer here, but that figure also spreads each "
      "ray's fixed work (generating it, shading the hit, its shadow ray) over a few dozen "
      "tests instead of thousands; the worst case above isolates the sort. Wall time is "
      "measured on this machine and not checked: the verdict of the statement is \"not "
      "checked\".";
  return r;
}

}  // namespace amalgam::experiments

// stats/distribution.h: the exact per-primary-ray cost distribution behind the stats JSON's
// per_primary_ray {mean, p50, p99, max}, on hand-built distributions whose percentiles are
// known ("the smallest value v such that at least q * count values are <= v").

#include "amalgam/stats/distribution.h"

#include <gtest/gtest.h>

#include <cstdint>

#include "amalgam/builtin/params.h"
#include "amalgam/io/stats_json.h"
#include "amalgam/render/loaded_scene.h"

namespace amalgam {
namespace {

TEST(CostDistribution, EmptyIsAllZero) {
  const CostDistribution d;
  EXPECT_EQ(d.count(), 0u);
  EXPECT_EQ(d.mean(), 0.0);
  EXPECT_EQ(d.quantile(0.5), 0u);
  EXPECT_EQ(d.max(), 0u);
}

TEST(CostDistribution, OneToHundredHasTheTextbookPercentiles) {
  CostDistribution d;
  for (std::uint64_t v = 100; v >= 1; --v) d.add(v);  // order of adding does not matter
  EXPECT_EQ(d.count(), 100u);
  EXPECT_DOUBLE_EQ(d.mean(), 50.5);
  EXPECT_EQ(d.quantile(0.0), 1u);
  EXPECT_EQ(d.quantile(0.01), 1u);
  EXPECT_EQ(d.quantile(0.5), 50u);
  EXPECT_EQ(d.quantile(0.505), 51u);
  EXPECT_EQ(d.quantile(0.99), 99u);
  EXPECT_EQ(d.quantile(1.0), 100u);
  EXPECT_EQ(d.max(), 100u);
}

TEST(CostDistribution, SkewedTailMovesP99AndMaxOnly) {
  // 99 rays of cost 5 and one of 1000: p50 = p99 = 5, max 1000, mean 14.95.
  CostDistribution d;
  d.add(5, 99);
  d.add(1000);
  EXPECT_DOUBLE_EQ(d.mean(), (99 * 5 + 1000) / 100.0);
  EXPECT_EQ(d.quantile(0.5), 5u);
  EXPECT_EQ(d.quantile(0.99), 5u);
  EXPECT_EQ(d.max(), 1000u);
  // Two rays of cost 1000: the 99th percentile is one of them.
  CostDistribution e;
  e.add(5, 98);
  e.add(1000, 2);
  EXPECT_EQ(e.quantile(0.99), 1000u);
  EXPECT_EQ(e.quantile(0.98), 5u);
}

TEST(CostDistribution, ValuesAboveTheDenseRangeAreExact) {
  // Costs beyond kDense (16384) live in the sparse part: still exact.
  const std::uint64_t big = CostDistribution::kDense, huge = 1'000'000'000'000ull;
  CostDistribution d;
  d.add(10, 3);
  d.add(big + 1);
  d.add(huge);
  EXPECT_EQ(d.count(), 5u);
  EXPECT_DOUBLE_EQ(d.mean(), (30.0 + double(big + 1) + double(huge)) / 5);
  EXPECT_EQ(d.quantile(0.5), 10u);       // 3 of 5 values <= 10
  EXPECT_EQ(d.quantile(0.61), big + 1);  // needs 4 values
  EXPECT_EQ(d.quantile(0.8), big + 1);
  EXPECT_EQ(d.quantile(0.99), huge);
  EXPECT_EQ(d.max(), huge);
  EXPECT_EQ(d.quantile(0.6), 10u);  // ceil(0.6 x 5) = 3 values
}

TEST(CostDistribution, MergeEqualsAddingEverythingToOne) {
  CostDistribution a, b, all;
  for (std::uint64_t v = 0; v < 300; ++v) {
    const std::uint64_t cost = (v * v * 7919) % 40000;  // dense and sparse values
    (v % 3 ? a : b).add(cost);
    all.add(cost);
  }
  a.merge(b);
  EXPECT_EQ(a.count(), all.count());
  EXPECT_DOUBLE_EQ(a.mean(), all.mean());
  for (double q : {0.0, 0.1, 0.5, 0.9, 0.99, 1.0}) EXPECT_EQ(a.quantile(q), all.quantile(q)) << q;
  EXPECT_EQ(a.max(), all.max());
}

// The stats JSON's per_primary_ray is the distribution's mean, p50, p99 and max.
TEST(CostDistribution, StatsJsonReportsMeanP50P99AndMax) {
  const LoadedScene scene = load_builtin("builtin:line", Params("builtin:line"));
  CostDistribution d;
  d.add(5, 98);
  d.add(1000, 2);
  const nlohmann::json j = stats_json(scene, RenderOptions{}, Counters{}, d, 0.5);
  const nlohmann::json& p = j["per_primary_ray"];
  EXPECT_DOUBLE_EQ(p["mean"].get<double>(), (98 * 5 + 2000) / 100.0);
  EXPECT_EQ(p["p50"], 5);
  EXPECT_EQ(p["p99"], 1000);
  EXPECT_EQ(p["max"], 1000);
}

}  // namespace
}  // namespace amalgam

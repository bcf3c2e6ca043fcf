// stats/counters.h: where a test is counted. Every level below kCountedLevels has its own
// counter; a test on a deeper level (an explicit hierarchy may be up to 255 levels deep) is
// counted on the last one, as is a level that is not a valid one (negative), and the totals
// by ray kind and object kind count every test once whatever its level.

#include "amalgam/stats/counters.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>

namespace amalgam {
namespace {

TEST(Counters, EachLevelBelowTheLastHasItsOwnCounter) {
  Counters c;
  for (int l = 0; l < kCountedLevels; ++l)
    c.count_tests(RayKind::kPrimary, ObjectKind::kBoundingVolume, l,
                  static_cast<std::uint64_t>(l + 1));
  for (int l = 0; l < kCountedLevels; ++l)
    EXPECT_EQ(c.by_level[static_cast<std::size_t>(l)], static_cast<std::uint64_t>(l + 1)) << l;
  const std::uint64_t sum = kCountedLevels * (kCountedLevels + 1) / 2;
  EXPECT_EQ(c.tests[0][1], sum);
  EXPECT_EQ(c.total(), sum);
}

TEST(Counters, DeeperAndInvalidLevelsGoToTheLastLevel) {
  Counters c;
  c.count_tests(RayKind::kShadow, ObjectKind::kPrimitive, kCountedLevels, 2);
  c.count_tests(RayKind::kShadow, ObjectKind::kAmalgam, 200, 3);
  c.count_test(RayKind::kPrimary, ObjectKind::kPrimitive, -1);
  c.count_test(RayKind::kPrimary, ObjectKind::kBoundingVolume, kCountedLevels - 1);
  EXPECT_EQ(c.by_level[kCountedLevels - 1], 7u);
  EXPECT_EQ(std::accumulate(c.by_level.begin(), c.by_level.end(), std::uint64_t{0}), 7u);
  EXPECT_EQ(c.tests[1][0], 2u);
  EXPECT_EQ(c.tests[1][2], 3u);
  EXPECT_EQ(c.tests[0][0], 1u);
  EXPECT_EQ(c.tests[0][1], 1u);
  EXPECT_EQ(c.tests_of(RayKind::kShadow), 5u);
  EXPECT_EQ(c.total(), 7u);
}

}  // namespace
}  // namespace amalgam

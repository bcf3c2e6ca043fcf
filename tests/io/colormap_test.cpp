// io/colormap.h: false colour for cost and error images.

#include "amalgam/io/colormap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace amalgam {
namespace {

TEST(Colormap, FalseColourIsMonotonicInLuminance) {
  std::vector<double> values;
  for (int i = 0; i <= 1000; ++i) values.push_back(i * 0.37);
  for (bool log_scale : {false, true}) {
    double vmax = -1;
    const std::vector<Vec3> colours = false_colour(values, log_scale, &vmax);
    ASSERT_EQ(colours.size(), values.size());
    EXPECT_DOUBLE_EQ(vmax, 1000 * 0.37);
    for (std::size_t i = 1; i < colours.size(); ++i)
      EXPECT_GT(luminance(colours[i]), luminance(colours[i - 1]))
          << "log " << log_scale << " i " << i;
    for (const Vec3& c : colours) {
      EXPECT_TRUE(is_finite(c));
      EXPECT_GE(std::min({c.x, c.y, c.z}), 0.0f);
      EXPECT_LE(std::max({c.x, c.y, c.z}), 1.0f);
    }
  }
  // Log scaling spreads small values further apart than linear scaling.
  const std::vector<double> small = {1, 1000};
  EXPECT_GT(luminance(false_colour(small, true)[0]), luminance(false_colour(small, false)[0]));
}

TEST(Colormap, FalseColourEdgeCases) {
  double vmax = -1;
  EXPECT_TRUE(false_colour({}, false, &vmax).empty());
  EXPECT_EQ(vmax, 0.0);
  // All zero: everything at the low end, no division by zero.
  const std::vector<Vec3> zeros = false_colour({0, 0, 0}, true, &vmax);
  EXPECT_EQ(vmax, 0.0);
  for (const Vec3& c : zeros) EXPECT_EQ(c, zeros[0]);
  // NaN and negative values map to the low end, +inf to the high end; vmax ignores inf.
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Vec3> c =
      false_colour({std::numeric_limits<double>::quiet_NaN(), -5, 0, 2, 4, inf}, false, &vmax);
  EXPECT_EQ(vmax, 4.0);
  EXPECT_EQ(c[0], c[2]);
  EXPECT_EQ(c[1], c[2]);
  EXPECT_EQ(c[4], c[5]);
  EXPECT_TRUE(is_finite(c[0]));
}

}  // namespace
}  // namespace amalgam

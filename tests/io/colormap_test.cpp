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

/// An 8-bit sRGB code of a linear value (IEC 61966-2-1, written out here).
int srgb_code(float v) {
  const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(double(v), 1 / 2.4) - 0.055;
  return static_cast<int>(std::lround(255 * s));
}

// The published viridis (matplotlib's _viridis_data, as hex) at t = 0, 1/4, 1/2, 3/4 and 1:
// #440154, #3b528b, #21918c, #5ec962, #fde725. On a linear scale t = v / max; on the log
// scale t = log1p(v) / log1p(max), so v = e^(4t) - 1 with max e^4 - 1 hits the same five.
TEST(Colormap, FalseColourIsPublishedViridisOnTheStatedScale) {
  const int hex[5][3] = {{0x44, 0x01, 0x54},
                         {0x3b, 0x52, 0x8b},
                         {0x21, 0x91, 0x8c},
                         {0x5e, 0xc9, 0x62},
                         {0xfd, 0xe7, 0x25}};
  const std::vector<double> linear = {0, 1, 2, 3, 4};
  std::vector<double> log_spaced;
  for (int k = 0; k <= 4; ++k) log_spaced.push_back(std::expm1(k));
  for (bool log_scale : {false, true}) {
    const std::vector<Vec3> c = false_colour(log_scale ? log_spaced : linear, log_scale);
    for (int k = 0; k <= 4; ++k)
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(srgb_code(c[k][ch]), hex[k][ch], 2)
            << (log_scale ? "log" : "linear") << " scale, t = " << k / 4.0 << ", channel " << ch;
  }
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

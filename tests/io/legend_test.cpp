// io/legend.h: every false-colour picture states its scale (numbers under its colour bar, a
// title), and the CLI's cost, level and error PNGs carry that legend.

#include "amalgam/io/legend.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "amalgam/io/image.h"

namespace amalgam {
namespace legend_test {

bool is_white(const Vec3& c) {
  return c.x > 0.99f && c.y > 0.99f && c.z > 0.99f;
}

/// The columns of row band [y0, y1) holding a white pixel.
std::vector<bool> white_columns(const std::vector<Vec3>& px, int w, int y0, int y1) {
  std::vector<bool> out(static_cast<std::size_t>(w), false);
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < w; ++x)
      if (is_white(px[static_cast<std::size_t>(y) * w + x]))
        out[static_cast<std::size_t>(x)] = true;
  return out;
}

TEST(Legend, TextIsDrawnWithinItsMeasuredBox) {
  for (int scale : {1, 2, 3}) {
    Canvas c{120, 40, std::vector<Vec3>(120 * 40)};
    draw_text(c, 7, 5, "10 tests", scale, {1, 1, 1});
    int x0 = c.width, x1 = -1, y0 = c.height, y1 = -1;
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x)
        if (is_white(c.at(x, y)))
          x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    ASSERT_GE(x1, 0) << "nothing drawn at scale " << scale;
    EXPECT_GE(x0, 7) << scale;  // "1" has a bearing of one font pixel
    EXPECT_LE(x0, 7 + scale) << scale;
    EXPECT_EQ(y0, 5) << scale;  // digits reach the top of the line
    EXPECT_LT(x1, 7 + text_width("10 tests", scale)) << scale;
    EXPECT_GT(x1, 7 + text_width("10 tests", scale) - 8 * scale) << scale;
    EXPECT_LT(y1, 5 + text_height(scale)) << scale;  // no descender in "10 tests"
  }
  // Clipped, not written outside: a long text from near the right edge and the bottom.
  Canvas c{30, 10, std::vector<Vec3>(300)};
  draw_text(c, 25, 6, "clipped text", 2, {1, 1, 1});
  EXPECT_EQ(c.pixels.size(), 300u);
}

TEST(Legend, NumbersAreShortAndNeverInExponentFormBelow10000) {
  EXPECT_EQ(bar_number(1), "1");
  EXPECT_EQ(bar_number(100), "100");
  EXPECT_EQ(bar_number(356.4), "356");
  EXPECT_EQ(bar_number(1000), "1000");
  EXPECT_EQ(bar_number(2500.4), "2500");
  EXPECT_EQ(bar_number(12345), "1.2e+04");
  EXPECT_EQ(bar_number(0.178), "0.178");
  EXPECT_EQ(bar_number(0.00025), "0.00025");
  EXPECT_EQ(bar_number(0.0000251), "2.5e-05");
  EXPECT_EQ(bar_number(0), "0");
}

// The labels of a log bar are its two ends and the powers of ten between, each at the column
// with_colour_bar (colormap.h) marks with its white tick.
TEST(Legend, LogBarLabelsSitOnTheColourBarsTicks) {
  const int w = 480, h = 100;
  const LogRange r{2, 3000};
  const std::vector<BarLabel> labels = log_bar_labels(r, w);
  ASSERT_EQ(labels.size(), 5u);
  EXPECT_EQ(labels[0].text, "2");
  EXPECT_EQ(labels[0].x, 0);
  EXPECT_EQ(labels[1].text, "10");
  EXPECT_EQ(labels[2].text, "100");
  EXPECT_EQ(labels[3].text, "1000");
  EXPECT_EQ(labels[4].text, "3000");
  EXPECT_EQ(labels[4].x, w);
  int out_h = 0;
  const std::vector<Vec3> bar = with_colour_bar(std::vector<Vec3>(w * h), w, h, r, out_h);
  const std::vector<bool> ticks = white_columns(bar, w, h + 1, out_h);
  for (int i = 1; i <= 3; ++i)
    EXPECT_TRUE(ticks[static_cast<std::size_t>(labels[static_cast<std::size_t>(i)].x)])
        << labels[static_cast<std::size_t>(i)].text;
  // An end that is itself a power of ten is not labelled twice.
  const std::vector<BarLabel> decade = log_bar_labels({1, 100}, w);
  ASSERT_EQ(decade.size(), 3u);
  EXPECT_EQ(decade[1].text, "10");
}

// Labels that would overlap are left out, the ends first kept; all stay inside the picture.
TEST(Legend, LabelsThatDoNotFitAreLeftOutAndTheEndsKept) {
  Canvas c{40, 10, std::vector<Vec3>(400)};
  append_labels(c, {{"1", 0}, {"10", 14}, {"100", 27}, {"1000", 40}}, "a title far too wide", "");
  EXPECT_EQ(c.height, 10 + 11) << "one row of numbers, no title row";
  const std::vector<bool> cols = white_columns(c.pixels, 40, 10, c.height);
  EXPECT_TRUE(cols[0] || cols[1]) << "the low end";
  EXPECT_TRUE(cols[36] || cols[37] || cols[38]) << "the high end, right-aligned inside";
  int runs = 0;
  for (int x = 0; x < 40; ++x)
    runs += cols[static_cast<std::size_t>(x)] && (x == 0 || !cols[x - 1]);
  EXPECT_GE(runs, 2);
}

// --- the CLI's pictures -------------------------------------------------------------------

int amalgam(const std::string& args) {
  const std::string cmd = std::string(AMALGAM_BINARY) + " " + args + " 2>/dev/null";
  return WEXITSTATUS(std::system(cmd.c_str()));
}

std::filesystem::path legend_dir() {
  const auto d =
      std::filesystem::temp_directory_path() /
      ("amalgam-legend-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::create_directories(d);
  return d;
}

// The cost PNG: under its colour bar the numbers of its range and its title.
TEST(Legend, CostPngShowsTheNumbersOfItsRangeAndATitle) {
  const auto d = legend_dir();
  const std::string c = (d / "c.png").string();
  ASSERT_EQ(amalgam("render builtin:prisms --set depth=4 --width 480 --height 100 --spp 1 "
                    "--cost-range 3,300 --quiet --out " +
                    (d / "a.png").string() + " --cost-image " + c),
            0);
  int w = 0, h = 0;
  const std::vector<Vec3> px = read_image(c, w, h);
  const int bar_end = 100 + 1 + 10;  // picture, black row, bar of height / 10 rows
  const int row = text_height(text_scale(w)) + 4 * text_scale(w);
  ASSERT_EQ(h, bar_end + 2 * row) << "a row of numbers and a title row";
  const std::vector<bool> numbers = white_columns(px, w, bar_end, bar_end + row);
  for (const BarLabel& l : log_bar_labels({3, 300}, w)) {  // 3, 10, 100, 300: none overlap
    const int half = text_width(l.text, text_scale(w)) / 2;
    const int x = std::clamp(static_cast<int>(l.x), half, w - half - 1);
    bool found = false;
    for (int dx = -half; dx <= half; ++dx)
      found = found || numbers[static_cast<std::size_t>(x + dx)];
    EXPECT_TRUE(found) << "no label " << l.text << " near column " << l.x;
  }
  const std::vector<bool> title = white_columns(px, w, bar_end + row, h);
  int lit = 0;
  for (bool b : title) lit += b;
  EXPECT_GT(lit, text_width("intersection tests", text_scale(w)) / 2) << "the title row";
  std::filesystem::remove_all(d);
}

// The level PNG: a bar of one block per level in its colour, the primitive and nothing
// swatches, and labels.
TEST(Legend, LevelPngShowsEachLevelsColourAndTheSpecialValues) {
  const auto d = legend_dir();
  const std::string l = (d / "l.png").string();
  ASSERT_EQ(amalgam("render builtin:prisms --set depth=5 --footprint 1 --width 240 --height 60 "
                    "--spp 1 --quiet --out " +
                    (d / "a.png").string() + " --level-image " + l),
            0);
  int w = 0, h = 0;
  const std::vector<Vec3> px = read_image(l, w, h);
  const int bar_y = 60 + 1 + 3;  // inside the bar of 6 rows
  for (int level = 0; level <= 5; ++level) {
    const int x = static_cast<int>((level + 0.5) * w / 6);
    const Vec3 want = viridis(level / 5.0);
    const Vec3 got = px[static_cast<std::size_t>(bar_y) * w + x];
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 0.01) << "level " << level;
  }
  int grey = 0, white = 0;
  for (std::size_t i = static_cast<std::size_t>(60 + 1 + 6) * w; i < px.size(); ++i) {
    grey += std::fabs(px[i].x - 0.6f) < 0.01f;
    white += is_white(px[i]);
  }
  EXPECT_GT(grey, 0) << "the primitive swatch";
  EXPECT_GT(white, 100) << "labels, swatch outlines and the title";
  std::filesystem::remove_all(d);
}

// compare --error-image: a linear bar from 0 to the largest error, labelled at both ends.
TEST(Legend, ErrorImageStatesItsLinearScale) {
  const auto d = legend_dir();
  const int w = 200, h = 40;
  std::vector<Vec3> a(w * h, Vec3{0.2f, 0.2f, 0.2f}), b = a;
  for (int x = 0; x < w / 2; ++x) b[static_cast<std::size_t>(x)].x = 0.7f;
  write_image((d / "a.pfm").string(), w, h, a);
  write_image((d / "b.pfm").string(), w, h, b);
  const std::string e = (d / "e.png").string();
  ASSERT_EQ(amalgam("compare " + (d / "a.pfm").string() + " " + (d / "b.pfm").string() +
                    " --error-image " + e),
            0);
  int ew = 0, eh = 0;
  const std::vector<Vec3> px = read_image(e, ew, eh);
  ASSERT_EQ(ew, w);
  const int bar_end = h + 1 + 6, row = text_height(1) + 4;
  ASSERT_EQ(eh, bar_end + 2 * row) << "bar, numbers, title";
  for (int x = 0; x < w; x += 20) {
    const Vec3 got = px[static_cast<std::size_t>(h + 3) * w + x], want = viridis((x + 0.5) / w);
    EXPECT_NEAR(got.y, want.y, 0.01) << "bar column " << x;
  }
  const std::vector<bool> numbers = white_columns(px, w, bar_end, bar_end + row);
  EXPECT_TRUE(numbers[0] || numbers[1]) << "0 at the left";
  bool right = false;
  for (int x = w - text_width(bar_number(std::sqrt(0.25 / 3)), 1); x < w; ++x)
    right = right || numbers[static_cast<std::size_t>(x)];
  EXPECT_TRUE(right) << "the largest error at the right";
  std::filesystem::remove_all(d);
}

}  // namespace legend_test
}  // namespace amalgam

#include "amalgam/analysis/metrics.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "amalgam/io/image.h"

namespace amalgam {
namespace {

namespace fs = std::filesystem;

/// A textured test image: smooth gradients plus fine detail, all within [0, 1].
std::vector<Vec3> texture(int w, int h, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 0.4f);
  std::vector<Vec3> px(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float base = 0.3f * (x + y) / static_cast<float>(w + h);
      const float check = ((x / 2 + y / 2) % 2) ? 0.2f : 0.0f;
      px[static_cast<std::size_t>(y) * w + x] = {base + check + u(rng), base + u(rng),
                                                 base + check + u(rng)};
    }
  return px;
}

/// Box blur of radius r (clipped at the border).
std::vector<Vec3> blur(const std::vector<Vec3>& in, int w, int h, int r) {
  std::vector<Vec3> out(in.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3 s{};
      int n = 0;
      for (int j = -r; j <= r; ++j)
        for (int i = -r; i <= r; ++i) {
          const int xi = x + i, yj = y + j;
          if (xi < 0 || yj < 0 || xi >= w || yj >= h) continue;
          s += in[static_cast<std::size_t>(yj) * w + xi];
          ++n;
        }
      out[static_cast<std::size_t>(y) * w + x] = s / static_cast<float>(n);
    }
  return out;
}

TEST(Metrics, IdenticalImages) {
  const auto a = texture(32, 24);
  const ImageComparison c = compare_images(a, a, 32, 24);
  EXPECT_EQ(c.rmse, 0.0);
  EXPECT_TRUE(std::isinf(c.psnr) && c.psnr > 0) << c.psnr;
  EXPECT_DOUBLE_EQ(c.ssim, 1.0);
  EXPECT_EQ(c.mean_abs, 0.0);
  EXPECT_EQ(c.max_abs, 0.0);
  for (double e : error_map(a, a)) EXPECT_EQ(e, 0.0);
}

TEST(Metrics, KnownNoiseGivesKnownRmseAndPsnr) {
  // +-0.1 with random signs in every channel: RMSE exactly 0.1, PSNR 20 dB.
  const int w = 40, h = 30;
  const auto a = texture(w, h);
  std::mt19937 rng(7);
  auto b = a;
  for (Vec3& p : b)
    for (int c = 0; c < 3; ++c) p[c] += (rng() & 1) ? 0.1f : -0.1f;
  const ImageComparison c = compare_images(a, b, w, h);
  EXPECT_NEAR(c.rmse, 0.1, 1e-6);
  EXPECT_NEAR(c.psnr, 20.0, 1e-4);
  EXPECT_NEAR(c.mean_abs, 0.1, 1e-6);
  EXPECT_NEAR(c.max_abs, 0.1, 1e-6);
  EXPECT_LT(c.ssim, 1.0);
  for (double e : error_map(a, b)) EXPECT_NEAR(e, 0.1, 1e-6);
}

TEST(Metrics, RmseOverChannels) {
  // One pixel, error 0.3 in one channel only: sqrt(0.09 / 3).
  const std::vector<Vec3> a{{0.5f, 0.5f, 0.5f}}, b{{0.8f, 0.5f, 0.5f}};
  EXPECT_NEAR(rmse(a, b), std::sqrt(0.09 / 3), 1e-6);
  EXPECT_NEAR(psnr(0.1), 20.0, 1e-12);
  EXPECT_NEAR(psnr(0.5, 255.0), 20 * std::log10(510.0), 1e-9);
}

TEST(Metrics, SsimDecreasesWithBlur) {
  const int w = 64, h = 48;
  const auto a = texture(w, h);
  double previous = ssim(a, a, w, h);
  EXPECT_DOUBLE_EQ(previous, 1.0);
  for (int r = 1; r <= 4; ++r) {
    const double s = ssim(a, blur(a, w, h, r), w, h);
    EXPECT_LT(s, previous) << "blur radius " << r;
    EXPECT_GT(s, -1.0);
    previous = s;
  }
}

TEST(Metrics, SsimIsSymmetricAndInRange) {
  const int w = 20, h = 16;
  const auto a = texture(w, h, 1), b = texture(w, h, 2);
  const double s = ssim(a, b, w, h);
  EXPECT_NEAR(s, ssim(b, a, w, h), 1e-12);
  EXPECT_LT(s, 0.9);
  EXPECT_GE(s, -1.0);
}

TEST(Metrics, SsimOfConstantImages) {
  // Equal constants: 1. A constant against another: the luminance term only.
  const std::vector<Vec3> a(16 * 16, Vec3{0.5f, 0.5f, 0.5f}), b(16 * 16, Vec3{0.25f, 0.25f, 0.25f});
  EXPECT_NEAR(ssim(a, a, 16, 16), 1.0, 1e-12);
  const double c1 = 0.01 * 0.01;
  EXPECT_NEAR(ssim(a, b, 16, 16), (2 * 0.5 * 0.25 + c1) / (0.25 + 0.0625 + c1), 1e-9);
}

TEST(Metrics, SsimClampsLuminance) {
  // Values above 1 all clamp to white: no structural difference is seen.
  const std::vector<Vec3> a(12 * 12, Vec3{2.0f, 2.0f, 2.0f}), b(12 * 12, Vec3{5.0f, 5.0f, 5.0f});
  EXPECT_NEAR(ssim(a, b, 12, 12), 1.0, 1e-12);
  EXPECT_GT(rmse(a, b), 2.9);  // RMSE is on unclamped linear RGB
}

TEST(Metrics, SmallerThanWindow) {
  const auto a = texture(5, 3);
  EXPECT_DOUBLE_EQ(ssim(a, a, 5, 3), 1.0);
  EXPECT_LT(ssim(a, blur(a, 5, 3, 1), 5, 3), 1.0);
}

// relMSE = mean over pixels and channels of (a - b)^2 / (b^2 + 0.01), b the reference.
TEST(Metrics, RelativeMseKnownValues) {
  const std::vector<Vec3> a = {{1, 1, 1}, {0.5f, 0.5f, 0.5f}};
  const std::vector<Vec3> b = {{0.5f, 0.5f, 0.5f}, {0, 0, 0}};
  // 0.25 / 0.26 on pixel 0, 0.25 / 0.01 = 25 on pixel 1 (a dark reference weighs heavily).
  EXPECT_NEAR(rel_mse(a, b), (0.25 / 0.26 + 25.0) / 2.0, 1e-6);
  EXPECT_EQ(rel_mse(a, a), 0.0);
  EXPECT_NE(rel_mse(a, b), rel_mse(b, a)) << "relative to the second image";
  EXPECT_EQ(compare_images(a, b, 2, 1).rel_mse, rel_mse(a, b));
  EXPECT_THROW(rel_mse(a, {{0, 0, 0}}), MetricsError);
}

TEST(Metrics, SizeMismatchThrows) {
  const auto a = texture(4, 4), b = texture(4, 5);
  EXPECT_THROW(rmse(a, b), MetricsError);
  EXPECT_THROW(error_map(a, b), MetricsError);
  EXPECT_THROW(ssim(a, a, 5, 4), MetricsError);
  EXPECT_THROW(compare_images(a, b, 4, 4), MetricsError);
}

// ---- the `amalgam compare` command ----

struct CliRun {
  int status;
  std::string out, err;
};

class CompareCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("amalgam_metrics_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  static std::string slurp(const std::string& path) {
    std::ifstream f(path);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }
  CliRun run(const std::string& args) const {
    const std::string out = file("stdout.txt"), err = file("stderr.txt");
    const std::string cmd =
        std::string(AMALGAM_BINARY) + " compare " + args + " >" + out + " 2>" + err;
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
  }
  fs::path dir_;
};

TEST_F(CompareCli, IdenticalImagesPrintInf) {
  const std::string a = file("a.pfm");
  write_image(a, 16, 12, texture(16, 12));
  const CliRun r = run(a + " " + a);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\nrmse            0\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\npsnr_db         inf\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nssim            1\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nrel_mse         0\n"), std::string::npos) << r.out;
}

// b = a plus 0.25 in the red channel of the left half of the pixels. Per channel the error is
// 0.25 on one sixth of all samples: RMSE sqrt(0.0625 / 6), PSNR -20 log10(RMSE), mean
// |error| 0.25 / 6, max 0.25; per pixel (the error image) sqrt(0.0625 / 3) on the left half,
// 0 on the right: viridis' top (#fde725) and bottom (#440154) on a linear scale.
TEST_F(CompareCli, JsonAndErrorImage) {
  const int w = 16, h = 12;
  const std::string a = file("a.pfm"), b = file("b.pfm"), e = file("err.png");
  const std::vector<Vec3> img = texture(w, h);
  std::vector<Vec3> shifted = img;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w / 2; ++x) shifted[static_cast<std::size_t>(y) * w + x].x += 0.25f;
  write_image(a, w, h, img);
  write_image(b, w, h, shifted);
  const CliRun r = run(a + " " + b + " --json --error-image " + e);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::ordered_json::parse(r.out);
  const double rmse = std::sqrt(0.0625 / 6);
  EXPECT_EQ(j["a"], a);
  EXPECT_EQ(j["b"], b);
  EXPECT_EQ(j["width"], w);
  EXPECT_EQ(j["height"], h);
  EXPECT_NEAR(j["rmse"].get<double>(), rmse, 1e-6);
  EXPECT_NEAR(j["psnr_db"].get<double>(), -20 * std::log10(rmse), 1e-4);
  EXPECT_NEAR(j["mean_abs_error"].get<double>(), 0.25 / 6, 1e-6);
  EXPECT_NEAR(j["max_abs_error"].get<double>(), 0.25, 1e-6);
  EXPECT_NEAR(j["ssim"].get<double>(), ssim(img, shifted, w, h), 1e-12);
  EXPECT_LT(j["ssim"].get<double>(), 0.99);
  EXPECT_EQ(j["error_image"], e);
  EXPECT_NEAR(j["error_image_max"].get<double>(), std::sqrt(0.0625 / 3), 1e-6);
  int ew = 0, eh = 0;
  const std::vector<Vec3> err = read_image(e, ew, eh);
  ASSERT_EQ(ew, w);
  ASSERT_EQ(eh, h + 1 + 6 + 11) << "the picture and its legend: bar and numbers (io/legend.h)";
  const auto srgb8 = [](float v) {
    return static_cast<int>(
        std::lround(255 * (v <= 0.0031308f ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055)));
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Vec3 c = err[static_cast<std::size_t>(y) * w + x];
      const int want[3] = {x < w / 2 ? 0xfd : 0x44, x < w / 2 ? 0xe7 : 0x01,
                           x < w / 2 ? 0x25 : 0x54};
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(srgb8(c[ch]), want[ch], 1) << "pixel " << x << "," << y << " channel " << ch;
    }
  // relMSE against the reference b: 0.0625 / (b_r^2 + 0.01) on the shifted red samples.
  double rel = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w / 2; ++x) {
      const double br = shifted[static_cast<std::size_t>(y) * w + x].x;
      rel += 0.0625 / (br * br + 0.01);
    }
  EXPECT_NEAR(j["rel_mse"].get<double>(), rel / (3.0 * w * h), 1e-6);
  // The text form prints the same keys, in the same order, with the same figures.
  const CliRun text = run(a + " " + b + " --error-image " + e);
  ASSERT_EQ(text.status, 0) << text.err;
  std::istringstream lines(text.out);
  std::string key, value;
  auto it = j.begin();
  int n = 0;
  while (lines >> key >> value) {
    ASSERT_NE(it, j.end()) << "extra key " << key;
    EXPECT_EQ(key, it.key());
    if (it->is_string())
      EXPECT_EQ(value, it->get<std::string>()) << key;
    else
      EXPECT_NEAR(std::stod(value), it->get<double>(), 1e-5 * std::fabs(it->get<double>())) << key;
    ++it, ++n;
  }
  EXPECT_EQ(it, j.end()) << "the text output lacks keys of the JSON output";
  EXPECT_EQ(n, 12);
}

TEST_F(CompareCli, SizeMismatchIsBadInput) {
  const std::string a = file("a.png"), b = file("b.png"), e = file("err.png");
  write_image(a, 8, 8, texture(8, 8));
  write_image(b, 8, 9, texture(8, 9));
  const CliRun r = run(a + " " + b + " --error-image " + e);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("8x8"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("8x9"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(e)) << "no output on bad input";
}

TEST_F(CompareCli, MissingOrBadArguments) {
  const std::string a = file("a.png");
  write_image(a, 4, 4, texture(4, 4));
  const CliRun missing = run(a + " " + file("nope.png"));
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("nope.png"), std::string::npos) << missing.err;
  EXPECT_EQ(run(a).status, 2) << "two images are required";
  EXPECT_EQ(run("--help").status, 0);
  // An error image that can never be written is bad input, refused before the comparison (as
  // render's outputs are).
  const CliRun bad_out = run(a + " " + a + " --error-image /no/such/dir/e.png");
  EXPECT_EQ(bad_out.status, 2) << bad_out.err;
  EXPECT_NE(bad_out.err.find("/no/such/dir"), std::string::npos) << bad_out.err;
}

}  // namespace
}  // namespace amalgam

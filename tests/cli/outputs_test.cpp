// The outputs of `amalgam render` that researchers read (docs/outputs.md): the float32
// multi-layer OpenEXR and its header, the cost PNG's scale and colour bar, the level image,
// and the stats JSON's run description.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

// OpenEXR 3.1's headers trip -Wunused-parameter under clang when not included as system headers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfRgbaFile.h>
#include <ImfStringAttribute.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "cli_support.h"

namespace {
namespace outputs {  // per file: the tests are compiled in batches

namespace fs = std::filesystem;

using amalgam::test::slurp;
using Result = amalgam::test::CommandResult;

Result amalgam(const std::string& args, const std::string& err_file = "/dev/null") {
  return amalgam::test::run_command(std::string(AMALGAM_BINARY) + " " + args + " 2>" + err_file);
}

fs::path temp_dir() {
  return amalgam::test::scratch_dir("amalgam-outputs");
}

/// Every channel of an EXR file as float, by name; checks each is stored as FLOAT.
std::map<std::string, std::vector<float>> read_channels(const fs::path& path, int& w, int& h,
                                                        Imf::Header* header = nullptr) {
  Imf::InputFile in(path.c_str());
  if (header) *header = in.header();
  const Imath::Box2i dw = in.header().dataWindow();
  w = dw.max.x - dw.min.x + 1;
  h = dw.max.y - dw.min.y + 1;
  std::map<std::string, std::vector<float>> out;
  Imf::FrameBuffer fb;
  const Imf::ChannelList& channels = in.header().channels();
  for (auto c = channels.begin(); c != channels.end(); ++c) {
    EXPECT_EQ(c.channel().type, Imf::FLOAT) << c.name() << " is not float32";
    std::vector<float>& v = out[c.name()];
    v.resize(static_cast<std::size_t>(w) * h);
    const long origin = dw.min.x + long(dw.min.y) * w;
    fb.insert(c.name(), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data() - origin),
                                   sizeof(float), sizeof(float) * w));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  return out;
}

const std::string kRender =
    "render builtin:prisms --set depth=5 --set view=corner --width 40 --height 30 --spp 3 "
    "--seed 7 --quiet ";

TEST(RenderOutputs, ExrHasEveryLayerInFloat32AndTheCostAddsUpToTheStats) {
  const fs::path d = temp_dir() / "exr";
  fs::create_directories(d);
  ASSERT_EQ(amalgam(kRender + "--out " + (d / "a.exr").string() + " --stats " +
                    (d / "s.json").string() + " --level-image " + (d / "l.pfm").string())
                .status,
            0);
  int w = 0, h = 0;
  Imf::Header header;
  const auto ch = read_channels(d / "a.exr", w, h, &header);
  ASSERT_EQ(w, 40);
  ASSERT_EQ(h, 30);
  for (const char* name : {"R", "G", "B", "cost.Y", "level.Y", "Z", "N.X", "N.Y", "N.Z", "albedo.R",
                           "albedo.G", "albedo.B"})
    EXPECT_EQ(ch.count(name), 1u) << "channel " << name;
  EXPECT_EQ(ch.size(), 12u);

  const auto j = nlohmann::json::parse(slurp(d / "s.json"));
  std::uint64_t sum = 0;
  for (float c : ch.at("cost.Y")) {
    ASSERT_EQ(c, std::floor(c)) << "a whole number of tests";
    sum += static_cast<std::uint64_t>(c);
  }
  EXPECT_EQ(sum, j["tests"]["total"].get<std::uint64_t>()) << "exactly the stats' total";

  for (const char* key : {"amalgam:command", "amalgam:version", "amalgam:scene", "amalgam:seed",
                          "amalgam:spp", "amalgam:options", "amalgam:cost", "amalgam:level"}) {
    const auto* a = header.findTypedAttribute<Imf::StringAttribute>(key);
    ASSERT_NE(a, nullptr) << key;
    EXPECT_FALSE(a->value().empty()) << key;
  }
  EXPECT_EQ(header.typedAttribute<Imf::StringAttribute>("amalgam:seed").value(), "7");
  EXPECT_EQ(header.typedAttribute<Imf::StringAttribute>("amalgam:spp").value(), "3");
  EXPECT_EQ(header.typedAttribute<Imf::StringAttribute>("amalgam:version").value(),
            j["version"].get<std::string>());
  EXPECT_NE(header.typedAttribute<Imf::StringAttribute>("amalgam:command").value().find("--seed 7"),
            std::string::npos);
  EXPECT_EQ(header.typedAttribute<Imf::StringAttribute>("amalgam:scene").value(), "builtin:prisms");

  // The layers hold what docs/outputs.md says: background (level -1) has depth +inf and zero
  // normal and albedo; a hit has a finite depth and a normal of length at most 1.
  int background = 0, hits = 0;
  for (int i = 0; i < w * h; ++i) {
    const float level = ch.at("level.Y")[i], z = ch.at("Z")[i];
    const float nx = ch.at("N.X")[i], ny = ch.at("N.Y")[i], nz = ch.at("N.Z")[i];
    if (level == -1.0f && std::isinf(z)) {
      ++background;
      EXPECT_EQ(nx * nx + ny * ny + nz * nz, 0.0f);
      EXPECT_EQ(ch.at("albedo.G")[i], 0.0f);
    } else if (std::isfinite(z)) {
      ++hits;
      EXPECT_GT(z, 0.0f);
      EXPECT_LE(std::sqrt(nx * nx + ny * ny + nz * nz), 1.0f + 1e-5f);
    }
    EXPECT_TRUE(level == -1.0f || level == -2.0f || (level >= 0.0f && level <= 5.0f)) << level;
  }
  EXPECT_GT(background, 0);
  EXPECT_GT(hits, 0);

  // --level-image x.pfm holds the same raw levels.
  int lw = 0, lh = 0;
  const std::vector<amalgam::Vec3> levels = amalgam::read_image((d / "l.pfm").string(), lw, lh);
  ASSERT_EQ(levels.size(), ch.at("level.Y").size());
  for (std::size_t i = 0; i < levels.size(); ++i)
    EXPECT_EQ(levels[i].x, ch.at("level.Y")[i]) << "pixel " << i;
}

// Same seed, same bytes, any thread count: the EXR header records the command and the options
// without --threads (the stats JSON holds the threads used), so the whole file is the same.
TEST(RenderOutputs, ExrBytesAreTheSameForAnyThreadCount) {
  const fs::path d = temp_dir() / "exr-threads";
  fs::create_directories(d);
  const std::string out = (d / "a.exr").string();
  std::string first;
  for (const char* threads : {"--threads 1", "--threads=2", "--threads 3"}) {
    SCOPED_TRACE(threads);
    ASSERT_EQ(amalgam(kRender + threads + " --out " + out).status, 0);
    const std::string bytes = slurp(out);
    if (first.empty()) {
      first = bytes;
      Imf::Header header;
      int w = 0, h = 0;
      (void)read_channels(out, w, h, &header);
      const std::string command =
          header.typedAttribute<Imf::StringAttribute>("amalgam:command").value();
      EXPECT_EQ(command.find("--threads"), std::string::npos) << command;
      EXPECT_NE(command.find("--seed 7"), std::string::npos) << command;
      EXPECT_EQ(
          header.typedAttribute<Imf::StringAttribute>("amalgam:options").value().find("threads"),
          std::string::npos);
    } else {
      EXPECT_TRUE(bytes == first) << "the file differs from the one rendered with 1 thread";
    }
  }
}

// Totals above 2048 per pixel (where half floats round) are exact in the float32 cost layer.
TEST(RenderOutputs, ExrCostIsExactBeyondHalfPrecision) {
  const fs::path d = temp_dir() / "exact";
  fs::create_directories(d);
  ASSERT_EQ(amalgam("render builtin:prisms --set depth=5 --set view=corner --renderer "
                    "traditional --width 4 --height 3 --spp 64 --quiet --out " +
                    (d / "a.exr").string() + " --stats " + (d / "s.json").string())
                .status,
            0);
  int w = 0, h = 0;
  const auto ch = read_channels(d / "a.exr", w, h);
  std::uint64_t sum = 0;
  float top = 0;
  int odd_above_2048 = 0;  // half floats hold only even integers in [2048, 4096)
  for (float c : ch.at("cost.Y")) {
    ASSERT_EQ(c, std::floor(c));
    sum += static_cast<std::uint64_t>(c);
    top = std::max(top, c);
    odd_above_2048 += c > 2048 && static_cast<std::uint64_t>(c) % 2 == 1;
  }
  EXPECT_GT(top, 2048.0f) << "the test needs a pixel beyond half precision";
  EXPECT_GT(odd_above_2048, 0) << "no total that half would have rounded";
  const auto j = nlohmann::json::parse(slurp(d / "s.json"));
  EXPECT_EQ(sum, j["tests"]["total"].get<std::uint64_t>());
}

TEST(RenderOutputs, PlainRgbReadersAndCompareSeeTheBeauty) {
  const fs::path d = temp_dir() / "beauty";
  fs::create_directories(d);
  ASSERT_EQ(amalgam(kRender + "--out " + (d / "a.exr").string()).status, 0);
  ASSERT_EQ(amalgam(kRender + "--out " + (d / "a.pfm").string()).status, 0);
  // OpenEXR's RGBA interface (what a plain RGB reader uses) finds R, G and B.
  Imf::RgbaInputFile rgba((d / "a.exr").c_str());
  EXPECT_EQ(rgba.channels() & Imf::WRITE_RGB, Imf::WRITE_RGB);
  // compare reads the beauty as float32: identical to the PFM of the same render.
  const Result c =
      amalgam("compare " + (d / "a.exr").string() + " " + (d / "a.pfm").string() + " --json");
  ASSERT_EQ(c.status, 0);
  const auto j = nlohmann::json::parse(c.out);
  EXPECT_EQ(j["rmse"].get<double>(), 0.0);
  EXPECT_EQ(j["max_abs_error"].get<double>(), 0.0);
}

/// The sRGB bytes of a PNG (8-bit) as read back, one Vec3 per pixel in [0, 255].
std::vector<amalgam::Vec3> png_pixels(const fs::path& p, int& w, int& h) {
  return amalgam::read_image(p.string(), w, h);
}

TEST(RenderOutputs, CostPngHasAColourBarAndAFixedRangeGivesTheSameColourForTheSameCost) {
  const fs::path d = temp_dir() / "cost";
  fs::create_directories(d);
  // Two different renders (a different view, and the traditional renderer) on one scale.
  const std::string scale = " --cost-range 2,400 ";
  const std::string a =
      "render builtin:prisms --set depth=5 --set view=corner --width 40 "
      "--height 30 --spp 1 --quiet" +
      scale;
  const std::string b =
      "render builtin:prisms --set depth=5 --renderer traditional --width 40 "
      "--height 30 --spp 1 --quiet" +
      scale;
  const Result ra = amalgam(a + "--out " + (d / "a.png").string() + " --cost-image " +
                            (d / "ca.png").string() + " --stats " + (d / "sa.json").string());
  ASSERT_EQ(ra.status, 0);
  ASSERT_EQ(
      amalgam(a + "--out " + (d / "a2.png").string() + " --cost-image " + (d / "ca.pfm").string())
          .status,
      0);
  ASSERT_EQ(
      amalgam(b + "--out " + (d / "b.png").string() + " --cost-image " + (d / "cb.png").string())
          .status,
      0);
  ASSERT_EQ(
      amalgam(b + "--out " + (d / "b2.png").string() + " --cost-image " + (d / "cb.pfm").string())
          .status,
      0);
  int w = 0, h = 0;
  const std::vector<amalgam::Vec3> raw_a = amalgam::read_image((d / "ca.pfm").string(), w, h);
  const std::vector<amalgam::Vec3> raw_b = amalgam::read_image((d / "cb.pfm").string(), w, h);
  const std::vector<amalgam::Vec3> png_a = png_pixels(d / "ca.png", w, h);
  ASSERT_EQ(w, 40);
  ASSERT_EQ(h, 30 + 1 + 6 + 11)
      << "the picture, one black row, a colour bar of 6 rows, a row of its numbers";
  const std::vector<amalgam::Vec3> png_b = png_pixels(d / "cb.png", w, h);
  int same = 0;
  for (int i = 0; i < 40 * 30; ++i)
    for (int k = 0; k < 40 * 30; ++k)
      if (raw_a[i].x == raw_b[k].x) {
        ++same;
        ASSERT_EQ(png_a[i], png_b[k]) << "cost " << raw_a[i].x << ": pixels " << i << ", " << k;
      }
  EXPECT_GT(same, 0) << "no cost in common: the test proves nothing";
  // The colour is that of the cost on the given scale, not on the image's own range.
  for (int i = 0; i < 40 * 30; ++i) {
    const amalgam::Vec3 want = amalgam::viridis(amalgam::log_position(raw_a[i].x, {2, 400}));
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(png_a[i][c], want[c], 0.01) << "pixel " << i;
  }

  // The bar: its bottom row runs through viridis left to right, luminance rising.
  const int bottom = 30 + 1 + 6 - 1;
  float last = -1.0f;
  for (int x = 0; x < w; ++x) {
    const amalgam::Vec3 c = png_a[static_cast<std::size_t>(bottom) * w + x];
    const float y = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
    EXPECT_GE(y, last) << "column " << x;
    last = y;
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(c[k], amalgam::viridis((x + 0.5) / w)[k], 0.01) << "column " << x;
  }
  for (int x = 0; x < w; ++x) EXPECT_EQ(png_a[30 * w + x], (amalgam::Vec3{})) << "black row";

  // The range is in the PNG's text metadata and in the stats.
  const std::string bytes = slurp(d / "ca.png");
  EXPECT_NE(bytes.find(std::string("amalgam:cost-range\0002,400", 24)), std::string::npos);
  const auto j = nlohmann::json::parse(slurp(d / "sa.json"));
  EXPECT_EQ(j["cost_range"]["min"].get<double>(), 2.0);
  EXPECT_EQ(j["cost_range"]["max"].get<double>(), 400.0);
}

TEST(RenderOutputs, DefaultCostRangeIsTheImagesOwnAndIsReported) {
  const fs::path d = temp_dir() / "own";
  fs::create_directories(d);
  const std::string err = (d / "err.txt").string();
  ASSERT_EQ(amalgam("render builtin:prisms --set depth=4 --width 20 --height 20 --spp 1 --out " +
                        (d / "a.png").string() + " --cost-image " + (d / "c.pfm").string() +
                        " --stats " + (d / "s.json").string(),
                    err)
                .status,
            0);
  int w = 0, h = 0;
  const std::vector<amalgam::Vec3> raw = amalgam::read_image((d / "c.pfm").string(), w, h);
  double lo = 1e300, hi = 0;
  for (const amalgam::Vec3& v : raw)
    if (v.x > 0) lo = std::min<double>(lo, v.x), hi = std::max<double>(hi, v.x);
  const auto j = nlohmann::json::parse(slurp(d / "s.json"));
  EXPECT_EQ(j["cost_range"]["min"].get<double>(), lo);
  EXPECT_EQ(j["cost_range"]["max"].get<double>(), hi);
}

TEST(RenderOutputs, StatsJsonDescribesTheRunWithIntegersAsIntegers) {
  const fs::path d = temp_dir() / "stats";
  fs::create_directories(d);
  ASSERT_EQ(amalgam("render builtin:prisms --set depth=4 --width 24 --height 16 --spp 2 "
                    "--threads 1 --seed 3 --quiet --out " +
                    (d / "a.png").string() + " --stats " + (d / "s.json").string())
                .status,
            0);
  const auto j = nlohmann::json::parse(slurp(d / "s.json"));
  for (const char* key : {"renderer",
                          "opacity",
                          "level",
                          "footprint",
                          "order",
                          "seed",
                          "scene",
                          "rays",
                          "tests",
                          "per_primary_ray",
                          "time_s",
                          "width",
                          "height",
                          "spp",
                          "threads",
                          "ranks",
                          "version",
                          "command_line",
                          "peak_memory_bytes",
                          "cost_range"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["width"], 24);
  EXPECT_EQ(j["height"], 16);
  EXPECT_EQ(j["spp"], 2);
  EXPECT_EQ(j["threads"], 1);
  EXPECT_EQ(j["ranks"], 1);
  EXPECT_TRUE(j["command_line"].is_array());
  EXPECT_EQ(j["command_line"][1], "render");
  EXPECT_GT(j["peak_memory_bytes"].get<std::uint64_t>(), 1u << 20);
  for (const char* t : {"load", "build", "bake", "render"})
    EXPECT_TRUE(j["time_s"][t].is_number()) << t;
  // Every count is a JSON integer (not 65536.0 or 1e+06).
  for (const auto* v :
       {&j["width"], &j["height"], &j["spp"], &j["threads"], &j["seed"], &j["peak_memory_bytes"],
        &j["scene"]["primitives"], &j["scene"]["nodes"], &j["scene"]["levels"],
        &j["rays"]["primary"], &j["rays"]["shadow"], &j["tests"]["total"],
        &j["per_primary_ray"]["max"], &j["per_primary_ray"]["p50"]})
    EXPECT_TRUE(v->is_number_integer()) << v->dump();
  for (const auto& v : j["tests"]["by_level"]) EXPECT_TRUE(v.is_number_integer());
}

TEST(RenderOutputs, LevelPngIsColourCodedWithItsLegendPrinted) {
  const fs::path d = temp_dir() / "level";
  fs::create_directories(d);
  const std::string err = (d / "err.txt").string();
  ASSERT_EQ(amalgam("render builtin:prisms --set depth=5 --level 2 --width 32 --height 24 "
                    "--spp 1 --out " +
                        (d / "a.png").string() + " --level-image " + (d / "l.png").string(),
                    err)
                .status,
            0);
  EXPECT_NE(slurp(err).find("level image"), std::string::npos) << slurp(err);
  int w = 0, h = 0;
  const std::vector<amalgam::Vec3> px = amalgam::read_image((d / "l.png").string(), w, h);
  // Level 2 of 0..5 is viridis(0.4); the background black.
  const amalgam::Vec3 want = amalgam::viridis(0.4);
  int on_level = 0, black = 0;
  for (const amalgam::Vec3& c : px) {
    on_level += std::fabs(c.x - want.x) < 0.01f && std::fabs(c.y - want.y) < 0.01f;
    black += c == amalgam::Vec3{};
  }
  EXPECT_GT(on_level, 0);
  EXPECT_GT(black, 0);
}

// With --cost-legend the cost PNG is the film's size, its pixels those of the picture above the
// bar without it (so it overlays the image), and the bar with its numbers is a PNG of its own.
TEST(RenderOutputs, CostLegendApartLeavesACostPngOfTheImagesSize) {
  const fs::path d = temp_dir();
  const std::string a =
      "render builtin:prisms --set depth=4 --width 40 --height 30 --spp 1 "
      "--quiet --cost-range 1,300 --out ";
  ASSERT_EQ(
      amalgam(a + (d / "l.png").string() + " --cost-image " + (d / "with_bar.png").string()).status,
      0);
  ASSERT_EQ(amalgam(a + (d / "l2.png").string() + " --cost-image " + (d / "apart.png").string() +
                    " --cost-legend " + (d / "bar.png").string())
                .status,
            0);
  int w = 0, h = 0, bw = 0, bh = 0, lw = 0, lh = 0;
  const auto apart = amalgam::read_image((d / "apart.png").string(), w, h);
  const auto with_bar = amalgam::read_image((d / "with_bar.png").string(), bw, bh);
  const auto bar = amalgam::read_image((d / "bar.png").string(), lw, lh);
  EXPECT_EQ(w, 40);
  EXPECT_EQ(h, 30);
  EXPECT_GT(bh, 30);
  EXPECT_TRUE(std::equal(apart.begin(), apart.end(), with_bar.begin()))
      << "the same colours as the picture above the bar";
  EXPECT_GE(lw, 40);
  EXPECT_GT(lh, 6);
  // A legend that is not a PNG, or without a PNG cost image: refused before any work.
  for (const std::string& bad :
       {" --cost-image " + (d / "c.png").string() + " --cost-legend " + (d / "bar.pfm").string(),
        " --cost-image " + (d / "c.pfm").string() + " --cost-legend " + (d / "bar2.png").string(),
        " --cost-legend " + (d / "bar3.png").string()}) {
    EXPECT_EQ(amalgam(a + (d / "x.png").string() + bad).status, 2) << bad;
    EXPECT_FALSE(fs::exists(d / "x.png")) << bad;
  }
}

}  // namespace outputs
}  // namespace

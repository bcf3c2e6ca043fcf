// `amalgam advise`: the renderers it compares, the figures it prints against what `compare`
// and `render` measure on the same images, its strip, and its refusals (docs/cli.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "amalgam/io/image.h"
#include "amalgam/render/tracer.h"
#include "cli_support.h"

namespace amalgam {
namespace advise_test {

namespace fs = std::filesystem;
using test::run_command;
using test::scratch_dir;
using test::slurp;

test::CommandResult amalgam_cli(const std::string& args) {
  return run_command(std::string(AMALGAM_BINARY) + " " + args + " 2>&1");
}

double rmse_of(const fs::path& a, const fs::path& b) {
  int w = 0, h = 0;
  const std::vector<Vec3> x = read_image(a.string(), w, h), y = read_image(b.string(), w, h);
  double s = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int k = 0; k < 3; ++k) s += (double(x[i][k]) - y[i][k]) * (double(x[i][k]) - y[i][k]);
  return std::sqrt(s / (3.0 * x.size()));
}

// On a small scene: every renderer is measured, the RMSE it reports is that of the image it
// kept against the reference it kept, full detail is 1x itself, the ratios are MSE x time
// ratios, the tests per ray are those `render` reports for the same options, and the strip has
// one column per renderer plus the reference.
TEST(Advise, MeasuresEveryRendererAgainstAConvergedEstimate) {
  const fs::path d = scratch_dir("amalgam-advise");
  const std::string args =
      "advise builtin:prisms --set depth=5 --width 64 --height 48 "
      "--reference-spp 32 --time 0.02 --repeats 1 --threads 2 --keep " +
      (d / "keep").string() + " --out " + (d / "strip.png").string() + " --json " +
      (d / "a.json").string();
  const test::CommandResult r = amalgam_cli(args);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("full detail"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("on this view"), std::string::npos) << "a verdict: " << r.out;
  const auto j = nlohmann::json::parse(slurp(d / "a.json"));
  const auto& rs = j["renderers"];
  ASSERT_EQ(rs.size(), have_embree() ? 5u : 4u);
  EXPECT_EQ(rs[0]["key"], "traditional");
  EXPECT_DOUBLE_EQ(rs[0]["vs_full_detail"].get<double>(), 1.0);
  const double base =
      std::pow(rs[0]["rmse"].get<double>(), 2) * rs[0]["render_seconds"].get<double>();
  for (const auto& m : rs) {
    const std::string key = m["key"];
    EXPECT_GE(m["spp"].get<int>(), 1) << key;
    EXPECT_NEAR(m["rmse"].get<double>(),
                rmse_of(d / "keep" / (key + ".pfm"), d / "keep" / "reference.pfm"), 1e-6)
        << key;
    EXPECT_NEAR(m["vs_full_detail"].get<double>(),
                base / (std::pow(m["rmse"].get<double>(), 2) * m["render_seconds"].get<double>()),
                1e-9)
        << key;
  }
  // Tests per ray: those of a plain render with the same options and spp.
  const auto& k1 = rs[have_embree() ? 2 : 1];
  ASSERT_EQ(k1["key"], "scale-sensitive-k1-stochastic");
  const test::CommandResult plain = run_command(
      std::string(AMALGAM_BINARY) +
      " render builtin:prisms --set depth=5 --width 64 --height 48 --sampler stratified --quiet "
      "--footprint 1 --spp " +
      std::to_string(k1["spp"].get<int>()) + " --out " + (d / "k1.pfm").string() + " --stats -");
  ASSERT_EQ(plain.status, 0);
  const auto st = nlohmann::json::parse(plain.out);
  EXPECT_DOUBLE_EQ(k1["tests_per_primary_ray"].get<double>(),
                   st["per_primary_ray"]["mean"].get<double>());
  EXPECT_EQ(slurp(d / "k1.pfm"), slurp(d / "keep" / "scale-sensitive-k1-stochastic.pfm"))
      << "the same image as render gives";
  int w = 0, h = 0;
  read_image((d / "strip.png").string(), w, h);
  EXPECT_EQ(w, static_cast<int>(rs.size() + 1) * 64 + static_cast<int>(rs.size()) * 4);
  EXPECT_GT(h, 3 * 48);
}

// Outputs are checked before any work; options that choose a renderer are not advise's.
TEST(Advise, RefusesBadOutputsAndRendererOptions) {
  const fs::path d = scratch_dir("amalgam-advise");
  for (const std::string& bad : std::vector<std::string>{
           "advise builtin:prisms --out " + (d / "x.exr").string(),
           "advise builtin:prisms --out " + (d / "no/such/dir/x.png").string(),
           "advise builtin:prisms --renderer traditional", "advise builtin:prisms --width 0",
           "advise builtin:prisms --time 0"}) {
    const test::CommandResult r = amalgam_cli(bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << bad << ": " << r.out;
  }
}

// Every output goes through render's checks, before any work: advise used to replace the
// scene with --json, the scene's sky map with --out or with a --keep image of the same name,
// and write one file twice, all with exit 0.
TEST(Advise, AnOutputNeverReplacesAnInputOrAnotherOutput) {
  const fs::path d = scratch_dir("amalgam-advise-inputs");
  // Two scenes under a sky map: one a PNG (what --out writes), one named as --keep's reference.
  const std::string png = (d / "map.png").string(), pfm = (d / "reference.pfm").string();
  for (const std::string& map : {png, pfm})
    ASSERT_EQ(amalgam_cli("render builtin:prisms --set depth=3 --width 8 --height 4 --spp 1 "
                          "--quiet --out " +
                          map)
                  .status,
              0);
  const std::string scene = (d / "s.json").string(), keep_scene = (d / "k.json").string(),
                    strip = (d / "strip.png").string();
  for (const auto& [file, map] :
       {std::pair{scene, "map.png"}, std::pair{keep_scene, "reference.pfm"}})
    std::ofstream(file) << R"({"spheres": [{"centre": [0, 0, 0], "radius": 1}],
      "lights": [{"type": "sky", "map": ")"
                        << map << R"("}]})";
  const std::string scene_bytes = test::slurp(scene), png_bytes = test::slurp(png),
                    pfm_bytes = test::slurp(pfm);
  const std::string size = " --width 16 --height 12 --time 0.01 ";
  const std::string small = "advise " + scene + size;
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {small + "--json " + scene, "an output never replaces an input"},
           {small + "--out " + png, "an output never replaces an input"},
           {"advise " + keep_scene + size + "--keep " + d.string(),
            "an output never replaces an input"},
           {small + "--out " + strip + " --json " + strip, "the same file as --out"},
           {small + "--keep /proc/amalgam-advise", "cannot create the directory"},
           {"advise " + scene + " --width 200000 --height 200000", "films held at once need"}}) {
    const test::CommandResult r = amalgam_cli(args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.out;
    EXPECT_NE(r.out.find(says), std::string::npos) << args << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << ": " << r.out;
  }
  EXPECT_EQ(test::slurp(scene), scene_bytes);
  EXPECT_EQ(test::slurp(png), png_bytes);
  EXPECT_EQ(test::slurp(pfm), pfm_bytes);
  EXPECT_FALSE(fs::exists(strip));
}

/// exp(mean -+ t * sd / sqrt(n)) of `logs`: the interval advise documents (Student's t, 95 %).
std::pair<double, double> interval(const std::vector<double>& logs) {
  const double t[] = {0, 12.706, 4.303, 3.182, 2.776, 2.571};
  const double n = static_cast<double>(logs.size());
  double mean = 0, var = 0;
  for (double l : logs) mean += l / n;
  for (double l : logs) var += (l - mean) * (l - mean) / (n - 1);
  const double half = t[logs.size() - 1] * std::sqrt(var / n);
  return {std::exp(mean - half), std::exp(mean + half)};
}

// On a close-up (a Wuson filling the view: amalgams render little but full detail), each ratio
// and interval is what the repeats' own errors and times give, the best named has the best
// ratio, and every renderer it is not tied with is slower beyond the interval: advise never
// names as best a renderer slower than another by more than the noise.
TEST(Advise, NamesABestOnlyBeyondTheIntervalsOfTheRepeats) {
  const fs::path d = scratch_dir("amalgam-advise-repeats");
  const test::CommandResult r = amalgam_cli(
      "advise /usr/share/assimp/models/PLY/Wuson.ply --width 48 --height 36 --reference-spp 16 "
      "--time 0.03 --repeats 4 --threads 2 --json " +
      (d / "a.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(slurp(d / "a.json"));
  const auto& rs = j["renderers"];
  ASSERT_EQ(rs.size(), have_embree() ? 6u : 5u) << "the volumetric renderer is compared";
  EXPECT_EQ(rs.back()["key"], "volumetric");
  auto costs = [&](const nlohmann::json& m) {
    std::vector<double> c;
    for (const auto& run : m["runs"])
      c.push_back(
          std::log(std::pow(run["rmse"].get<double>(), 2) * run["render_seconds"].get<double>()));
    return c;
  };
  auto log_ratio = [&](const nlohmann::json& a, const nlohmann::json& b) {
    std::vector<double> out, x = costs(a), y = costs(b);
    for (std::size_t k = 0; k < x.size(); ++k) out.push_back(x[k] - y[k]);
    return out;
  };
  std::size_t best = 0;
  for (std::size_t i = 0; i < rs.size(); ++i) {
    ASSERT_EQ(rs[i]["runs"].size(), 4u);
    const auto [lo, hi] = interval(log_ratio(rs[0], rs[i]));
    EXPECT_NEAR(rs[i]["vs_full_detail_low"].get<double>(), lo, 1e-9 * lo);
    EXPECT_NEAR(rs[i]["vs_full_detail_high"].get<double>(), hi, 1e-9 * hi);
    EXPECT_NEAR(rs[i]["vs_full_detail"].get<double>(), std::sqrt(lo * hi), 1e-9 * hi);
    if (rs[i]["vs_full_detail"].get<double>() > rs[best]["vs_full_detail"].get<double>()) best = i;
  }
  ASSERT_EQ(j["best"], rs[best]["key"]) << r.out;
  std::vector<std::string> tied;
  for (const auto& k : j.value("tied_with_best", nlohmann::json::array())) tied.push_back(k);
  for (std::size_t i = 0; i < rs.size(); ++i) {
    if (i == best) continue;
    const bool is_tied = std::find(tied.begin(), tied.end(), rs[i]["key"]) != tied.end();
    // Its cost over the best's: tied exactly when the interval reaches 1.
    EXPECT_EQ(is_tied, interval(log_ratio(rs[i], rs[best])).first <= 1.0) << rs[i]["key"];
  }
  const auto& q = j["level_of_detail_vs_full_detail"];
  const std::string verdict = j["verdict"];
  EXPECT_EQ(verdict, q["low"].get<double>() > 1    ? "pays off"
                     : q["high"].get<double>() < 1 ? "does not pay off"
                                                   : "undecided");
  EXPECT_NE(r.out.find("Best error per time on this view: " + rs[best]["name"].get<std::string>()),
            std::string::npos)
      << r.out;
}

}  // namespace advise_test
}  // namespace amalgam

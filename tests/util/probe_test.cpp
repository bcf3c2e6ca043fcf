// util/probe.h: the light probe's switches (AMALGAM_LIGHT_PROBE), parsed and honoured by both
// renderers (scripts/bias_terms.py splits the volumetric renderer's error with them).

#include "amalgam/util/probe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../cli/cli_support.h"
#include "amalgam/io/pfm.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace probe_test {

TEST(LightProbe, ParsesSwitchesAndNamesThemInOneOrder) {
  EXPECT_TRUE(LightProbe::parse("").is_default());
  const LightProbe p = LightProbe::parse("shadow-triangles,no-hot-spot,lines=8");
  EXPECT_FALSE(p.shadow_cells);
  EXPECT_FALSE(p.hot_spot);
  EXPECT_TRUE(p.shadows);
  EXPECT_TRUE(p.camera_cells);
  EXPECT_EQ(p.lines, 8);
  EXPECT_EQ(p.describe(), "lines=8,no-hot-spot,shadow-triangles");
  const LightProbe q = LightProbe::parse("lit-share,no-other-hot-spot");
  EXPECT_TRUE(q.hot_spot);
  EXPECT_FALSE(q.other_hot_spot);
  EXPECT_FALSE(q.march_self);
  EXPECT_EQ(q.describe(), "lit-share,no-other-hot-spot");
  for (const char* bad : {"no-shadow", "lines=0", "lines=65", "lines=8x", "lines="})
    EXPECT_THROW(LightProbe::parse(bad), InputError) << bad;
}

struct Render {
  int status;
  nlohmann::json stats;
  std::vector<Vec3> image;
};

/// `amalgam render` of the sphere on its ground (two suns) under `probe`, 32 x 24, 1 spp.
Render render(const std::string& probe, const std::string& renderer) {
  const auto dir = test::scratch_dir("amalgam-probe");
  const std::string out = (dir / (renderer + "-" + probe + ".pfm")).string();
  const std::string stats = (dir / (renderer + "-" + probe + ".json")).string();
  const auto r = test::run_command(
      "AMALGAM_LIGHT_PROBE='" + probe + "' " + std::string(AMALGAM_BINARY) + " render " +
      AMALGAM_SOURCE_DIR
      "/scenes/volumetric/sphere.json --eye 0,6,10 --look-at 0,0.5,0 "
      "--width 32 --height 24 --spp 1 --quiet --renderer " +
      renderer + " --out " + out + " --stats " + stats + " 2>/dev/null");
  Render res{r.status, {}, {}};
  if (r.status != 0) return res;
  res.stats = nlohmann::json::parse(test::slurp(stats));
  int w = 0, h = 0;
  res.image = codec::read_pfm(out, w, h);
  return res;
}

double mean(const std::vector<Vec3>& img) {
  double s = 0;
  for (const Vec3& p : img) s += p.x + p.y + p.z;
  return s / static_cast<double>(img.size());
}

TEST(LightProbe, NoShadowsTracesNoShadowRayInEitherRenderer) {
  for (const char* renderer : {"traditional", "volumetric"}) {
    const Render lit = render("", renderer);
    const Render open = render("no-shadows", renderer);
    ASSERT_EQ(lit.status, 0);
    ASSERT_EQ(open.status, 0);
    EXPECT_GT(lit.stats["tests"]["shadow"].get<double>(), 0) << renderer;
    EXPECT_EQ(open.stats["tests"]["shadow"].get<double>(), 0) << renderer;
    EXPECT_EQ(open.stats["light_probe"], "no-shadows");
    EXPECT_FALSE(lit.stats.contains("light_probe"));
    EXPECT_GT(mean(open.image), mean(lit.image) * 1.001) << renderer;  // the sphere's shadow
  }
}

// With camera rays through triangles and no shadows, the volumetric renderer reads no cell and
// shades the full-detail hit as the traditional renderer does.
TEST(LightProbe, VolumetricWithoutCellsOrShadowsIsFullDetail) {
  const Render full = render("no-shadows", "traditional");
  const Render vol = render("camera-triangles,no-shadows", "volumetric");
  ASSERT_EQ(vol.status, 0);
  EXPECT_EQ(vol.stats["tests"]["cell"].get<double>(), 0);
  ASSERT_EQ(full.image.size(), vol.image.size());
  for (std::size_t i = 0; i < full.image.size(); ++i)
    EXPECT_NEAR(vol.image[i].y, full.image[i].y, 1e-5f * (1.0f + full.image[i].y)) << i;
}

TEST(LightProbe, AnUnknownSwitchIsBadInputAndWritesNothing) {
  const auto dir = test::scratch_dir("amalgam-probe");
  const std::string out = (dir / "bad.png").string();
  const auto r =
      test::run_command("AMALGAM_LIGHT_PROBE=no-sky " + std::string(AMALGAM_BINARY) +
                        " render builtin:demo --width 8 --height 8 --out " + out + " 2>&1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("AMALGAM_LIGHT_PROBE"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace probe_test
}  // namespace amalgam

// The sky (constant or an equirectangular map, scene/sky.h) and spot lights (scene/scene.h),
// against closed forms: a Lambertian floor of albedo rho under an open sky of radiance L sends
// rho L; a spot light's falloff is glTF's.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "amalgam/builtin/params.h"
#include "amalgam/io/image.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/lights.h"
#include "amalgam/render/render.h"
#include "amalgam/scene/sky.h"

namespace amalgam {
namespace sky_spot_test {

namespace fs = std::filesystem;

fs::path dir() {
  const fs::path d = fs::temp_directory_path() / ("amalgam_sky_" + std::to_string(getpid()));
  fs::create_directories(d);
  return d;
}

/// A floor (albedo 0.5, top at y = 0), optionally a roof over it, the given lights, and a
/// camera at `eye` looking at `at` with a narrow field of view.
std::string scene(const std::string& lights, const std::string& eye, const std::string& at,
                  bool roof = false) {
  std::string s = R"({"materials": {"m": {"colour": [0.5, 0.5, 0.5]}},
    "boxes": [{"min": [-100, -1, -100], "max": [100, 0, 100], "material": "m"})";
  if (roof)  // and walls: a closed room (under a roof alone, rays within 1 degree of the
             // horizon would still see the sky between floor and roof)
    s += R"(, {"min": [-100, 2, -100], "max": [100, 3, 100], "material": "m"},
      {"min": [-101, -1, -101], "max": [-100, 3, 101], "material": "m"},
      {"min": [100, -1, -101], "max": [101, 3, 101], "material": "m"},
      {"min": [-101, -1, -101], "max": [101, 3, -100], "material": "m"},
      {"min": [-101, -1, 100], "max": [101, 3, 101], "material": "m"})";
  s += R"(], "camera": {"position": )" + eye + R"(, "look_at": )" + at +
       R"(, "up": [0, 0, -1], "vfov": 2}, "lights": [)" + lights + "]}";
  return s;
}

/// The mean colour of a render of scene file text `json` (16 x 16, full detail).
Vec3 mean_colour(const std::string& json, int spp = 4) {
  const fs::path p = dir() / "s.json";
  std::ofstream(p) << json;
  const LoadedScene s = load_scene(p.string(), Params(p.string()));
  RenderOptions o;
  o.lod = FullDetail{};
  o.width = o.height = 16;
  o.spp = spp;
  const RenderOutput out = render(s, o);
  Vec3 sum{};
  for (const Vec3& c : out.image) sum += c;
  return sum * (1.0f / static_cast<float>(out.image.size()));
}

/// A W x H map written as PFM: `top` on the upper half of the sphere, `bottom` below.
std::string write_map(const std::string& name, int w, int h, float top, float bottom,
                      float zenith_row = -1) {
  std::vector<Vec3> px(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float v = y == 0 && zenith_row >= 0 ? zenith_row : (y < h / 2 ? top : bottom);
      px[static_cast<std::size_t>(y) * w + x] = {v, v, v};
    }
  const fs::path p = dir() / name;
  write_image(p.string(), w, h, px);
  return p.string();
}

// Cosine-weighted sampling of a constant sky makes every sample of a Lambertian floor bring
// exactly rho L: no noise at all.
TEST(Sky, ConstantSkyLightsAnOpenFloorWithRhoTimesL) {
  const Vec3 c = mean_colour(
      scene(R"({"type": "sky", "radiance": [2, 2, 2], "samples": 8})", "[0, 5, 0]", "[0, 0, 0]"));
  EXPECT_NEAR(c.x, 0.5f * 2.0f, 1e-5f);
  EXPECT_NEAR(c.z, 0.5f * 2.0f, 1e-5f);
}

TEST(Sky, ARoofShadowsTheSkyCompletely) {
  const Vec3 c = mean_colour(scene(R"({"type": "sky", "radiance": [2, 2, 2], "samples": 8})",
                                   "[0, 1, 0]", "[0, 0, 0]", true));
  EXPECT_EQ(c.x, 0.0f);
}

// A map that is 1 above the horizon and 0 below lights the floor as the constant sky of 1
// does, through importance sampling of the map (noisy: the mean over the image).
TEST(Sky, MapSampledByLuminanceGivesTheSameIrradiance) {
  for (const auto& [top, bottom] : {std::pair{1.0f, 0.0f}, std::pair{1.0f, 1.0f}}) {
    const std::string map = write_map("map.pfm", 32, 16, top, bottom);
    const Vec3 c = mean_colour(scene(R"({"type": "sky", "map": ")" + map + R"(", "samples": 16})",
                                     "[0, 5, 0]", "[0, 0, 0]"),
                               16);
    EXPECT_NEAR(c.x, 0.5f, 0.01f) << "bottom " << bottom;
  }
}

// A camera ray that meets nothing sees the sky: the map's zenith row looking straight up.
TEST(Sky, CameraRaysThatMissSeeTheSky) {
  const std::string map = write_map("zenith.pfm", 8, 8, 1.0f, 0.0f, 3.0f);
  const Vec3 c =
      mean_colour(scene(R"({"type": "sky", "map": ")" + map + R"(", "radiance": [2, 2, 2]})",
                        "[0, 5, 0]", "[0, 10, 0]"));
  EXPECT_FLOAT_EQ(c.x, 6.0f);
}

// The map's density integrates to 1 over the sphere, sample() reports pdf(), and pixels are
// drawn in proportion to luminance x solid angle.
TEST(Sky, MapDensityIsNormalisedAndMatchesItsSamples) {
  const int w = 8, h = 4;
  std::vector<Vec3> px(w * h);
  for (int i = 0; i < w * h; ++i)
    px[static_cast<std::size_t>(i)] = Vec3{1, 1, 1} * float(1 + i % 5);
  const SkyMap m(w, h, px, {1, 1, 1}, 30.0f);
  double integral = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {  // uniform directions (a Fibonacci sphere)
    const double z = 1 - (2.0 * i + 1) / n, r = std::sqrt(1 - z * z);
    const double phi = i * std::numbers::pi * (3 - std::sqrt(5.0));
    integral += m.pdf(Vec3{float(r * std::cos(phi)), float(z), float(r * std::sin(phi))});
  }
  EXPECT_NEAR(integral * 4 * std::numbers::pi / n, 1.0, 0.01);
  for (int i = 0; i < 1000; ++i) {
    const SkyMap::Sample s = m.sample((i * 0.618034f) - std::floor(i * 0.618034f),
                                      (i * 0.414214f) - std::floor(i * 0.414214f));
    if (s.pdf == 0.0f) continue;  // the pole itself (u1 = 0): no density, never used
    EXPECT_NEAR(s.pdf, m.pdf(s.dir), 1e-3f * s.pdf) << i;
    EXPECT_EQ(s.radiance, m.radiance(s.dir)) << i;
  }
  EXPECT_THROW(SkyMap(2, 2, std::vector<Vec3>(4), {1, 1, 1}), InputError);
}

TEST(Spot, FalloffIsGltfs) {
  Light l;
  l.kind = LightKind::kSpot;
  l.direction = {0, -1, 0};
  l.cos_inner = std::cos(0.2f), l.cos_outer = std::cos(0.4f);
  auto toward = [](float a) { return Vec3{-std::sin(a), std::cos(a), 0}; };  // to the light
  EXPECT_EQ(spot_falloff(l, toward(0.1f)), 1.0f);
  EXPECT_EQ(spot_falloff(l, toward(0.5f)), 0.0f);
  const float t = (std::cos(0.3f) - l.cos_outer) / (l.cos_inner - l.cos_outer);
  EXPECT_NEAR(spot_falloff(l, toward(0.3f)), t * t, 1e-6f);
}

// A spot 4 above the floor pointing down: full intensity on its axis, glTF's falloff between
// the cones, nothing outside.
TEST(Spot, LightsTheFloorInsideItsCone) {
  const std::string spot = R"({"type": "spot", "position": [0, 4, 0], "direction": [0, -1, 0],
      "intensity": [16, 16, 16], "inner_deg": 10, "outer_deg": 20})";
  const double pi = std::numbers::pi, rho = 0.5;
  const Vec3 axis = mean_colour(scene(spot, "[0, 10, 0]", "[0, 0, 0]"));
  EXPECT_NEAR(axis.x, rho / pi * 16 / 16, 2e-3);
  const double a = 15 * pi / 180, x = 4 * std::tan(a);
  const double t =
      (std::cos(a) - std::cos(20 * pi / 180)) / (std::cos(10 * pi / 180) - std::cos(20 * pi / 180));
  const double want = rho / pi * 16 / (16 + x * x) * std::cos(a) * t * t;
  const std::string at = "[" + std::to_string(x) + ", 0, 0]";
  const Vec3 mid = mean_colour(scene(spot, "[" + std::to_string(x) + ", 10, 0]", at));
  EXPECT_NEAR(mid.x, want, 0.03 * want);
  const Vec3 out = mean_colour(scene(spot, "[2.5, 10, 0]", "[2.5, 0, 0]"));  // 32 degrees
  EXPECT_EQ(out.x, 0.0f);
}

}  // namespace sky_spot_test
}  // namespace amalgam

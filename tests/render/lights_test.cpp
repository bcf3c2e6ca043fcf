// Sized lights (render/lights.h) and prefiltered shadows (PrefilteredOpacity,
// traverse/opacity.h): the expected images are exact (a uniform sphere lights a plane as a
// point at its centre does; prefiltered shadows have the stochastic ones' expectation), so
// the checks are on means over many samples with tolerances far below the errors a wrong
// weight or pdf would make (a factor 2, a missing cosine: tens of per cent).

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "amalgam/io/scene_json.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/traverse/opacity.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

/// A white-ish floor (y = 0) seen from above, lit by `light` (a JSON object).
LoadedScene floor_scene(const std::string& light, const std::string& extra = "") {
  SceneDescription d = parse_scene_json(
      R"({"camera": {"position": [0, 6, 0.01], "look_at": [0, 0, 0], "vfov": 60},
          "lights": [)" +
          light + R"(],
          "background": [0, 0, 0],
          "materials": {"m": {"colour": [0.8, 0.8, 0.8]}},
          "triangles": [{"vertices": [[-20, 0, -20], [20, 0, -20], [20, 0, 20]], "material": "m"},
                        {"vertices": [[-20, 0, -20], [20, 0, 20], [-20, 0, 20]], "material": "m"})" +
          extra + R"(]})",
      "floor.json");
  Environment env = std::move(d.env);
  return LoadedScene{"floor", build_hierarchy(std::move(d)), std::move(env)};
}

RenderOutput render_traditional(const LoadedScene& s, int spp, std::uint64_t seed = 1) {
  RenderOptions o;
  o.lod = FullDetail{};
  o.width = 24, o.height = 24, o.spp = spp, o.seed = seed, o.threads = 2;
  return render(s, o);
}

double mean(const std::vector<Vec3>& img) {
  double sum = 0;
  for (const Vec3& p : img) sum += p.x + p.y + p.z;
  return sum / (3.0 * static_cast<double>(img.size()));
}

TEST(SizedLights, SphereLightsAPlaneAsAPointAtItsCentreDoes) {
  // A uniform sphere entirely above a surface's horizon gives it the irradiance of a point of
  // the same intensity at its centre: the images agree per pixel in expectation.
  const RenderOutput point = render_traditional(
      floor_scene(R"({"type": "point", "position": [0.5, 4, 0], "intensity": [20, 20, 20]})"), 4);
  const RenderOutput sphere = render_traditional(
      floor_scene(R"({"type": "point", "position": [0.5, 4, 0], "intensity": [20, 20, 20],
                      "radius": 1.5, "samples": 64})"),
      4);
  ASSERT_EQ(point.image.size(), sphere.image.size());
  EXPECT_NEAR(mean(sphere.image) / mean(point.image), 1.0, 0.005);
  double worst = 0;
  for (std::size_t i = 0; i < point.image.size(); ++i)
    worst = std::max(worst, std::fabs(double(sphere.image[i].y) / point.image[i].y - 1.0));
  EXPECT_LT(worst, 0.03);  // 256 samples of the cosine over a 22-degree cone per pixel
}

TEST(SizedLights, SunDiscGivesItsIrradianceFromEveryDirectionOfTheDisc) {
  // E from each direction of a disc of angular diameter 10 degrees about the vertical: the
  // floor receives E times the mean cosine over the disc, (1 + cos 5 deg) / 2.
  const RenderOutput sun = render_traditional(
      floor_scene(R"({"type": "directional", "direction": [0, -1, 0], "intensity": [2, 2, 2]})"),
      2);
  const RenderOutput disc = render_traditional(
      floor_scene(R"({"type": "directional", "direction": [0, -1, 0], "intensity": [2, 2, 2],
                      "angle": 10, "samples": 16})"),
      2);
  const double expected = (1.0 + std::cos(5.0 * 3.14159265358979 / 180.0)) / 2.0;
  EXPECT_NEAR(mean(disc.image) / mean(sun.image), expected, 0.002);
}

TEST(SizedLights, ASizedLightCastsAPenumbraAPointLightDoesNot) {
  // A square floating above the floor: under the point light its shadow is hard (every floor
  // pixel fully lit or fully dark but for the few the shadow's edge crosses), under a sphere
  // light of the same intensity many are partly lit.
  const std::string box = R"(, {"vertices": [[-0.6, 2, -0.6], [0.6, 2, -0.6], [0.6, 2, 0.6]],
                                 "material": "m"},
                                {"vertices": [[-0.6, 2, -0.6], [0.6, 2, 0.6], [-0.6, 2, 0.6]],
                                 "material": "m"})";
  auto partly_lit = [&](const std::string& light) {
    const LoadedScene s = floor_scene(light, box);
    const LoadedScene lit = floor_scene(light);
    const RenderOutput a = render_traditional(s, 16), b = render_traditional(lit, 16);
    int partial = 0, dark = 0;
    for (std::size_t i = 0; i < a.image.size(); ++i) {
      // Only pixels that see nothing but the floor (the same mean depth as without the box).
      if (std::fabs(a.depth[i] - b.depth[i]) > 1e-4f * b.depth[i]) continue;
      const double r = a.image[i].y / b.image[i].y;
      if (r < 0.01) ++dark;
      if (r > 0.05 && r < 0.95) ++partial;
    }
    return std::pair(partial, dark);
  };
  const auto [point_partial, point_dark] =
      partly_lit(R"({"type": "point", "position": [0, 4, 0], "intensity": [20, 20, 20]})");
  const auto [sphere_partial, sphere_dark] = partly_lit(
      R"({"type": "point", "position": [0, 4, 0], "intensity": [20, 20, 20], "radius": 0.8,
          "samples": 32})");
  EXPECT_GT(point_dark, 0);
  EXPECT_GT(point_partial, 0);                   // the edge pixels, partly covered
  EXPECT_GT(sphere_partial, 2 * point_partial);  // measured: 119 against 33
}

TEST(SizedLights, SceneFileErrorsNameTheLight) {
  auto message = [](const std::string& light) {
    try {
      (void)floor_scene(light);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"type": "point", "position": [0, 4, 0], "intensity": [1, 1, 1],
                        "samples": 4})")
                .find("/lights/0/samples"),
            std::string::npos);
  EXPECT_NE(message(R"({"type": "point", "position": [0, 4, 0], "intensity": [1, 1, 1],
                        "radius": -1})")
                .find("/lights/0/radius"),
            std::string::npos);
  EXPECT_NE(message(R"({"type": "directional", "direction": [0, -1, 0], "intensity": [1, 1, 1],
                        "angle": 120})")
                .find("/lights/0/angle"),
            std::string::npos);
}

/// scenes/field.json seen from above: at footprint 16 its Wusons render as amalgams.
LoadedScene field_from_above() {
  Params none("scenes/field.json");
  LoadedScene s = load_scene(AMALGAM_SOURCE_DIR "/scenes/field.json", none);
  CameraChoice aerial;
  aerial.eye = Vec3{0, 120, 160}, aerial.look_at = Vec3{0, 0, 0};
  choose_camera(s, aerial);
  return s;
}

TEST(PrefilteredOpacity, StochasticForCameraRaysBlendedForShadowRays) {
  const PrefilteredOpacity p;
  const StochasticOpacity s;
  for (std::uint64_t key = 0; key < 1000; ++key)
    for (float a : {0.1f, 0.5f, 0.9f})
      ASSERT_EQ(p.effect(a, key, key * 7 + 3, false), s.effect(a, key, key * 7 + 3, false));
  EXPECT_EQ(p.effect(0.3f, 1, 2, true), AmalgamEffect::kBlend);
  EXPECT_EQ(p.effect(1.0f, 1, 2, true), AmalgamEffect::kStop);
  EXPECT_EQ(p.effect(0.0f, 1, 2, true), AmalgamEffect::kPass);
}

TEST(PrefilteredOpacity, HasTheExpectationOfStochasticShadowsWithLessNoise) {
  // The field from above at footprint 16: Wusons render as amalgams for shadow rays. The
  // camera rays' decisions are the same under both models, so the prefiltered image is the
  // stochastic one with each shadow ray's decision replaced by its expectation.
  const LoadedScene s = field_from_above();
  RenderOptions o;
  o.lod = ByFootprint{16.0f}, o.width = 32, o.height = 24, o.threads = 2;
  auto image = [&](OpacityKind k, int spp, std::uint64_t seed) {
    o.opacity = k, o.spp = spp, o.seed = seed;
    return render(s, o).image;
  };
  const auto stochastic = image(OpacityKind::kStochastic, 512, 5);
  const auto prefiltered = image(OpacityKind::kPrefiltered, 512, 5);
  EXPECT_NEAR(mean(prefiltered) / mean(stochastic), 1.0, 0.003);
  // Noise of 1-sample images against the 512-sample prefiltered one.
  auto mse = [&](const std::vector<Vec3>& a) {
    double e = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Vec3 d = a[i] - prefiltered[i];
      e += dot(d, d);
    }
    return e / static_cast<double>(a.size());
  };
  double mse_s = 0, mse_p = 0;
  for (std::uint64_t seed = 100; seed < 108; ++seed) {
    mse_s += mse(image(OpacityKind::kStochastic, 1, seed));
    mse_p += mse(image(OpacityKind::kPrefiltered, 1, seed));
  }
  EXPECT_LT(mse_p, mse_s);
}

TEST(CompositeOpacity, HasTheDeterministicImageWithOneShadowRayPerLightPerSample) {
  // The field from above at footprint 16, one directional light. Composite blends what a
  // camera ray crosses as the deterministic model does (and stops when it is saturated), but
  // traces the shadow rays of one member only: the same expected image, at most one shadow
  // ray per sample (the deterministic model: one per translucent member as well).
  const LoadedScene s = field_from_above();
  ASSERT_EQ(s.env.lights.size(), 1u);
  RenderOptions o;
  o.lod = ByFootprint{16.0f}, o.width = 32, o.height = 24, o.threads = 2, o.seed = 9;
  o.opacity = OpacityKind::kDeterministic, o.spp = 64;
  const RenderOutput det = render(s, o);
  o.opacity = OpacityKind::kComposite, o.spp = 256;
  const RenderOutput comp = render(s, o);
  EXPECT_NEAR(mean(comp.image) / mean(det.image), 1.0, 0.003);
  double se = 0;
  for (std::size_t i = 0; i < det.image.size(); ++i) {
    const Vec3 d = comp.image[i] - det.image[i];
    se += dot(d, d);
  }
  EXPECT_LT(std::sqrt(se / (3.0 * det.image.size())), 0.01);
  EXPECT_LE(comp.counters.rays[1], comp.counters.rays[0]);
  EXPECT_GT(det.counters.rays[1] * 256, comp.counters.rays[1] * 64);  // per sample: more
}

}  // namespace
}  // namespace amalgam

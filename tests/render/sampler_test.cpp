// Stratified pixel sampling (RenderOptions::sampler, math/sobol.h): the points are stratified,
// the images do not depend on the thread count or on interruption, and edges converge faster
// than with independent samples.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <set>

#include "amalgam/analysis/metrics.h"
#include "amalgam/io/scene_json.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/math/sobol.h"
#include "amalgam/render/render.h"

namespace amalgam {
namespace {

TEST(Sobol, EveryPowerOfTwoPrefixIsStratifiedInEveryElementaryInterval) {
  for (std::uint64_t key : {0ull, 1ull, 0x1234567890abcdefull}) {
    for (int m = 0; m <= 8; ++m) {
      const std::uint32_t n = 1u << m;
      for (int a = 0; a <= m; ++a) {  // intervals 2^-a wide, 2^-(m-a) high
        std::set<std::uint32_t> cells;
        for (std::uint32_t i = 0; i < n; ++i) {
          const auto [x, y] = scrambled_sobol_2d(i, key);
          ASSERT_GE(x, 0.0f);
          ASSERT_LT(x, 1.0f);
          ASSERT_GE(y, 0.0f);
          ASSERT_LT(y, 1.0f);
          const auto cx = static_cast<std::uint32_t>(std::ldexp(x, a));
          const auto cy = static_cast<std::uint32_t>(std::ldexp(y, m - a));
          cells.insert((cx << 16) | cy);
        }
        EXPECT_EQ(cells.size(), n) << "key " << key << ", 2^" << m << " points, a = " << a;
      }
    }
  }
}

TEST(Sobol, ScramblesDifferPerKey) {
  // Different pixels must not share their points (that would correlate the error over the
  // image): the first points of two keys differ.
  EXPECT_NE(scrambled_sobol_2d(0, 1), scrambled_sobol_2d(0, 2));
  EXPECT_NE(scrambled_sobol_2d(5, 1), scrambled_sobol_2d(5, 2));
}

LoadedScene prisms() {
  Params p("builtin:prisms");
  p.set("depth", "6");
  p.set("view", "corner");
  return load_scene("builtin:prisms", p);
}

TEST(StratifiedSampler, SameBytesForAnyThreadCountAndWhenResumed) {
  const LoadedScene s = prisms();
  RenderOptions o;
  o.width = 96, o.height = 64, o.spp = 12, o.seed = 3, o.sampler = PixelSampler::kStratified;
  o.threads = 1;
  const RenderOutput one = render(s, o);
  o.threads = 2;
  const RenderOutput two = render(s, o);
  ASSERT_EQ(one.image.size(), two.image.size());
  for (std::size_t i = 0; i < one.image.size(); ++i) ASSERT_EQ(one.image[i], two.image[i]) << i;
  EXPECT_EQ(one.counters.total(), two.counters.total());

  // Interrupted after its first pass (10 samples per pass at this size), then resumed.
  std::atomic<bool> cancel{false};
  RenderControl control;
  control.cancel = &cancel;
  control.on_pass = [&](const FilmState&) { cancel = true; };
  FilmState state;
  const RenderOutput part = render(s, o, &state, control);
  ASSERT_TRUE(part.interrupted);
  ASSERT_LT(state.spp_done, o.spp);
  const RenderOutput resumed = render(s, o, &state);
  for (std::size_t i = 0; i < one.image.size(); ++i) ASSERT_EQ(resumed.image[i], one.image[i]) << i;

  // The sampler changes the image (and only where the pixel position matters).
  o.sampler = PixelSampler::kIndependent;
  const RenderOutput indep = render(s, o);
  EXPECT_GT(rmse(indep.image, one.image), 0.0);
}

/// A white-lit triangle against a dark background: all the error is in its edge pixels.
LoadedScene edge_scene() {
  SceneDescription d = parse_scene_json(
      R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vfov": 30},
          "lights": [{"type": "directional", "direction": [0, 0, -1], "intensity": [1, 1, 1]}],
          "background": [0.05, 0.05, 0.05],
          "materials": {"m": {"colour": [0.9, 0.8, 0.7]}},
          "triangles": [{"vertices": [[-0.9, -0.7, 0], [0.8, -0.9, 0], [0.1, 0.85, 0]],
                         "material": "m"}]})",
      "edge.json");
  Environment env = std::move(d.env);
  return LoadedScene{"edge", build_hierarchy(std::move(d)), std::move(env)};
}

TEST(StratifiedSampler, ConvergesFasterThanIndependentOnEdges) {
  const LoadedScene s = edge_scene();
  RenderOptions o;
  o.width = 48, o.height = 48, o.lod = FullDetail{};
  o.spp = 4096, o.seed = 777;  // reference: independent, its own seed
  const RenderOutput ref = render(s, o);
  for (int spp : {4, 16, 64}) {
    double err[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      o.sampler = k ? PixelSampler::kStratified : PixelSampler::kIndependent;
      o.spp = spp;
      for (std::uint64_t seed = 1; seed <= 4; ++seed) {
        o.seed = seed;
        const double e = rmse(render(s, o).image, ref.image);
        err[k] += e * e / 4.0;
      }
    }
    const double independent = std::sqrt(err[0]), stratified = std::sqrt(err[1]);
    // Independent: RMSE ~ 1/sqrt(spp); stratified edges ~ spp^-3/4: the gap grows with spp.
    EXPECT_LT(stratified, (spp >= 16 ? 0.55 : 0.7) * independent)
        << spp << " spp: stratified " << stratified << ", independent " << independent;
  }
}

}  // namespace
}  // namespace amalgam

// The volumetric renderer (render/volume_integrator.h, docs/volumetric.md): its mean against a
// stored converged reference, tile by tile; that the correlation fit gives a small object its
// coverage; its exact counts; its level choice; full detail close up; and its determinism.
//
// Scene: tests/data/bias-meadow.json (250,000 instanced tufts of grass, blades 1-2 cm wide,
// pixels of 2-20 cm at 128 x 96), loaded as objects; reference tests/data/bias-meadow-ref.pfm
// (full detail, 1024 spp; its own noise: 0.23 % per 32 x 32 tile, bias_reference_test.cpp).
// Measured when written (4 spp, stratified, seed 1, 2 threads): tiles -1.98 to +1.30 %, frame
// -0.45 %.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "amalgam/io/image.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/traverse/cone_march.h"
#include "bias_meadow.h"

namespace amalgam {
namespace {

LoadedScene load_objects(const std::string& path, bool correlated = true) {
  SceneFileConfig c;
  c.objects = true;
  c.volume.correlated = correlated;
  return load_scene_path(path, c);
}

RenderOptions volumetric(int width, int height, int spp) {
  RenderOptions o;
  o.lod = VolumetricCells{};
  o.sampler = PixelSampler::kStratified;
  o.width = width, o.height = height, o.spp = spp, o.threads = 2, o.seed = 1;
  return o;
}

/// The relative error of each 32 x 32 tile's mean luminance (the top row only under a
/// sanitizer, rendered tile by tile: render_tile gives them the bytes of the whole frame), and
/// of the frame (last; the checked tiles together).
std::vector<double> tile_errors(const LoadedScene& scene, const char* what) {
  int w = 0, h = 0;
  const std::vector<Vec3> ref = read_image(kReference, w, h);
  EXPECT_EQ(w, kWidth);
  EXPECT_EQ(h, kHeight);
  const RenderOptions o = volumetric(kWidth, kHeight, 4);
  check_options(scene, o);
  std::vector<double> err;
  double sum = 0, ref_sum = 0;
  for (int y = 0; y < (kSanitized ? kTile : kHeight); y += kTile)
    for (int x = 0; x < kWidth; x += kTile) {
      const TileRect r{x, y, x + kTile, y + kTile};
      FilmTile t{r,
                 std::vector<Vec3>(r.pixels()),
                 std::vector<std::uint64_t>(r.pixels()),
                 std::vector<PixelAov>(r.pixels()),
                 {},
                 {}};
      EXPECT_TRUE(render_tile(scene, o, t, 0, o.spp));
      double mine = 0, theirs = 0;
      for (int j = 0; j < kTile; ++j)
        for (int i = 0; i < kTile; ++i) {
          mine += luminance(t.sum[static_cast<std::size_t>(j) * kTile + i]) / o.spp;
          theirs += luminance(ref[static_cast<std::size_t>(y + j) * w + x + i]);
        }
      EXPECT_GT(t.counters.tests_of(ObjectKind::kCell), 0u);
      err.push_back(mine / theirs - 1.0);
      sum += mine, ref_sum += theirs;
    }
  err.push_back(sum / ref_sum - 1.0);
  std::printf("%s: tile luminance vs reference\n", what);
  for (std::size_t i = 0; i + 1 < err.size(); ++i)
    std::printf("%+6.2f %%%s", 100 * err[i], (i + 1) % (kWidth / kTile) == 0 ? "\n" : "  ");
  std::printf("frame %+.2f %%\n", 100 * err.back());
  return err;
}

TEST(Volumetric, MeadowTilesWithin3PercentOfFullDetail) {
  const LoadedScene scene = load_objects(kScene);
  ASSERT_TRUE(scene.volumes);
  const std::vector<double> err = tile_errors(scene, "volumetric");
  for (std::size_t i = 0; i + 1 < err.size(); ++i)
    EXPECT_LE(std::fabs(err[i]), 0.03) << "tile " << i << ": " << 100 * err[i] << " %";
  EXPECT_LE(std::fabs(err.back()), 0.01) << "frame: " << 100 * err.back() << " %";
}

/// The pixels the tuft of tests/data/tuft-coverage.json covers (black tuft, white background,
/// no lights: 1 minus the luminance, summed), over the 16 x 16 pixels of the 32 x 24 frame
/// around it (it lies in rows 9-13, columns 14-17), rendered tile-wise (render_tile gives
/// them the bytes of the whole frame).
double tuft_coverage(RendererKind kind, bool correlated, int spp) {
  const LoadedScene scene =
      load_objects(std::string(AMALGAM_SOURCE_DIR) + "/tests/data/tuft-coverage.json", correlated);
  RenderOptions o = volumetric(32, 24, spp);
  if (kind == RendererKind::kTraditional) o.lod = FullDetail{};
  check_options(scene, o);
  const TileRect r{8, 4, 24, 20};
  FilmTile t{r,
             std::vector<Vec3>(r.pixels()),
             std::vector<std::uint64_t>(r.pixels()),
             std::vector<PixelAov>(r.pixels()),
             {},
             {}};
  EXPECT_TRUE(render_tile(scene, o, t, 0, o.spp));
  double covered = 0;
  for (const Vec3& p : t.sum) covered += 1.0 - luminance(p) / o.spp;
  if (kind == RendererKind::kVolumetric) {
    EXPECT_GT(t.counters.tests_of(ObjectKind::kCell), 0u);
  }
  return covered;
}

// The correlation fit (cells.h: each cell's coverage measured on the mesh's first hits) is what
// gives a small object its silhouette: without it (VolumeConfig::correlated = false, each cell
// an independent exponential medium of its own surfaces) the blades behind one another count
// as if they filled each other's gaps. Measured when written (1024 spp): -2.2 % with the fit,
// +50.7 % without.
TEST(Volumetric, CorrelationFitGivesTheCoverage) {
  // The tuft covers about one pixel: fewer samples would test the noise (16 spp: -20 %).
  const int spp = 256;
  const double full = tuft_coverage(RendererKind::kTraditional, true, spp);
  const double fit = tuft_coverage(RendererKind::kVolumetric, true, spp);
  const double independent = tuft_coverage(RendererKind::kVolumetric, false, spp);
  std::printf("tuft coverage: full detail %.3f pixels, cells %+.2f %%, without the fit %+.2f %%\n",
              full, 100 * (fit / full - 1), 100 * (independent / full - 1));
  EXPECT_NEAR(fit / full, 1.0, 0.05);
  EXPECT_GT(independent / full, 1.25);
}

// Counts add up as the stats JSON promises, cells included, and the cost image adds up to them.
TEST(Volumetric, CellTestsAddUp) {
  const LoadedScene scene =
      load_objects(std::string(AMALGAM_SOURCE_DIR) + "/scenes/volumetric/tree.json");
  RenderOptions o = volumetric(48, 36, 2);
  const RenderOutput out = render(scene, o);
  const Counters& c = out.counters;
  EXPECT_GT(c.tests_of(ObjectKind::kCell), 0u);
  EXPECT_EQ(c.total(), c.tests_of(ObjectKind::kPrimitive) +
                           c.tests_of(ObjectKind::kBoundingVolume) +
                           c.tests_of(ObjectKind::kAmalgam) + c.tests_of(ObjectKind::kCell));
  std::uint64_t by_level = 0, per_pixel = 0;
  for (std::uint64_t n : c.by_level) by_level += n;
  for (std::uint64_t n : out.tests) per_pixel += n;
  EXPECT_EQ(by_level, c.total());
  EXPECT_EQ(per_pixel, c.total());
  EXPECT_EQ(c.rays[0], 48u * 36u * 2u);
}

// The level between the two nearest is drawn with probability by the fraction: over many rays
// the share of the finer level is the fraction (so the mean image is the exact mix of the two).
TEST(Volumetric, LevelChoiceIsUnbiased) {
  CellGrid g;
  g.size = {1, 1, 1};
  g.levels = 8;
  for (const float frac : {0.1f, 0.37f, 0.5f, 0.9f}) {
    const float width = 1.0f / std::exp2(3.0f + frac);  // log2(longest / width) = 3 + frac
    int finer = 0;
    const int n = 200000;
    for (int k = 0; k < n; ++k) {
      const int l = choose_cell_level(g, width, 1.0f, level_choice_u(hash_combine(7, k), 3));
      ASSERT_TRUE(l == 3 || l == 4) << l;
      finer += l == 4;
    }
    EXPECT_NEAR(static_cast<double>(finer) / n, frac, 0.004) << "fraction " << frac;
  }
  // Wider than the whole box: level 0; finer than the finest cells: full detail (levels).
  EXPECT_EQ(choose_cell_level(g, 2.0f, 1.0f, 0.5f), 0);
  EXPECT_EQ(choose_cell_level(g, 1e-6f, 1.0f, 0.5f), g.levels);
  EXPECT_EQ(choose_cell_level(g, 0.0f, 1.0f, 0.5f), g.levels);
}

// Close enough that every cone is finer than the finest cells: the objects are traced at full
// detail, and the image is the traditional renderer's (to float rounding of the estimator).
TEST(Volumetric, CloseUpIsFullDetail) {
  LoadedScene scene =
      load_objects(std::string(AMALGAM_SOURCE_DIR) + "/scenes/volumetric/tuft.json");
  scene.env.camera.position = {0.0f, 0.45f, 0.5f};
  scene.env.camera.look_at = {0.0f, 0.2f, 0.0f};
  RenderOptions o = volumetric(128, 96, 1);
  const RenderOutput v = render(scene, o);
  o.lod = FullDetail{};
  const RenderOutput t = render(scene, o);
  ASSERT_EQ(v.image.size(), t.image.size());
  double worst = 0;
  for (std::size_t i = 0; i < v.image.size(); ++i)
    worst = std::max(worst, static_cast<double>(max_component(abs(v.image[i] - t.image[i]))));
  EXPECT_LT(worst, 1e-5);
  EXPECT_EQ(v.counters.tests_of(ObjectKind::kCell), 0u);
}

// One object (its own cells) and a crowd of instances smaller than a pixel (world cells).
TEST(Volumetric, SameBytesForAnyThreadCount) {
  for (const char* path : {"/scenes/volumetric/tree.json", "/tests/data/crowd.json"}) {
    SCOPED_TRACE(path);
    const LoadedScene scene = load_objects(std::string(AMALGAM_SOURCE_DIR) + path);
    RenderOptions o = volumetric(40, 30, 3);
    o.threads = 1;
    const RenderOutput one = render(scene, o);
    o.threads = 2;
    const RenderOutput two = render(scene, o);
    EXPECT_EQ(one.image, two.image);
    EXPECT_EQ(one.tests, two.tests);
    EXPECT_EQ(one.counters.total(), two.counters.total());
    EXPECT_GT(one.counters.tests_of(ObjectKind::kCell), 0u);
  }
}

}  // namespace
}  // namespace amalgam

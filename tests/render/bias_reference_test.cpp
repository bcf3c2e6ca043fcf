// The per-tile bias of rendered amalgams against a stored, converged full-detail reference
// (issue 13: "every 32 x 32 tile's mean luminance within 3 %"), on a small fine-detail scene.
//
// Scene: tests/data/bias-meadow.json, scenes/meadow.json's 250,000 instanced tufts of grass
// (subdivided once) seen from standing height, tilted down so that the frame is all grass:
// blades 1-2 cm wide, pixels of 2 cm (bottom row, 4 m away) to 20 cm (top row, 47 m) at
// 128 x 96. Reference: tests/data/bias-meadow-ref.pfm, written by
// scripts/make_bias_reference.sh with (one command line)
//
//   build/amalgam render tests/data/bias-meadow.json --renderer traditional
//       --sampler stratified --spp 1024 --seed 1 --width 128 --height 96 --quiet
//       --out tests/data/bias-meadow-ref.pfm
//
// Its own noise, from a second such render with --seed 2: per-pixel standard error 0.0022 (root
// mean square over pixels and channels; 1.6 % of the mean pixel luminance, 0.138); the 32 x 32
// tile means of the two renders differ by at most 0.23 %, the frame means by 0.02 %.
// Rerun the script, and check the figures in this comment, whenever the scene or the shading
// at full detail changes on purpose.
//
// What is guarded: `--opacity composite --footprint 2` (the best mode of the meadow yardstick,
// docs/yardstick.md, "The meadow") at 8 spp, stratified, seed 0, on this street view: every 32 x 32
// tile, and the whole frame, within 3 % of the reference. Amalgams end 39-40 % of the samples
// of the top row of tiles (the grass 9-47 m away), 2 % of the middle row and none of the
// bottom row, so a bias of rendered amalgams shows in the top row; the test asserts that share
// too. Measured with the default hierarchy (8 children, leaves of 4): top row -2.0 to -2.8 %,
// middle row up to +1.4 %, frame -0.6 %. With the earlier default (4 children, leaves of 4),
// when the test was written: top row -0.6 to -1.4 %, worst tile +1.5 %, frame -0.2 %; with 8
// children and leaves of 8 the top row reaches -3.5 % and fails (docs/real-scenes.md). Made to
// fail by hand (4 children): amalgams shaded 5 % darker (integrator.h, shade()) put the top row
// at -2.9 to -3.8 %; a tolerance of 1 % fails on three tiles. Not caught: amalgam opacities
// 10 % too low (the top row moves by +1 %, saturated blends are renormalised). The second test
// renders K = 8 (4 spp), which the check must find biased (measured: 7 of 12 tiles over 3 %,
// worst -8.1 %).
//
// Not guarded, because composite does not meet 3 % there today (measured while choosing the
// view, with 4 children per node, 8-16 spp against 64-spp traditional references): views from
// higher up, where most of the frame is amalgams. This scene from 8 m up, 20 degrees down, 128 x
// 96: K = 1 worst tile -4.8 %, K = 2 +8.8 % (top row) and -7.0 % (bottom row); at 64 x 48 (16 x 16
// tiles), K = 2 +8.7 to +15.2 % in every tile. A patch of 16,000 tufts seen from 45 degrees, 64 x
// 48: K = 2 +9 to +21 %, K = 1 down to -7.9 %.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "amalgam/io/image.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "bias_meadow.h"

namespace amalgam {
namespace {

constexpr double kTolerance = 0.03;  // issue 13's bias target, per tile and for the frame

/// The 32 x 32 tiles checked: all 12, or under a sanitizer the top row.
std::vector<TileRect> checked_tiles() {
  std::vector<TileRect> out;
  for (int y = 0; y < (kSanitized ? kTile : kHeight); y += kTile)
    for (int x = 0; x < kWidth; x += kTile) out.push_back({x, y, x + kTile, y + kTile});
  return out;
}

struct TileStats {
  double luminance = 0;  ///< mean over the tile's pixels
  /// Share of the samples whose camera ray did not end at a primitive. The ground covers the
  /// frame (no sample misses at full detail), so these ended at a rendered amalgam or in a
  /// saturated blend of translucent ones.
  double amalgams = 0;
};

struct Measured {
  std::vector<TileStats> tiles;
  Counters counters;
};

/// Renders the checked tiles with composite opacity at footprint K, `spp` samples per pixel.
Measured render_composite(const LoadedScene& scene, float footprint, int spp) {
  RenderOptions o;
  o.opacity = OpacityKind::kComposite;
  o.lod = ByFootprint{footprint};
  o.sampler = PixelSampler::kStratified;
  o.width = kWidth, o.height = kHeight, o.spp = spp, o.threads = 2;
  check_options(scene, o);
  Measured m;
  for (const TileRect& r : checked_tiles()) {
    FilmTile t{r,
               std::vector<Vec3>(r.pixels()),
               std::vector<std::uint64_t>(r.pixels()),
               std::vector<PixelAov>(r.pixels()),
               {},
               {}};
    EXPECT_TRUE(render_tile(scene, o, t, 0, spp));
    TileStats s;
    for (std::size_t i = 0; i < r.pixels(); ++i) {
      s.luminance += luminance(t.sum[i]) / spp;
      s.amalgams += spp - t.aov[i].primitives;
    }
    s.luminance /= static_cast<double>(r.pixels());
    s.amalgams /= static_cast<double>(r.pixels()) * spp;
    m.tiles.push_back(s);
    m.counters.merge(t.counters);
  }
  return m;
}

/// The reference's mean luminance over each checked tile.
std::vector<double> reference_tiles() {
  int w = 0, h = 0;
  const std::vector<Vec3> ref = read_image(kReference, w, h);
  EXPECT_EQ(w, kWidth);
  EXPECT_EQ(h, kHeight);
  std::vector<double> out;
  if (w != kWidth || h != kHeight) return out;
  for (const TileRect& r : checked_tiles()) {
    double sum = 0;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) sum += luminance(ref[static_cast<std::size_t>(y) * w + x]);
    out.push_back(sum / static_cast<double>(r.pixels()));
  }
  return out;
}

/// Relative luminance error of each tile, and of all checked tiles together (last).
std::vector<double> relative_errors(const Measured& m, const std::vector<double>& ref) {
  std::vector<double> out;
  double sum = 0, ref_sum = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    out.push_back(m.tiles[i].luminance / ref[i] - 1.0);
    sum += m.tiles[i].luminance, ref_sum += ref[i];
  }
  out.push_back(sum / ref_sum - 1.0);
  return out;
}

/// Prints the errors as a grid of tiles (rows of the image), then the amalgam shares and the
/// frame: every run shows the figures this file's comments quote.
void print_errors(const char* what, const Measured& m, const std::vector<double>& err) {
  std::printf("%s: tile luminance vs reference (amalgams' share of the samples)\n", what);
  const std::size_t row = kWidth / kTile;
  for (std::size_t i = 0; i + 1 < err.size(); ++i)
    std::printf("%+6.2f %% (%3.0f %%)%s", 100 * err[i], 100 * m.tiles[i].amalgams,
                (i + 1) % row == 0 ? "\n" : "   ");
  std::printf("frame %+.2f %%\n", 100 * err.back());
}

/// The scene, loaded once for both tests (building and baking it takes half a second).
class BiasReference : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { scene_ = new LoadedScene(load_scene_path(kScene)); }
  static void TearDownTestSuite() { delete scene_, scene_ = nullptr; }
  static const LoadedScene* scene_;
};
const LoadedScene* BiasReference::scene_ = nullptr;

TEST_F(BiasReference, CompositeFootprint2IsWithin3PercentOfFullDetailPerTile) {
  const std::vector<double> ref = reference_tiles();
  ASSERT_EQ(ref.size(), checked_tiles().size());
  const Measured m = render_composite(*scene_, 2.0f, 8);
  const std::vector<double> err = relative_errors(m, ref);
  print_errors("composite K = 2", m, err);
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const TileRect r = checked_tiles()[i];
    EXPECT_LE(std::fabs(err[i]), kTolerance)
        << "tile at (" << r.x0 << ", " << r.y0 << "): " << 100 * err[i] << " %, amalgams in "
        << 100 * m.tiles[i].amalgams << " % of its samples";
  }
  EXPECT_LE(std::fabs(err.back()), kTolerance) << "frame: " << 100 * err.back() << " %";
  // Meaningful only if amalgams made much of the image: rendered-amalgam tests in the counters,
  // and the top row of tiles (measured: 39-40 % of its samples end at amalgams).
  EXPECT_GT(m.counters.tests_of(ObjectKind::kAmalgam), 0u);
  for (std::size_t i = 0; i < static_cast<std::size_t>(kWidth / kTile); ++i)
    EXPECT_GT(m.tiles[i].amalgams, 0.3) << "tile " << i << " of the top row";
}

TEST_F(BiasReference, TheCheckSeesTheBiasOfACoarseFootprint) {
  // The power of the check: K = 8 (amalgams four times as large, 67-100 % of the samples; 4
  // spp, its bias is large) is measured -5.9 to -8.1 % off in the top row, -3.1 to +0.2 % in the
  // middle, -4.7 to -0.7 % at the bottom: 7 of the 12 tiles over 3 %, frame -3.5 % (with 4
  // children per node: 10 of 12 tiles over 3 % while the frame was only +0.2 % off, which is why
  // the tiles are checked one by one). Should a change make K = 8 unbiased too, replace it here
  // by a variant that still is: this test is about the tolerance, not about K = 8.
  if (kSanitized) GTEST_SKIP() << "a second render; the release suite runs it";
  const std::vector<double> ref = reference_tiles();
  ASSERT_EQ(ref.size(), checked_tiles().size());
  const Measured m = render_composite(*scene_, 8.0f, 4);
  const std::vector<double> err = relative_errors(m, ref);
  print_errors("composite K = 8", m, err);
  std::size_t over = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) over += std::fabs(err[i]) > kTolerance ? 1 : 0;
  EXPECT_GE(2 * over, ref.size()) << over << " of " << ref.size() << " tiles over 3 %";
}

}  // namespace
}  // namespace amalgam

// World cells (hierarchy/volume/world_cells.h): instances smaller than the cone read as one
// medium per cell. Their sums add up on every level, their bake is the same for any thread
// count, and on a crowd of instances smaller than a pixel (tests/data/crowd.json: 40,000
// tufts of 15 cm seen from 43 m, about 30 cm per pixel at 64 x 48) the volumetric renderer
// keeps the mean of a stored converged full-detail reference (tests/data/crowd-ref.pfm,
// 1024 spp, scripts/make_bias_reference.sh) tile by tile, with a cost per camera ray that
// does not grow with ten times more tufts in the same disc.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../sanitized.h"
#include "amalgam/io/image.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

namespace amalgam {
namespace {

const std::string kCrowd = std::string(AMALGAM_SOURCE_DIR) + "/tests/data/crowd.json";
const std::string kCrowdRef = std::string(AMALGAM_SOURCE_DIR) + "/tests/data/crowd-ref.pfm";
constexpr int kW = 64, kH = 48, kTile = 16;

LoadedScene load_crowd(const std::string& path = kCrowd, bool world = true) {
  SceneFileConfig c;
  c.objects = true;
  c.volume.world = world;
  return load_scene_path(path, c);
}

RenderOptions volumetric(int spp) {
  RenderOptions o;
  o.lod = VolumetricCells{};
  o.sampler = PixelSampler::kStratified;
  o.width = kW, o.height = kH, o.spp = spp, o.threads = 2, o.seed = 1;
  return o;
}

/// tests/data/crowd.json with `count` tufts in the same disc, written beside the test binary.
std::string crowd_with(int count) {
  std::ifstream in(kCrowd);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "\"count\": 40000";
  text.replace(text.find(from), from.size(), "\"count\": " + std::to_string(count));
  const std::string mesh = "../../scenes/grass-tuft.obj";
  text.replace(text.find(mesh), mesh.size(),
               std::string(AMALGAM_SOURCE_DIR) + "/scenes/grass-tuft.obj");
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("amalgam_crowd_" + std::to_string(count) + ".json"))
                               .string();
  std::ofstream(path) << text;
  return path;
}

// Every absorbed instance adds its surface once to its cell on its absorb level and once to an
// ancestor on every coarser level; the top tree's absorb levels are the minimum over their
// instances.
TEST(WorldCells, InstancesAddUpOnEveryLevel) {
  const LoadedScene scene = load_crowd();
  const auto& h = std::get<InstancedHierarchy>(scene.hierarchy);
  const VolumeSet& v = *scene.volumes;
  const WorldCells& w = v.world;
  ASSERT_GT(w.levels, 1);
  std::vector<double> expected(static_cast<std::size_t>(w.levels), 0.0);
  int smallest = 127, tufts = 0;
  for (std::size_t i = 0; i < h.instances.size(); ++i) {
    const int a = w.absorb[i];
    smallest = std::min(smallest, a);
    if (a < 0) continue;
    ++tufts;
    ASSERT_LT(a, w.levels);
    const CellGrid& g = v.grids[h.instances[i].mesh];
    const double area = static_cast<double>(g.surface[g.at(0, 0, 0, 0) - 1].area) *
                        v.instance_scale[i] * v.instance_scale[i];
    for (int l = 0; l <= a; ++l) expected[static_cast<std::size_t>(l)] += area;
  }
  EXPECT_EQ(w.top_absorb[0], smallest);
  EXPECT_EQ(smallest, -1);  // the ground box: no cells
  EXPECT_EQ(tufts, 40000);
  for (int l = 0; l < w.levels; ++l) {
    const std::array<int, 3>& n = w.counts[static_cast<std::size_t>(l)];
    double sum = 0;
    const std::size_t entries = static_cast<std::size_t>(n[0]) * n[1] * n[2];
    for (std::size_t e = 0; e < entries; ++e)
      if (const std::uint32_t c = w.index[w.index_offset[static_cast<std::size_t>(l)] + e])
        sum += w.surface[c - 1].area;
    EXPECT_NEAR(sum / expected[static_cast<std::size_t>(l)], 1.0, 1e-5) << "level " << l;
  }
}

TEST(WorldCells, SameCellsForAnyThreadCount) {
  const LoadedScene two = load_crowd();
  LoadedScene one;
  {
    tbb::global_control only(tbb::global_control::max_allowed_parallelism, 1);
    one = load_crowd();
  }
  const WorldCells& a = one.volumes->world;
  const WorldCells& b = two.volumes->world;
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.sigma, b.sigma);
  EXPECT_EQ(a.normals, b.normals);
  ASSERT_EQ(a.surface.size(), b.surface.size());
  for (std::size_t c = 0; c < a.surface.size(); ++c) {
    EXPECT_EQ(a.surface[c].area, b.surface[c].area);
    EXPECT_EQ(a.surface[c].albedo, b.surface[c].albedo);
  }
}

/// Each 16 x 16 tile's mean luminance over the reference's, minus 1; the frame's last.
std::vector<double> crowd_errors(const LoadedScene& scene, int spp) {
  int w = 0, h = 0;
  const std::vector<Vec3> ref = read_image(kCrowdRef, w, h);
  EXPECT_EQ(w, kW);
  EXPECT_EQ(h, kH);
  const RenderOutput out = render(scene, volumetric(spp));
  std::vector<double> err;
  double sum = 0, ref_sum = 0;
  for (int y = 0; y < kH; y += kTile)
    for (int x = 0; x < kW; x += kTile) {
      double mine = 0, theirs = 0;
      for (int j = y; j < y + kTile; ++j)
        for (int i = x; i < x + kTile; ++i) {
          mine += luminance(out.image[static_cast<std::size_t>(j) * kW + i]);
          theirs += luminance(ref[static_cast<std::size_t>(j) * kW + i]);
        }
      err.push_back(mine / theirs - 1.0);
      sum += mine, ref_sum += theirs;
      std::printf("%+6.2f %%%s", 100 * err.back(), x + kTile == kW ? "\n" : "  ");
    }
  err.push_back(sum / ref_sum - 1.0);
  std::printf("frame %+.2f %%\n", 100 * err.back());
  return err;
}

// Measured when written (16 spp, stratified, seed 1): the two tiles of grass +3.7 and +4.4 %
// (seeds 2 and 3: up to +5.4 %; the grass alone, black soil, +6 to +8 %, the soil alone seen
// through it -6 %: one hot-spot width for both, docs/volumetric.md), frame +0.2 %. Without world
// cells, every tuft marched through its own cells, those tiles are +30 %.
TEST(WorldCells, CrowdKeepsTheMeanOfFullDetail) {
  if (kSanitized) GTEST_SKIP() << "about a minute under the sanitizer; the bake is tested above";
  const LoadedScene scene = load_crowd();
  std::printf("world cells:\n");
  const std::vector<double> err = crowd_errors(scene, 16);
  for (std::size_t i = 0; i + 1 < err.size(); ++i)
    EXPECT_LE(std::fabs(err[i]), 0.06) << "tile " << i << ": " << 100 * err[i] << " %";
  EXPECT_LE(std::fabs(err.back()), 0.01) << "frame: " << 100 * err.back() << " %";
  std::printf("each tuft its own cells:\n");
  const std::vector<double> own = crowd_errors(load_crowd(kCrowd, false), 16);
  double worst = 0;
  for (std::size_t i = 0; i + 1 < own.size(); ++i) worst = std::max(worst, std::fabs(own[i]));
  EXPECT_GT(worst, 0.06);
}

// Ten times the tufts in the same disc: full detail's camera rays make several times more
// tests; with world cells the cost per camera ray stays within 1.2x (a denser crowd saturates
// sooner) and below a fifth of full detail's.
TEST(WorldCells, CostPerRayIsFlatAsTheCrowdGrows) {
  if (kSanitized) GTEST_SKIP() << "400,000 instances: minutes under the sanitizer";
  double vol[2], full[2];
  const int counts[2] = {40000, 400000};
  for (int k = 0; k < 2; ++k) {
    const std::string path = k == 0 ? kCrowd : crowd_with(counts[k]);
    const LoadedScene scene = load_crowd(path);
    if (k > 0) std::filesystem::remove(path);
    RenderOptions o = volumetric(1);
    const RenderOutput v = render(scene, o);
    o.lod = FullDetail{};
    const RenderOutput f = render(scene, o);
    // As the stats' per_primary_ray: every test a camera sample causes, shadows included.
    vol[k] = static_cast<double>(v.counters.total()) / static_cast<double>(v.counters.rays[0]);
    full[k] = static_cast<double>(f.counters.total()) / static_cast<double>(f.counters.rays[0]);
    std::printf("%d tufts: tests per camera ray: volumetric %.1f, full detail %.1f\n", counts[k],
                vol[k], full[k]);
  }
  EXPECT_LE(vol[1] / vol[0], 1.2);
  EXPECT_GT(full[1] / full[0], 2.0);
  for (int k = 0; k < 2; ++k) EXPECT_LE(vol[k], full[k] / 5);
}

}  // namespace
}  // namespace amalgam

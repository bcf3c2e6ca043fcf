// The auxiliary outputs of a render (depth, normal, albedo, rendered level; docs/outputs.md):
// what they hold, the same for any thread count, and equal after an interrupted and resumed
// render (through a checkpoint file).

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "amalgam/io/checkpoint.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

namespace amalgam {
namespace {

LoadedScene prisms(const char* view) {
  Params p("builtin:prisms");
  p.set("depth", "5");
  p.set("view", view);
  return load_scene("builtin:prisms", p);
}

/// Bitwise equality of every auxiliary output (NaN-free: +inf compares equal to itself).
void expect_same_aovs(const RenderOutput& a, const RenderOutput& b, const char* what) {
  ASSERT_EQ(a.depth.size(), b.depth.size()) << what;
  for (std::size_t i = 0; i < a.depth.size(); ++i) {
    ASSERT_EQ(a.depth[i], b.depth[i]) << what << ", depth of pixel " << i;
    ASSERT_EQ(a.level[i], b.level[i]) << what << ", level of pixel " << i;
    ASSERT_EQ(a.normal[i], b.normal[i]) << what << ", normal of pixel " << i;
    ASSERT_EQ(a.albedo[i], b.albedo[i]) << what << ", albedo of pixel " << i;
    ASSERT_EQ(a.tests[i], b.tests[i]) << what << ", tests of pixel " << i;
  }
}

TEST(Aov, SameForOneAndTwoThreads) {
  const LoadedScene s = prisms("corner");
  for (const OpacityKind op : {OpacityKind::kStochastic, OpacityKind::kDeterministic}) {
    RenderOptions o;
    o.width = 48, o.height = 40, o.spp = 3, o.seed = 11, o.opacity = op;
    o.threads = 1;
    const RenderOutput one = render(s, o);
    o.threads = 2;
    const RenderOutput two = render(s, o);
    expect_same_aovs(one, two, op == OpacityKind::kStochastic ? "stochastic" : "deterministic");
  }
}

TEST(Aov, ResumedEqualsUninterrupted) {
  const LoadedScene s = prisms("corner");
  RenderOptions o;
  o.width = 256, o.height = 256, o.spp = 3, o.seed = 5;  // 1 sample per pass at this size
  const RenderOutput full = render(s, o);
  std::atomic<bool> cancel{false};
  RenderControl control;
  control.cancel = &cancel;
  control.on_pass = [&](const FilmState&) { cancel = true; };
  FilmState state;
  ASSERT_TRUE(render(s, o, &state, control).interrupted);
  ASSERT_EQ(state.spp_done, 1);
  const std::string path =
      (std::filesystem::temp_directory_path() / ("amalgam-aov-" + std::to_string(getpid())))
          .string();
  write_checkpoint(path, "fp", state);
  FilmState loaded = read_checkpoint(path, "fp");
  std::filesystem::remove(path);
  const RenderOutput resumed = render(s, o, &loaded);
  ASSERT_EQ(resumed.spp, 3);
  expect_same_aovs(full, resumed, "resumed");
}

TEST(Aov, BackgroundPrimitivesAndRenderedLevels) {
  const LoadedScene s = prisms("corner");
  RenderOptions o;
  o.width = 64, o.height = 64, o.spp = 2;
  o.lod = FullDetail{};
  const RenderOutput trad = render(s, o);
  int background = 0, hit = 0;
  for (std::size_t i = 0; i < trad.level.size(); ++i) {
    ASSERT_TRUE(trad.level[i] == kLevelPrimitive || trad.level[i] == kLevelNothing)
        << "the traditional renderer renders no amalgam, pixel " << i;
    if (trad.level[i] == kLevelNothing && trad.depth[i] == kInfinity) {
      ++background;
      EXPECT_EQ(trad.normal[i], Vec3{}) << "pixel " << i;
      EXPECT_EQ(trad.albedo[i], Vec3{}) << "pixel " << i;
    }
    if (trad.level[i] == kLevelPrimitive) {
      ++hit;
      EXPECT_TRUE(std::isfinite(trad.depth[i]) && trad.depth[i] > 0) << "pixel " << i;
    }
  }
  EXPECT_GT(background, 0);
  EXPECT_GT(hit, 0);
  // A pixel all of whose samples hit: its normal is the mean of unit normals facing the camera.
  const std::size_t centre = 32 * 64 + 32;
  ASSERT_EQ(trad.level[centre], kLevelPrimitive);
  EXPECT_LE(length(trad.normal[centre]), 1.0f + 1e-5f);
  EXPECT_GT(length(trad.normal[centre]), 0.5f);

  // At a fixed level every rendered amalgam is on that level: the level output is exactly it.
  o.lod = OnLevel{2};
  const RenderOutput fixed = render(s, o);
  int on_level = 0;
  for (std::size_t i = 0; i < fixed.level.size(); ++i) {
    const float l = fixed.level[i];
    ASSERT_TRUE(l == 2.0f || l == kLevelPrimitive || l == kLevelNothing) << "pixel " << i;
    on_level += l == 2.0f;
  }
  EXPECT_GT(on_level, 0);
}

TEST(Aov, ACompositeBlendThatSaturatesIsWhereTheRayEnded) {
  // tests/data/bias-meadow.json: grass on ground that fills the frame. A camera ray ends at a
  // primitive, at a rendered amalgam, or in a blend of translucent amalgams that saturates
  // (composite opacity), whose depth and level are those of the amalgam that saturated it.
  // (They were reported as "nothing met": level -1, depth +inf, for about half the pixels.)
  // Only a ray that crosses the grass without saturating and then misses the ground (in the
  // top rows, beyond its far edge) meets nothing: 10 of these 3,072.
  const LoadedScene s =
      load_scene(std::string(AMALGAM_SOURCE_DIR) + "/tests/data/bias-meadow.json", Params{});
  RenderOptions o;
  o.opacity = OpacityKind::kComposite;
  o.lod = ByFootprint{2};
  o.width = 64, o.height = 48, o.spp = 1, o.threads = 2;
  const RenderOutput out = render(s, o);
  int nothing = 0, amalgams = 0;
  for (std::size_t i = 0; i < out.level.size(); ++i) {
    if (out.level[i] == -1.0f) {
      ++nothing;
      continue;
    }
    ASSERT_TRUE(std::isfinite(out.depth[i])) << "pixel " << i;
    if (out.level[i] >= 0) ++amalgams;
  }
  EXPECT_LT(nothing, 31) << "of " << out.level.size() << " pixels";
  EXPECT_GT(amalgams, static_cast<int>(out.level.size()) / 4);  // the far grass
}

TEST(Aov, OlderCheckpointFormatIsRefusedInOneLine) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("amalgam-old-" + std::to_string(getpid())))
          .string();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    const char old[] = "AMALGAM-CHECKPOINT-2\0rest of an old checkpoint";
    std::fwrite(old, 1, sizeof old, f);
    std::fclose(f);
  }
  try {
    read_checkpoint(path, "x");
    ADD_FAILURE() << "an old checkpoint was read";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("format 2"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace amalgam

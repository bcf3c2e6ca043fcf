// Progressive rendering: interruption keeps whole samples; resuming equals the uninterrupted
// render bit for bit.

#include <gtest/gtest.h>

#include <filesystem>

#include "amalgam/io/checkpoint.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

namespace amalgam {
namespace {

LoadedScene scene() {
  Params p("builtin:prisms");
  p.set("depth", "6");
  p.set("view", "corner");
  return load_scene("builtin:prisms", p);
}

TEST(Progressive, InterruptedThenResumedEqualsUninterrupted) {
  const LoadedScene s = scene();
  RenderOptions o;
  o.width = 256, o.height = 256, o.spp = 3, o.seed = 5;  // 1 sample per pass at this size
  const RenderOutput full = render(s, o);

  std::atomic<bool> cancel{false};
  RenderControl control;
  control.cancel = &cancel;
  control.on_pass = [&](const FilmState&) { cancel = true; };
  FilmState state;
  const RenderOutput part = render(s, o, &state, control);
  EXPECT_TRUE(part.interrupted);
  EXPECT_EQ(part.spp, 1);
  EXPECT_EQ(state.spp_done, 1);
  EXPECT_EQ(part.counters.rays[0], 256u * 256u) << "only whole samples are kept";

  // Through a checkpoint file, as the CLI does.
  const std::string path =
      (std::filesystem::temp_directory_path() / ("amalgam-ckpt-" + std::to_string(getpid())))
          .string();
  write_checkpoint(path, "fingerprint", state);
  EXPECT_THROW(read_checkpoint(path, "other settings"), InputError);
  FilmState loaded = read_checkpoint(path, "fingerprint");
  std::filesystem::remove(path);

  const RenderOutput resumed = render(s, o, &loaded);
  EXPECT_FALSE(resumed.interrupted);
  ASSERT_EQ(resumed.spp, 3);
  ASSERT_EQ(resumed.image.size(), full.image.size());
  for (std::size_t i = 0; i < full.image.size(); ++i) {
    ASSERT_EQ(resumed.image[i], full.image[i]) << "pixel " << i;
    ASSERT_EQ(resumed.cost[i], full.cost[i]) << "pixel " << i;
  }
  EXPECT_EQ(resumed.counters.total(), full.counters.total());
  EXPECT_EQ(resumed.counters.by_level, full.counters.by_level);
  EXPECT_EQ(resumed.per_primary.mean(), full.per_primary.mean());
  EXPECT_EQ(resumed.per_primary.quantile(0.99), full.per_primary.quantile(0.99));
}

TEST(Progressive, CorruptCheckpointIsAnInputError) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("amalgam-bad-" + std::to_string(getpid())))
          .string();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    std::fputs("AMALGAM-CHECKPOINT-1 but truncated", f);
    std::fclose(f);
  }
  EXPECT_THROW(read_checkpoint(path, "x"), InputError);
  std::filesystem::remove(path);
  EXPECT_THROW(read_checkpoint(path, "x"), InputError) << "missing file";
}

}  // namespace
}  // namespace amalgam

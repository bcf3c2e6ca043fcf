// Progressive rendering: interruption keeps whole samples; resuming equals the uninterrupted
// render bit for bit.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

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

/// read_checkpoint's message on the bytes of `path`, "" if it read them.
std::string refusal(const std::string& path, const std::string& bytes) {
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << bytes;
  }
  try {
    read_checkpoint(path, "fp");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The message says what is wrong: a flipped byte in the header's magic (byte 20 is the NUL that
// ends "AMALGAM-CHECKPOINT-5") is damage, not "format 5, this one reads format 5"; another
// format is named; a file shorter or longer than its header declares is refused without
// reading more than the file holds.
TEST(Progressive, ACheckpointHeaderSaysWhatIsWrongWithIt) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("amalgam-hdr-" + std::to_string(getpid())))
          .string();
  FilmState st;
  st.width = 2, st.height = 1, st.spp_done = 1;
  st.sum.assign(2, Vec3{0.5f, 0.5f, 0.5f});
  st.tests.assign(2, 7);
  write_checkpoint(path, "fp", st);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  ASSERT_EQ(refusal(path, bytes), "");
  ASSERT_EQ(bytes.substr(0, 21), std::string("AMALGAM-CHECKPOINT-5", 21));

  std::string flipped = bytes;
  flipped[20] = static_cast<char>(flipped[20] ^ 0xff);
  std::string m = refusal(path, flipped);
  EXPECT_NE(m.find("damaged"), std::string::npos) << m;
  EXPECT_EQ(m.find("this one reads format 5"), std::string::npos) << m;
  flipped = bytes;
  flipped[20] = '7';  // a digit: "format 57" would be made up too
  m = refusal(path, flipped);
  EXPECT_NE(m.find("damaged"), std::string::npos) << m;

  std::string older = bytes;
  older[19] = '4';
  m = refusal(path, older);
  EXPECT_NE(m.find("format 4, this one reads format 5"), std::string::npos) << m;

  for (const std::string& wrong :
       {bytes + "x", bytes.substr(0, bytes.size() - 1), bytes.substr(0, 40)}) {
    m = refusal(path, wrong);
    EXPECT_NE(m.find("truncated or damaged"), std::string::npos) << m;
    EXPECT_NE(m.find(path), std::string::npos) << m;
  }
  std::filesystem::remove(path);
}

// A checkpoint whose header declares another film than the render's is refused from its
// header, before its body (as large as the film it declares) is read.
TEST(Progressive, ACheckpointOfAnotherFilmIsRefusedFromItsHeader) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("amalgam-film-" + std::to_string(getpid())))
          .string();
  FilmState st;
  st.width = 500, st.height = 400, st.spp_done = 1;
  st.sum.assign(200000, Vec3{0.5f, 0.5f, 0.5f});
  st.tests.assign(200000, 7);
  st.aov.assign(200000, PixelAov{});
  write_checkpoint(path, "fp", st);
  EXPECT_EQ(read_checkpoint(path, "fp", {500, 400}).width, 500);
  std::string m;
  try {
    read_checkpoint(path, "fp", {2, 1});
  } catch (const InputError& e) {
    m = e.what();
  }
  EXPECT_NE(m.find("declares a 500x400 film, this render's is 2x1"), std::string::npos) << m;
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace amalgam

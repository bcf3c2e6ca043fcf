// What every subcommand owes its user beyond `render`'s outputs: standard output's write errors
// are failures, a FIFO whose reader went away costs one checkpoint and not the render, compare
// and experiment check their outputs before any work (and a refused experiment leaves nothing
// behind), and the volumetric renderer's refusals say what is wrong.

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "../sanitized.h"
#include "cli_support.h"

namespace {
namespace commands {  // per file: the tests are compiled in batches

namespace fs = std::filesystem;

struct Result {
  int status;
  std::string err;
};

fs::path scratch() {
  return amalgam::test::scratch_dir("amalgam-commands");
}

/// Runs amalgam with `args` under `timeout 20` (stdout as `args` redirects it, else discarded);
/// its status and stderr.
Result amalgam(const std::string& args) {
  const fs::path err = scratch() / "stderr.txt";
  const bool redirected = args.find(" >") != std::string::npos;
  const auto r =
      amalgam::test::run_command("timeout -k 1 20 " + std::string(AMALGAM_BINARY) + " " + args +
                                 (redirected ? "" : " >/dev/null") + " 2>" + err.string());
  return {r.status, amalgam::test::slurp(err)};
}

int lines(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

const std::string kSmall =
    "render builtin:prisms --set depth=3 --width 8 --height 8 --spp 1 --quiet --out ";

// A write error on standard output (a full disk: /dev/full) fails the command that printed
// there, with one line: each of these exited 0 having printed nothing.
TEST(Stdout, AWriteErrorOnStandardOutputIsAFailure) {
  const std::string png = (scratch() / "a.png").string();
  ASSERT_EQ(amalgam(kSmall + png).status, 0);
  for (const std::string& cmd :
       {std::string("--version"), std::string("scenes"), "compare " + png + " " + png,
        std::string("trace builtin:prisms --set depth=3")}) {
    const Result r = amalgam(cmd + " >/dev/full");
    EXPECT_EQ(r.status, 1) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find("amalgam: cannot write to standard output"), std::string::npos)
        << cmd << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << cmd << ": " << r.err;
  }
  EXPECT_EQ(amalgam("scenes").status, 0);
}

// A checkpoint FIFO whose reader leaves after 100 bytes: one warning, and the render goes on
// and writes its image (SIGPIPE used to end it: no image, no stats).
TEST(Stdout, AFifoWhoseReaderWentAwayCostsOnlyTheCheckpoint) {
  const fs::path fifo = scratch() / "ckpt.fifo", png = scratch() / "fifo.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread reader([&] {
    (void)amalgam::test::run_command("timeout 20 head -c 100 " + fifo.string() + " >/dev/null");
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the reader opens first
  const Result r = amalgam(
      "render builtin:prisms --set depth=6 --width 256 --height 256 --spp 4 --quiet "
      "--checkpoint-every 0 --checkpoint " +
      fifo.string() + " --out " + png.string());
  reader.join();
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(png)) << r.err;
  EXPECT_NE(r.err.find("warning: checkpoint " + fifo.string() + " not written"), std::string::npos)
      << r.err;
}

// compare checks its output before any work, and reads the images' sizes from their headers
// before decoding them.
TEST(Compare, TheOutputAndTheSizesAreCheckedBeforeAnyWork) {
  const std::string a = (scratch() / "c8.png").string(), b = (scratch() / "c16.png").string();
  ASSERT_EQ(amalgam(kSmall + a).status, 0);
  ASSERT_EQ(amalgam("render builtin:prisms --set depth=3 --width 16 --height 8 --spp 1 --quiet "
                    "--out " +
                    b)
                .status,
            0);
  // An error image that is no image format: exit 2 at once (it used to be exit 1 after the
  // comparison).
  Result r = amalgam("compare " + a + " " + a + " --error-image " + (scratch() / "e.txt").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--error-image"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("unsupported image format"), std::string::npos) << r.err;
  // A first image whose pixels are damaged but whose header says 8x8: the sizes differ, said
  // from the headers, before the damaged pixels are decoded.
  std::string bytes = amalgam::test::slurp(a);
  bytes.resize(40);
  const std::string cut = (scratch() / "cut.png").string();
  std::ofstream(cut, std::ios::binary) << bytes;
  r = amalgam("compare " + cut + " " + b);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is 8x8 but"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is 16x8: compare needs images of the same size"), std::string::npos)
      << r.err;
}

// A refused experiment leaves no directory behind: --out is created only for a run that
// starts, and removed again when its outputs are refused.
TEST(Experiment, ARefusedExperimentLeavesNoDirectory) {
  const fs::path out = scratch() / "new" / "dir";
  Result r = amalgam("experiment linear-cost --quick --scenes " + (scratch() / "missing").string() +
                     " --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(fs::exists(scratch() / "new")) << r.err;
  // Its report on a directory where report.md is a directory: refused before any work.
  fs::create_directories(scratch() / "taken" / "report.md");
  r = amalgam("experiment linear-cost --quick --out " + (scratch() / "taken").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("report.md"), std::string::npos) << r.err;
}

// The volumetric renderer on a scene without meshes says so (it used to say the scene "was
// loaded without volumetric amalgams").
TEST(Volumetric, ASceneWithoutMeshesIsSaidToHaveNone) {
  const std::string png = (scratch() / "v.png").string();
  const Result r =
      amalgam("render " + std::string(AMALGAM_SOURCE_DIR) +
              "/scenes/spheres.json --renderer volumetric --width 8 --height 8 --out " + png);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("spheres.json has no meshes"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(png));
}

// The volumetric renderer's bake is held to --max-memory as it goes: each block of cells is
// charged before it is allocated, on top of what the process holds once the scene is built.
// The aerial forest peaks at about 91 MiB (8x8 pixels); under 80M its render used to go on
// past the limit (the bake's 26 MiB were in no estimate); now it is refused, within the limit.
TEST(Volumetric, TheBakeIsHeldToTheMemoryLimit) {
  const std::string scene = std::string(AMALGAM_SOURCE_DIR) + "/scenes/aerial-forest.json";
  const std::string png = (scratch() / "aerial.png").string();
  const Result r = amalgam("render " + scene + " --renderer volumetric --width 8 --height 8 " +
                           "--spp 1 --quiet --max-memory 80M --out " + png);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("baking its volumetric amalgams needs more than --max-memory 80.0 MiB"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(png));
  struct rusage children {};
  getrusage(RUSAGE_CHILDREN, &children);
  if (!amalgam::kSanitized) {  // AddressSanitizer's shadow memory is resident too
    EXPECT_LT(static_cast<double>(children.ru_maxrss) * 1024.0, 80.0 * (1 << 20));
  }
  // With room, it renders (AddressSanitizer's shadow memory counts: far more room there).
  const std::string ample = amalgam::kSanitized ? "8G" : "200M";
  EXPECT_EQ(amalgam("render " + scene + " --renderer volumetric --width 8 --height 8 " +
                    "--spp 1 --quiet --max-memory " + ample + " --out " + png)
                .status,
            0);
}

/// What `command` prints on its standard output (and stderr, if it redirects it there).
std::string output_of(const std::string& command) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  if (p == nullptr) return out;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  pclose(p);
  return out;
}

// On a terminal the bar moves as blocks of pixels finish, not once per pass of samples: a
// render of one sample per pixel (one pass) showed nothing until 100 %.
TEST(Progress, TheBarMovesWithinAPassOfSamples) {
  ASSERT_EQ(std::system("command -v script >/dev/null 2>&1"), 0) << "script(1) (bsdutils) missing";
  const std::string out = output_of(
      "AMALGAM_PROGRESS_AFTER=0 script -qec '" + std::string(AMALGAM_BINARY) +
      " render builtin:prisms --set depth=8 --set view=corner --width 512 --height 512 --spp 1 "
      "--threads 1 --out " +
      (scratch() / "bar.pfm").string() + "' /dev/null");
  int below_full = 0;  // percentages shown before the end (measured: about 25 in 0.6 s)
  for (std::size_t at = out.find("% of 1 spp"); at != std::string::npos;
       at = out.find("% of 1 spp", at + 1)) {
    const int percent = std::atoi(out.substr(at - 3, 3).c_str());
    below_full += percent > 0 && percent < 100;
  }
  EXPECT_GE(below_full, 2) << out;
  EXPECT_NE(out.find("ETA"), std::string::npos) << out;
}

}  // namespace commands
}  // namespace

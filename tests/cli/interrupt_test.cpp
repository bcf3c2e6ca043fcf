// SIGINT/SIGTERM during a render, made deterministic: the render asks for far more samples than
// it could finish during the test and writes a checkpoint after every pass
// (--checkpoint-every 0), so the test waits until the first checkpoint exists (at least one
// pass done) and only then signals the process. Checked: the partial image is written, complete,
// with a message saying how many samples it holds; the checkpoint resumes to the same bytes as
// an uninterrupted render; a second (and a third) signal never leaves a half-written file or a
// temporary behind; damaged checkpoints, other settings and an edited scene are refused.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "../sanitized.h"
#include "cli_support.h"

extern char** environ;

namespace {
namespace interrupt {  // per file: the tests are compiled in batches

namespace fs = std::filesystem;
using amalgam::test::samples_held;
using amalgam::test::slurp;

/// A fresh directory per test.
struct Dir {
  fs::path path;
  explicit Dir(const std::string& name)
      : path(fs::temp_directory_path() / ("amalgam-int-" + name + "-" + std::to_string(getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Dir() { fs::remove_all(path); }
  /// Files whose name holds ".tmp-": temporaries of atomic writes.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> t;
    for (const auto& e : fs::directory_iterator(path))
      if (e.path().filename().string().find(".tmp-") != std::string::npos)
        t.push_back(e.path().filename().string());
    return t;
  }
};

std::vector<std::string> split(const std::string& args) {
  std::istringstream in(args);
  std::vector<std::string> v;
  for (std::string w; in >> w;) v.push_back(w);
  return v;
}

/// Starts amalgam with `args`, stderr to `err`.
pid_t start(const std::string& args, const fs::path& err) {
  std::vector<std::string> words = split(args);
  words.insert(words.begin(), AMALGAM_BINARY);
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  EXPECT_EQ(posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&fa);
  return pid;
}

/// Waits for `pid`; its exit status, or 128 + signal.
int finish(pid_t pid) {
  int st = 0;
  while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

int run(const std::string& args) {
  const fs::path err = fs::temp_directory_path() / ("amalgam-int-run-" + std::to_string(getpid()));
  const int st = finish(start(args, err));
  fs::remove(err);
  return st;
}

/// Waits until `file` exists (the render wrote its first checkpoint), at most a minute.
bool wait_for(const fs::path& file, pid_t pid) {
  for (int i = 0; i < 6000; ++i) {
    if (fs::exists(file)) return true;
    int st = 0;
    if (waitpid(pid, &st, WNOHANG) == pid) return false;  // ended before: a failure
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

/// The PFM bytes a complete w x h colour image has.
std::size_t pfm_size(int w, int h) {
  const std::string header = "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n";
  return header.size() + static_cast<std::size_t>(w) * h * 12;
}

const std::string kRender =
    "render builtin:prisms --set depth=7 --set view=corner --width 64 --height 48 --seed 3 "
    "--quiet --checkpoint-every 0";

/// Starts a render that cannot finish, waits for its first checkpoint, sends `signals` (each
/// 5 ms after the one before) and returns its exit status; `err` receives its stderr.
int interrupt(const Dir& d, const std::string& out, const std::vector<int>& signals,
              const std::string& extra = "") {
  const pid_t pid = start(kRender + " --spp 1000000 --out " + out + extra, d.path / "err.txt");
  EXPECT_TRUE(wait_for(out + ".ckpt", pid))
      << "no checkpoint appeared: " << slurp(d.path / "err.txt");
  for (int s : signals) {
    kill(pid, s);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return finish(pid);
}

TEST(CliInterrupt, SigintWritesTheCompletePartialImageAndResumeMatchesAnUninterruptedRun) {
  Dir d("sigint");
  const std::string out = (d.path / "run.pfm").string();
  EXPECT_EQ(interrupt(d, out, {SIGINT}), 1);
  const std::string err = slurp(d.path / "err.txt");
  EXPECT_NE(err.find("interrupted by SIGINT"), std::string::npos) << err;
  const int held = samples_held(err);
  ASSERT_GE(held, 1) << err;
  EXPECT_EQ(fs::file_size(out), pfm_size(64, 48)) << "the partial image is complete";
  EXPECT_TRUE(fs::exists(out + ".ckpt"));
  EXPECT_TRUE(d.temporaries().empty());
  // Resume to two more samples than the checkpoint holds: the bytes of an uninterrupted run.
  const std::string spp = " --spp " + std::to_string(held + 2);
  const std::string ref = (d.path / "ref.pfm").string();
  ASSERT_EQ(run(kRender + spp + " --out " + ref), 0);
  ASSERT_EQ(run(kRender + spp + " --out " + out + " --resume"), 0);
  EXPECT_EQ(slurp(out), slurp(ref)) << "resumed image differs";
  EXPECT_FALSE(fs::exists(out + ".ckpt")) << "checkpoint removed once complete";
}

// A resumed OpenEXR is the same file as the uninterrupted render's, header included: the
// command line it records leaves out --resume (it used to record it; the pixels were the same).
TEST(CliInterrupt, AResumedExrIsTheSameFileAsAnUninterruptedOne) {
  Dir d("exr");
  const std::string out = (d.path / "run.exr").string();
  EXPECT_EQ(interrupt(d, out, {SIGINT}), 1);
  const int held = samples_held(slurp(d.path / "err.txt"));
  ASSERT_GE(held, 1) << slurp(d.path / "err.txt");
  // The uninterrupted render under the same command line (the path is in the header), its
  // checkpoint set aside meanwhile.
  const std::string spp = " --spp " + std::to_string(held + 1);
  fs::rename(out + ".ckpt", d.path / "kept.ckpt");
  ASSERT_EQ(run(kRender + spp + " --out " + out), 0);
  const std::string ref = slurp(out);
  fs::rename(d.path / "kept.ckpt", out + ".ckpt");
  ASSERT_EQ(run(kRender + spp + " --out " + out + " --resume"), 0);
  EXPECT_TRUE(slurp(out) == ref) << "the resumed EXR differs";
}

TEST(CliInterrupt, SigtermDoesTheSame) {
  Dir d("sigterm");
  const std::string out = (d.path / "run.pfm").string();
  EXPECT_EQ(interrupt(d, out, {SIGTERM}), 1);
  const std::string err = slurp(d.path / "err.txt");
  EXPECT_NE(err.find("interrupted by SIGTERM"), std::string::npos) << err;
  EXPECT_GE(samples_held(err), 1) << err;
  EXPECT_EQ(fs::file_size(out), pfm_size(64, 48));
  EXPECT_TRUE(fs::exists(out + ".ckpt"));
  EXPECT_TRUE(d.temporaries().empty());
}

TEST(CliInterrupt, ASecondSignalStillWritesEverythingAndAThirdLeavesNothingHalfWritten) {
  {
    Dir d("twice");
    const std::string out = (d.path / "run.pfm").string();
    EXPECT_EQ(interrupt(d, out, {SIGINT, SIGINT}), 1) << slurp(d.path / "err.txt");
    EXPECT_EQ(fs::file_size(out), pfm_size(64, 48));
    EXPECT_TRUE(d.temporaries().empty()) << d.temporaries().front();
    // The checkpoint is whole: resuming it is accepted.
    const int held = samples_held(slurp(d.path / "err.txt"));
    ASSERT_GE(held, 1);
    EXPECT_EQ(run(kRender + " --spp " + std::to_string(held + 1) + " --out " + out + " --resume"),
              0);
  }
  for (int round = 0; round < 3; ++round) {
    Dir d("thrice");
    const std::string out = (d.path / "run.pfm").string();
    const int st = interrupt(d, out, {SIGINT, SIGINT, SIGINT});
    // Finished the writes (1) or ended by the third signal (130): never a partial file.
    EXPECT_TRUE(st == 1 || st == 128 + SIGINT) << st;
    EXPECT_TRUE(d.temporaries().empty()) << d.temporaries().front();
    if (fs::exists(out)) {
      EXPECT_EQ(fs::file_size(out), pfm_size(64, 48));
    }
  }
}

TEST(CliInterrupt, ResumeRefusesOtherSettingsADamagedCheckpointAndAnEditedScene) {
  Dir d("refuse");
  const std::string out = (d.path / "run.pfm").string();
  ASSERT_EQ(interrupt(d, out, {SIGINT}), 1);
  const int held = samples_held(slurp(d.path / "err.txt"));
  ASSERT_GE(held, 1);
  const std::string spp = " --spp " + std::to_string(held + 1);
  // Other settings: another seed; another builtin parameter.
  std::string reseeded = kRender;
  reseeded.replace(reseeded.find("--seed 3"), 8, "--seed 4");
  for (const std::string& other : {reseeded, kRender + " --set leaf=3"}) {
    const fs::path e = d.path / "other.txt";
    EXPECT_EQ(finish(start(other + spp + " --out " + out + " --resume", e)), 2) << other;
    EXPECT_NE(slurp(e).find("different settings"), std::string::npos) << slurp(e);
  }
  // One flipped bit.
  const std::string ckpt = out + ".ckpt";
  std::string bytes = slurp(ckpt);
  bytes[bytes.size() / 2] ^= 0x10;
  std::ofstream(ckpt, std::ios::binary | std::ios::trunc) << bytes;
  const fs::path err = d.path / "resume-err.txt";
  EXPECT_EQ(finish(start(kRender + spp + " --out " + out + " --resume", err)), 2);
  EXPECT_NE(slurp(err).find("damaged"), std::string::npos) << slurp(err);

  // A scene file edited between the interrupt and the resume.
  const fs::path scene = d.path / "s.json";
  auto write_scene = [&](const char* colour) {
    std::ofstream(scene)
        << R"({"materials": {"m": {"colour": )" << colour
        << R"(}}, "spheres": [{"centre": [0, 0, 0], "radius": 1, "material": "m"}]})";
  };
  write_scene("[0.8, 0.2, 0.2]");
  const std::string sout = (d.path / "scene.pfm").string();
  const std::string srender =
      "render " + scene.string() + " --width 64 --height 48 --quiet --checkpoint-every 0";
  const pid_t pid = start(srender + " --spp 1000000 --out " + sout, d.path / "serr.txt");
  ASSERT_TRUE(wait_for(sout + ".ckpt", pid)) << slurp(d.path / "serr.txt");
  kill(pid, SIGINT);
  ASSERT_EQ(finish(pid), 1) << slurp(d.path / "serr.txt");
  const int sheld = samples_held(slurp(d.path / "serr.txt"));
  ASSERT_GE(sheld, 1);
  const std::string sres = " --spp " + std::to_string(sheld + 1) + " --out " + sout + " --resume";
  write_scene("[0.2, 0.8, 0.2]");
  const fs::path serr = d.path / "serr2.txt";
  EXPECT_EQ(finish(start(srender + sres, serr)), 2) << "an edited scene is not resumed";
  EXPECT_NE(slurp(serr).find("different settings"), std::string::npos) << slurp(serr);
  write_scene("[0.8, 0.2, 0.2]");
  EXPECT_EQ(run(srender + sres), 0) << "the same scene again is";
}

/// Runs `sh -c SCRIPT` bounded by `timeout 10`, SIGKILL a second later (a hang fails the test,
/// never the suite); its exit status (124 or 137: it timed out) and stderr (`err`).
int run_bounded(const std::string& script, const fs::path& err) {
  const std::string cmd = "timeout -k 1 10 sh -c '" + script + "' 2>" + err.string();
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

// A checkpoint to resume that is not a regular file is refused at once, naming it: a character
// device used to be read without end (memory grew until it ran out), a FIFO waited forever for
// a writer.
TEST(CliInterrupt, ResumeRefusesACheckpointThatIsNotARegularFile) {
  Dir d("special");
  const std::string fifo = (d.path / "fifo.ckpt").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& ckpt : {std::string("/dev/zero"), fifo}) {
    const auto t0 = std::chrono::steady_clock::now();
    // Bounded address space (not under ASan, which reserves terabytes): a reader without end
    // runs out instead of taking the machine's memory.
#if AMALGAM_TEST_ASAN
    const std::string limit;
#else
    const std::string limit = "ulimit -v 600000; ";
#endif
    const int st =
        run_bounded(limit + "exec " + std::string(AMALGAM_BINARY) +
                        " render builtin:prisms --set depth=3 --width 8 --height 8 "
                        "--spp 2 --quiet --out " +
                        (d.path / "x.pfm").string() + " --checkpoint " + ckpt + " --resume",
                    d.path / "err.txt");
    const std::string err = slurp(d.path / "err.txt");
    EXPECT_EQ(st, 2) << ckpt << ": " << err;
    EXPECT_NE(err.find(ckpt + ": is a "), std::string::npos) << err;
    EXPECT_NE(err.find("not a regular file"), std::string::npos) << err;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  }
  EXPECT_FALSE(fs::exists(d.path / "x.pfm"));
}

// --checkpoint through a symbolic link: written through it (the link kept), and once the
// resumed render is complete the checkpoint it leads to is removed, the link still kept.
TEST(CliInterrupt, ACheckpointThroughASymbolicLinkKeepsTheLink) {
  Dir d("ckptlink");
  fs::create_directories(d.path / "store");
  const fs::path target = d.path / "store" / "run.ckpt", link = d.path / "run.ckpt";
  fs::create_symlink(target, link);
  const std::string out = (d.path / "run.pfm").string();
  const std::string args = " --out " + out + " --checkpoint " + link.string();
  const pid_t pid = start(kRender + " --spp 1000000" + args, d.path / "err.txt");
  ASSERT_TRUE(wait_for(target, pid)) << slurp(d.path / "err.txt");
  kill(pid, SIGINT);
  ASSERT_EQ(finish(pid), 1) << slurp(d.path / "err.txt");
  ASSERT_TRUE(fs::is_symlink(link));
  const int held = samples_held(slurp(d.path / "err.txt"));
  ASSERT_GE(held, 1);
  ASSERT_EQ(run(kRender + " --spp " + std::to_string(held + 1) + args + " --resume"), 0);
  EXPECT_TRUE(fs::is_symlink(link)) << "the link was removed";
  EXPECT_EQ(fs::read_symlink(link), target);
  EXPECT_FALSE(fs::exists(target)) << "the stale checkpoint was left at the link's target";
}

// SIGHUP (a closed terminal, a dropped SSH session) and SIGQUIT keep the work as SIGTERM does.
TEST(CliInterrupt, SighupAndSigquitDoTheSame) {
  for (const auto& [sig, name] : {std::pair{SIGHUP, "SIGHUP"}, std::pair{SIGQUIT, "SIGQUIT"}}) {
    Dir d(name);
    const std::string out = (d.path / "run.pfm").string();
    EXPECT_EQ(interrupt(d, out, {sig}), 1) << name;
    const std::string err = slurp(d.path / "err.txt");
    EXPECT_NE(err.find(std::string("interrupted by ") + name), std::string::npos) << err;
    EXPECT_GE(samples_held(err), 1) << err;
    EXPECT_EQ(fs::file_size(out), pfm_size(64, 48));
    EXPECT_TRUE(fs::exists(out + ".ckpt"));
  }
}

/// The inode of `p`, 0 if it does not exist (each atomic write of a file makes a new one).
ino_t inode(const fs::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 ? st.st_ino : 0;
}

// A signal ignored when amalgam starts stays ignored (nohup ignores SIGHUP; a non-interactive
// shell ignores SIGINT in the jobs it starts with &): the render goes on through it, writing
// checkpoints, and stops only on SIGTERM.
TEST(CliInterrupt, ASignalIgnoredAtStartStaysIgnored) {
  Dir d("ignored");
  const std::string out = (d.path / "run.pfm").string(), ckpt = out + ".ckpt";
  std::vector<std::string> words = {"/bin/sh", "-c", "trap \"\" INT HUP; exec \"$0\" \"$@\"",
                                    AMALGAM_BINARY};
  for (const std::string& w : split(kRender + " --spp 1000000 --out " + out)) words.push_back(w);
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  const std::string err = (d.path / "err.txt").string();
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  ASSERT_EQ(posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&fa);
  ASSERT_TRUE(wait_for(ckpt, pid)) << slurp(err);
  kill(pid, SIGINT);
  kill(pid, SIGHUP);
  // Still rendering: three more checkpoints after the signals (a render they stopped would
  // write at most two: at the end of the pass under way and the final one).
  ino_t last = inode(ckpt);
  int written = 0;
  for (int i = 0; i < 6000 && written < 3; ++i) {
    int st = 0;
    if (waitpid(pid, &st, WNOHANG) == pid) {
      FAIL() << "ended by an ignored signal: " << slurp(err);
    }
    if (const ino_t now = inode(ckpt); now != 0 && now != last) last = now, ++written;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(written, 3);
  kill(pid, SIGTERM);
  EXPECT_EQ(finish(pid), 1);
  EXPECT_NE(slurp(err).find("interrupted by SIGTERM"), std::string::npos) << slurp(err);
}

#if defined(AMALGAM_HAVE_EMBREE)
TEST(CliInterrupt, EmbreeResumesItsOwnCheckpointButNotAmalgams) {
  Dir d("embree");
  const std::string out = (d.path / "run.pfm").string();
  // --tracer embree on a smaller prisms (Embree lists every box: 2 million at depth 7).
  std::string render = kRender;
  render.replace(render.find("depth=7"), 7, "depth=5");
  const std::string embree = render + " --tracer embree";
  const pid_t pid = start(embree + " --spp 1000000 --out " + out, d.path / "err.txt");
  ASSERT_TRUE(wait_for(out + ".ckpt", pid)) << slurp(d.path / "err.txt");
  kill(pid, SIGINT);
  ASSERT_EQ(finish(pid), 1) << slurp(d.path / "err.txt");
  const int held = samples_held(slurp(d.path / "err.txt"));
  ASSERT_GE(held, 1);
  const std::string spp = " --spp " + std::to_string(held + 2);
  // amalgam's tracer does not continue Embree's samples (the fingerprint names the tracer).
  const fs::path e = d.path / "other.txt";
  EXPECT_EQ(
      finish(start(render + " --renderer traditional" + spp + " --out " + out + " --resume", e)),
      2);
  EXPECT_NE(slurp(e).find("different settings"), std::string::npos) << slurp(e);
  const std::string ref = (d.path / "ref.pfm").string();
  ASSERT_EQ(run(embree + spp + " --out " + ref), 0);
  ASSERT_EQ(run(embree + spp + " --out " + out + " --resume"), 0);
  EXPECT_EQ(slurp(out), slurp(ref)) << "resumed image differs";
}
#endif

}  // namespace interrupt
}  // namespace

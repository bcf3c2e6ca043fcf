// `mpirun -np N amalgam render` (docs/mpi.md), end to end with Open MPI on this machine:
// byte-identical to a single-process render for any N; an interrupted parallel render
// (a signal to one worker rank, made deterministic by waiting for the first checkpoint) writes
// what the ranks finished and resumes with another N, and with one process; a stalled rank is
// taken as lost and its tiles are rendered by the others; a killed rank is named with the tile
// it held. Skipped, with the reason, only in a build without MPI or where mpirun cannot start
// a process at all.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_support.h"

extern char** environ;

namespace {
namespace mpi_cli {  // per file: the tests are compiled in batches

namespace fs = std::filesystem;
using amalgam::test::run_command;
using amalgam::test::samples_held;
using amalgam::test::slurp;

#if defined(AMALGAM_MPIEXEC)
const std::string kMpirun = AMALGAM_MPIEXEC;
#else
const std::string kMpirun;
#endif

/// mpirun's options for N ranks on this machine: more ranks than cores, and as root here.
std::string mpirun(int n) {
  std::string s = kMpirun + " -np " + std::to_string(n) + " --oversubscribe";
  if (geteuid() == 0) s += " --allow-run-as-root";
  return s;
}

/// Why the MPI tests cannot run here, or "" when they can.
std::string cannot_run() {
  if (kMpirun.empty()) return "amalgam was built without MPI (AMALGAM_MPI=OFF or no MPI found)";
  static const std::string why = [] {
    const auto r = run_command(mpirun(1) + " true 2>&1");
    return r.status == 0 ? std::string() : "mpirun cannot start a process here: " + r.out;
  }();
  return why;
}

#define SKIP_WITHOUT_MPIRUN()                                                    \
  do {                                                                           \
    if (const std::string why = cannot_run(); !why.empty()) GTEST_SKIP() << why; \
  } while (0)

struct Dir {
  fs::path path;
  explicit Dir(const std::string& name)
      : path(fs::temp_directory_path() / ("amalgam-mpi-" + name + "-" + std::to_string(getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Dir() { fs::remove_all(path); }
};

const std::string kBinary = AMALGAM_BINARY;
// 64x48 pixels: 3 rounds of 64 samples per pixel with 3 ranks (mpi_render.cpp), 12 tiles each.
const std::string kScene =
    " render builtin:prisms --set depth=7 --set view=corner --width 64 --height 48 --seed 3 "
    "--quiet";

/// Runs a command line; its exit status, stderr into `err`.
int sh(const std::string& cmd, const fs::path& err) {
  return run_command(cmd + " 2>" + err.string()).status;
}

/// Starts `cmd` with /bin/sh, stderr to `err`; its pid.
pid_t start(const std::string& cmd, const fs::path& err) {
  const std::string line = "exec " + cmd + " 2>" + err.string();
  std::vector<char*> argv = {const_cast<char*>("/bin/sh"), const_cast<char*>("-c"),
                             const_cast<char*>(line.c_str()), nullptr};
  pid_t pid = -1;
  EXPECT_EQ(posix_spawn(&pid, "/bin/sh", nullptr, nullptr, argv.data(), environ), 0);
  return pid;
}

int finish(pid_t pid) {
  int st = 0;
  while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

bool wait_for(const fs::path& file, pid_t pid) {
  for (int i = 0; i < 6000; ++i) {
    if (fs::exists(file)) return true;
    int st = 0;
    if (waitpid(pid, &st, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

/// The pid of rank `rank` among the children of mpirun `pid` (its OMPI_COMM_WORLD_RANK), -1 if
/// none.
pid_t rank_pid(pid_t mpirun_pid, int rank) {
  std::ifstream children("/proc/" + std::to_string(mpirun_pid) + "/task/" +
                         std::to_string(mpirun_pid) + "/children");
  for (pid_t c; children >> c;) {
    const std::string env = slurp("/proc/" + std::to_string(c) + "/environ");
    if (env.find(std::string("OMPI_COMM_WORLD_RANK=") + std::to_string(rank) + '\0') !=
        std::string::npos)
      return c;
  }
  return -1;
}

/// The counts of a stats JSON: everything but times, memory, the command line and the
/// thread and rank counts.
nlohmann::json counts(const fs::path& stats) {
  nlohmann::json j = nlohmann::json::parse(slurp(stats));
  for (const char* k : {"time_s", "peak_memory_bytes", "command_line", "threads", "ranks"})
    j.erase(k);
  return j;
}

TEST(CliMpi, ThreeRanksRenderTheBytesOfOneProcess) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("same");
  const auto p = [&](const std::string& f) { return (d.path / f).string(); };
  const std::string args = kScene + " --spp 150";  // one process on 2 threads, ranks on 1
  ASSERT_EQ(sh(kBinary + args + " --threads 2 --out " + p("one.pfm") + " --cost-image " +
                   p("one-cost.pfm") + " --level-image " + p("one-level.pfm") + " --stats " +
                   p("one.json"),
               d.path / "err1"),
            0)
      << slurp(d.path / "err1");
  ASSERT_EQ(sh(mpirun(3) + " " + kBinary + args + " --threads 1 --out " + p("three.pfm") +
                   " --cost-image " + p("three-cost.pfm") + " --level-image " +
                   p("three-level.pfm") + " --stats " + p("three.json"),
               d.path / "err3"),
            0)
      << slurp(d.path / "err3");
  EXPECT_FALSE(slurp(p("one.pfm")).empty());
  EXPECT_EQ(slurp(p("three.pfm")), slurp(p("one.pfm"))) << "image";
  EXPECT_EQ(slurp(p("three-cost.pfm")), slurp(p("one-cost.pfm"))) << "cost image";
  EXPECT_EQ(slurp(p("three-level.pfm")), slurp(p("one-level.pfm"))) << "level image";
  const nlohmann::json one = counts(p("one.json")), three = counts(p("three.json"));
  EXPECT_EQ(three, one) << three.dump(1) << "\n" << one.dump(1);
  EXPECT_GT(one.at("tests").at("total").get<std::uint64_t>(), 0u);
  EXPECT_EQ(nlohmann::json::parse(slurp(p("one.json"))).at("ranks"), 1);
  EXPECT_EQ(nlohmann::json::parse(slurp(p("three.json"))).at("ranks"), 3);
  EXPECT_FALSE(fs::exists(p("three.pfm.ckpt")));
}

TEST(CliMpi, StratifiedSamplingAndTwoRanksToo) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("strat");
  const auto p = [&](const std::string& f) { return (d.path / f).string(); };
  const std::string args = kScene + " --spp 40 --sampler stratified --renderer traditional";
  ASSERT_EQ(sh(kBinary + args + " --out " + p("one.exr"), d.path / "err1"), 0);
  ASSERT_EQ(
      sh(mpirun(2) + " " + kBinary + args + " --threads 1 --out " + p("two.exr"), d.path / "err2"),
      0)
      << slurp(d.path / "err2");
  // The EXR header holds the command line: compare the pixels through the PFM outputs instead.
  ASSERT_EQ(sh(kBinary + args + " --out " + p("one.pfm"), d.path / "err1"), 0);
  ASSERT_EQ(
      sh(mpirun(2) + " " + kBinary + args + " --threads 1 --out " + p("two.pfm"), d.path / "err2"),
      0);
  EXPECT_EQ(slurp(p("two.pfm")), slurp(p("one.pfm")));
}

// One object (the tree: its own cells) and a crowd of instances smaller than a pixel (the
// world cells stand for them).
TEST(CliMpi, VolumetricRendersTheSameBytesOverRanks) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("volumetric");
  const auto p = [&](const std::string& f) { return (d.path / f).string(); };
  for (const char* scene : {"/scenes/volumetric/tree.json", "/tests/data/crowd.json"}) {
    SCOPED_TRACE(scene);
    const std::string args = std::string(" render ") + AMALGAM_SOURCE_DIR + scene +
                             " --width 48 --height 36 --spp 2 --renderer volumetric --quiet";
    ASSERT_EQ(sh(kBinary + args + " --out " + p("one.pfm") + " --stats " + p("one.json"),
                 d.path / "err1"),
              0)
        << slurp(d.path / "err1");
    ASSERT_EQ(sh(mpirun(2) + " " + kBinary + args + " --threads 1 --out " + p("two.pfm") +
                     " --stats " + p("two.json"),
                 d.path / "err2"),
              0)
        << slurp(d.path / "err2");
    EXPECT_FALSE(slurp(p("one.pfm")).empty());
    EXPECT_EQ(slurp(p("two.pfm")), slurp(p("one.pfm")));
    nlohmann::json one = counts(p("one.json")), two = counts(p("two.json"));
    for (nlohmann::json* j : {&one, &two})
      for (const char* time : {"bake_s", "world_bake_s"}) j->at("volumes").erase(time);
    EXPECT_EQ(two, one) << two.dump(1) << "\n" << one.dump(1);
    EXPECT_GT(one.at("tests").at("cell").get<std::uint64_t>(), 0u);
  }
}

#if defined(AMALGAM_HAVE_EMBREE)
TEST(CliMpi, EmbreeRendersTheSameBytesOverRanks) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("embree");
  const auto p = [&](const std::string& f) { return (d.path / f).string(); };
  const std::string args = kScene + " --spp 100 --tracer embree --renderer traditional";
  ASSERT_EQ(
      sh(kBinary + args + " --out " + p("one.pfm") + " --stats " + p("one.json"), d.path / "err1"),
      0)
      << slurp(d.path / "err1");
  ASSERT_EQ(sh(mpirun(3) + " " + kBinary + args + " --threads 1 --out " + p("three.pfm") +
                   " --stats " + p("three.json"),
               d.path / "err3"),
            0)
      << slurp(d.path / "err3");
  EXPECT_FALSE(slurp(p("one.pfm")).empty());
  EXPECT_EQ(slurp(p("three.pfm")), slurp(p("one.pfm")));
  nlohmann::json one = counts(p("one.json")), three = counts(p("three.json"));
  EXPECT_EQ(three, one);
}
#endif

TEST(CliMpi, AnInterruptedRenderResumesWithAnotherRankCountAndWithOneProcess) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("resume");
  const auto p = [&](const std::string& f) { return (d.path / f).string(); };
  const std::string out = p("run.pfm");
  const std::string cmd = mpirun(3) + " " + kBinary + kScene + " --threads 1 --checkpoint-every 0";
  const pid_t pid = start(cmd + " --spp 1000000 --out " + out, d.path / "err");
  ASSERT_TRUE(wait_for(out + ".ckpt", pid)) << slurp(d.path / "err");
  // SIGINT to one worker rank only: it tells rank 0, which stops every rank.
  const pid_t worker = rank_pid(pid, 2);
  ASSERT_GT(worker, 0) << "rank 2 not found among mpirun's children";
  kill(worker, SIGINT);
  EXPECT_EQ(finish(pid), 1);
  const std::string err = slurp(d.path / "err");
  EXPECT_NE(err.find("interrupted by SIGINT on rank 2"), std::string::npos) << err;
  const int held = samples_held(err);
  ASSERT_GE(held, 64) << err;
  EXPECT_EQ(held % 64, 0) << "a whole number of rounds: " << err;
  EXPECT_EQ(fs::file_size(out), std::string("PF\n64 48\n-1.0\n").size() + 64 * 48 * 12);
  ASSERT_TRUE(fs::exists(out + ".ckpt"));
  fs::copy_file(out + ".ckpt", p("saved.ckpt"));

  // Continued with two ranks, then (from the same checkpoint) with one process: both give the
  // bytes of an uninterrupted single-process render.
  const std::string spp = " --spp " + std::to_string(held + 70);
  ASSERT_EQ(sh(kBinary + kScene + spp + " --out " + p("ref.pfm"), d.path / "e"), 0);
  ASSERT_EQ(sh(mpirun(2) + " " + kBinary + kScene + spp + " --threads 1 --out " + out + " --resume",
               d.path / "e2"),
            0)
      << slurp(d.path / "e2");
  EXPECT_EQ(slurp(out), slurp(p("ref.pfm"))) << "resumed with 2 ranks";
  EXPECT_FALSE(fs::exists(out + ".ckpt"));
  fs::copy_file(p("saved.ckpt"), out + ".ckpt");
  fs::remove(out);
  ASSERT_EQ(sh(kBinary + kScene + spp + " --out " + out + " --resume", d.path / "e1"), 0)
      << slurp(d.path / "e1");
  EXPECT_EQ(slurp(out), slurp(p("ref.pfm"))) << "resumed with one process";
}

// Two ranks: once the only other rank stalls, rank 0 renders its tile and the rest itself.
TEST(CliMpi, AStalledRankIsTakenAsLostAndTheOthersFinishTheImage) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("stall");
  const auto p = [&](const std::string& f) { return (d.path / f).string(); };
  const std::string args = kScene + " --spp 1200 --checkpoint-every 0";
  ASSERT_EQ(sh(kBinary + args + " --out " + p("ref.pfm"), d.path / "e"), 0);
  const std::string out = p("run.pfm");
  const pid_t pid =
      start(mpirun(2) + " " + kBinary + args + " --threads 1 --rank-timeout 1 --out " + out,
            d.path / "err");
  ASSERT_TRUE(wait_for(out + ".ckpt", pid)) << slurp(d.path / "err");
  const pid_t worker = rank_pid(pid, 1);
  ASSERT_GT(worker, 0);
  kill(worker, SIGSTOP);  // alive but silent: no MPI failure, only the timeout finds it
  EXPECT_EQ(finish(pid), 1) << "the job ends with an error once the outputs are written";
  const std::string err = slurp(d.path / "err");
  EXPECT_NE(err.find("rank 1 has not returned tile"), std::string::npos) << err;
  EXPECT_NE(err.find("rank 1 was lost during the render"), std::string::npos) << err;
  EXPECT_EQ(slurp(out), slurp(p("ref.pfm")))
      << "complete and identical: rank 0 rendered the lost tile itself";
}

TEST(CliMpi, AKilledRankIsNamedWithTheTileItHeld) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("kill");
  const std::string out = (d.path / "run.pfm").string();
  const pid_t pid = start(mpirun(3) + " " + kBinary + kScene +
                              " --threads 1 --checkpoint-every 0 --spp 1000000 --out " + out,
                          d.path / "err");
  ASSERT_TRUE(wait_for(out + ".ckpt", pid)) << slurp(d.path / "err");
  const pid_t worker = rank_pid(pid, 2);
  ASSERT_GT(worker, 0);
  kill(worker, SIGKILL);
  // mpirun ends the job (SIGTERM to the other ranks): rank 0 writes what the ranks finished.
  EXPECT_NE(finish(pid), 0);
  const std::string err = slurp(d.path / "err");
  const std::size_t under_way = err.find("not finished; under way: ");
  ASSERT_NE(under_way, std::string::npos) << err;
  EXPECT_NE(err.find("(rank 2)", under_way), std::string::npos) << err;
  EXPECT_GE(samples_held(err), 64) << err;
  EXPECT_TRUE(fs::exists(out + ".ckpt"));
}

TEST(CliMpi, ARankThatCannotLoadTheSceneStopsEveryRankWithItsMessage) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("fail");
  // A scene file only rank 0's... every rank reads the same path here: a missing file fails
  // on every rank; each says so, and no rank waits for another.
  const int st = sh(mpirun(2) + " " + kBinary + " render " + (d.path / "none.json").string() +
                        " --quiet --out " + (d.path / "x.pfm").string(),
                    d.path / "err");
  const std::string err = slurp(d.path / "err");
  EXPECT_EQ(st, 2) << err;
  EXPECT_NE(err.find("none.json"), std::string::npos) << err;
  EXPECT_NE(err.find("rank 1 on "), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(d.path / "x.pfm"));
}

/// Whether a CSV column holds a wall time or a figure computed from one (they differ between
/// any two runs): *seconds*, us_*, ns_*, time_*, and premise's fits (fit_*, err_*) and sorting's
/// overhead_pct.
bool timed(const std::string& column) {
  if (column.find("seconds") != std::string::npos) return true;
  for (const char* prefix : {"us_", "ns_", "time_", "fit_", "err_", "overhead"})
    if (column.rfind(prefix, 0) == 0) return true;
  return false;
}

/// A CSV without its timed columns: what two runs share.
std::string untimed_csv(const fs::path& file) {
  std::istringstream in(slurp(file));
  std::string line, out;
  std::vector<bool> keep;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string c; std::getline(row, c, ',');) cells.push_back(c);
    if (keep.empty())
      for (const std::string& c : cells) keep.push_back(!timed(c));
    for (std::size_t i = 0; i < cells.size() && i < keep.size(); ++i)
      if (keep[i]) out += cells[i] + ",";
    out += "\n";
  }
  return out;
}

TEST(CliMpi, ExperimentSweepsOverThreeRanksGiveTheResultsOfOneProcess) {
  SKIP_WITHOUT_MPIRUN();
  Dir d("exp");
  const std::string args = " experiment all --quick --threads 1 --out ";
  const auto one = run_command(kBinary + args + (d.path / "one").string() + " 2>/dev/null");
  const auto three =
      run_command(mpirun(3) + " " + kBinary + args + (d.path / "three").string() + " 2>/dev/null");
  ASSERT_EQ(one.status, 0);
  ASSERT_EQ(three.status, 0);
  // The verdicts and check counts, in report order (the last line names the directory), but
  // premise's: it checks wall time, which differs between any two runs.
  const auto verdicts = [](const std::string& out) {
    std::istringstream in(out.substr(0, out.rfind("report:")));
    std::string kept;
    for (std::string line; std::getline(in, line);)
      if (line.rfind("premise: ", 0) != 0) kept += line + "\n";
    return kept;
  };
  EXPECT_EQ(verdicts(three.out), verdicts(one.out));
  int csvs = 0;
  for (const auto& e : fs::directory_iterator(d.path / "one")) {
    if (e.path().extension() != ".csv") continue;
    ++csvs;
    const fs::path other = d.path / "three" / e.path().filename();
    ASSERT_TRUE(fs::exists(other)) << other;
    EXPECT_EQ(untimed_csv(other), untimed_csv(e.path())) << e.path().filename();
  }
  EXPECT_GE(csvs, 9);
  EXPECT_TRUE(fs::exists(d.path / "three" / "report.md"));
}

}  // namespace mpi_cli
}  // namespace

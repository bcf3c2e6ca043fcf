// End-to-end tests of the `amalgam` binary: the outside contract (docs/cli.md, docs/outputs.md).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "amalgam/io/srgb.h"
#include "cli_support.h"

namespace {
namespace cli {  // per file: the tests are compiled in batches

namespace fs = std::filesystem;

struct CliRun {
  int status;
  std::string out;
};

/// The first line of a file (an error message the CLI wrote to stderr).
std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

// Runs the binary with `args` (a shell-quoted string); stdout captured, stderr to err_file.
CliRun run(const std::string& args, const std::string& err_file = "/dev/null") {
  const auto r =
      amalgam::test::run_command(std::string(AMALGAM_BINARY) + " " + args + " 2>" + err_file);
  return {r.status, r.out};
}

/// This process's scratch directory, removed when the process ends.
fs::path temp_dir() {
  return amalgam::test::scratch_dir("amalgam-cli");
}

TEST(Cli, TraceLineTraditionalIsTheWorstCase) {
  const CliRun r = run("trace builtin:line --set n=3 --set depth=6 --renderer traditional");
  ASSERT_EQ(r.status, 0);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["tests"]["primary"], 1093);
  EXPECT_EQ(j["tests"]["shadow"], 1093);
  EXPECT_EQ(j["scene"]["levels"], 7);
  EXPECT_EQ(j["hit"]["object"]["kind"], "primitive");
  EXPECT_TRUE(j["level"].is_null());
}

// `traversed` is the paper's count of objects traversed: on builtin:poisson with p huge the
// first amalgam of level 3 stops the ray, so it reaches the left edge and that amalgam,
// 3 + 1 = Eq. 4 with i = 1, while it tests both children of the 3 nodes it enters, 1 + 2 * 3.
// In the worst case (builtin:line, traditional) both counts are C_t0.
TEST(Cli, TraceReportsObjectsTraversedAsThePaperCounts) {
  CliRun r = run("trace builtin:poisson --set p=1e12 --set depth=6 --level 3");
  ASSERT_EQ(r.status, 0);
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["traversed"]["primary"], 4);
  EXPECT_EQ(j["tests"]["primary"], 7);
  r = run("trace builtin:line --set n=3 --set depth=6 --renderer traditional");
  ASSERT_EQ(r.status, 0);
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["traversed"]["primary"], 1093);
  EXPECT_EQ(j["traversed"]["shadow"], 1093);
}

TEST(Cli, TraceFootprintIsThatOfAPixelOfWidthByHeight) {
  auto trace = [](const std::string& size) {
    const CliRun r = run("trace builtin:prisms" + size);
    EXPECT_EQ(r.status, 0) << size;
    return nlohmann::json::parse(r.out);
  };
  const auto by_default = trace(""), same = trace(" --width 512 --height 512");
  EXPECT_EQ(by_default["tests"], same["tests"]);  // 512 x 512 is the default, as for render
  EXPECT_EQ(by_default["hit"], same["hit"]);
  // A pixel of a 16 x 16 image is wide: the ray stops at an amalgam above the primitives.
  const auto coarse = trace(" --width 16 --height 16");
  EXPECT_EQ(coarse["hit"]["object"]["kind"], "amalgam");
  EXPECT_EQ(by_default["hit"]["object"]["kind"], "primitive");
  EXPECT_LT(coarse["tests"]["total"].get<int>(), by_default["tests"]["total"].get<int>());
  EXPECT_EQ(run("trace builtin:prisms --width 0").status, 2);
}

TEST(Cli, RenderWritesImageCostImageAndStats) {
  const fs::path d = temp_dir();
  const CliRun r =
      run("render builtin:prisms --set depth=4 --level 2 --width 40 --height 30 --spp 2 "
          "--out " +
          (d / "a.png").string() + " --cost-image " + (d / "c.png").string() + " --stats " +
          (d / "s.json").string());
  ASSERT_EQ(r.status, 0);
  // Both images are real 40 x 30 pictures, not just files: the render shows the prisms against
  // the background (several colours), the cost image varies with the geometry (it has its
  // legend appended below: one black row, a colour bar of 6 rows, a row of numbers 11 rows
  // tall; no title, which does not fit 40 pixels).
  for (const char* name : {"a.png", "c.png"}) {
    int w = 0, h = 0;
    const std::vector<amalgam::Vec3> px = amalgam::read_image((d / name).string(), w, h);
    EXPECT_EQ(w, 40) << name;
    EXPECT_EQ(h, name[0] == 'c' ? 30 + 1 + 6 + 11 : 30) << name;
    std::set<std::tuple<float, float, float>> colours;
    for (const amalgam::Vec3& c : px) colours.insert({c.x, c.y, c.z});
    EXPECT_GE(colours.size(), 3u) << name << " is (nearly) one colour";
  }
  std::ifstream in(d / "s.json");
  const auto j = nlohmann::json::parse(in);
  for (const char* key : {"renderer", "opacity", "level", "footprint", "scene", "rays", "tests",
                          "per_primary_ray", "time_s"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["renderer"], "scale-sensitive");
  EXPECT_EQ(j["level"], 2);
  const auto& t = j["tests"];
  std::uint64_t levels = 0;
  for (const auto& v : t["by_level"]) levels += v.get<std::uint64_t>();
  EXPECT_EQ(t["primary"].get<std::uint64_t>() + t["shadow"].get<std::uint64_t>(), t["total"]);
  EXPECT_EQ(t["primitive"].get<std::uint64_t>() + t["bounding_volume"].get<std::uint64_t>() +
                t["amalgam"].get<std::uint64_t>(),
            t["total"]);
  EXPECT_EQ(levels, t["total"]);
  EXPECT_EQ(j["rays"]["primary"], 40 * 30 * 2);
  fs::remove_all(d);
}

// The cost image holds, per pixel, the intersection tests of its samples (primary and shadow
// rays) divided by spp: raw in .pfm, so the pixels add up to the stats' total exactly; in .png
// the same counts in false colour, viridis on a log scale from the smallest to the largest
// (colormap.h's log_colours), with a colour bar below the picture.
TEST(Cli, CostImageCountsAddUpToTheStatsAndPngIsViridisOnALogScale) {
  const fs::path d = temp_dir() / "cost";
  fs::create_directories(d);
  const std::string common =
      "render builtin:prisms --set depth=4 --set view=corner --level 2 --width 40 --height 30 "
      "--spp 2 --seed 5 --quiet ";
  ASSERT_EQ(run(common + "--out " + (d / "a.pfm").string() + " --cost-image " +
                (d / "c.pfm").string() + " --stats " + (d / "s.json").string())
                .status,
            0);
  ASSERT_EQ(
      run(common + "--out " + (d / "b.pfm").string() + " --cost-image " + (d / "c.png").string())
          .status,
      0);
  std::ifstream in(d / "s.json");
  const auto j = nlohmann::json::parse(in);
  int w = 0, h = 0;
  const std::vector<amalgam::Vec3> raw = amalgam::read_image((d / "c.pfm").string(), w, h);
  ASSERT_EQ(w, 40);
  ASSERT_EQ(h, 30);
  std::vector<double> counts;
  double sum = 0, lo = 1e300, hi = 0;
  for (const amalgam::Vec3& v : raw) {
    EXPECT_EQ(v.x, v.y);
    EXPECT_EQ(v.x, v.z);
    const double tests = 2.0 * v.x;  // per pixel: tests of its 2 samples / spp
    EXPECT_EQ(tests, std::floor(tests)) << "not a whole number of tests: " << tests;
    EXPECT_GE(v.x, 1.0f) << "every primary ray tests at least the root";
    counts.push_back(v.x);
    sum += tests, lo = std::min<double>(lo, v.x), hi = std::max<double>(hi, v.x);
  }
  EXPECT_EQ(sum, j["tests"]["total"].get<double>())
      << "the cost image's pixels add up to the total";
  EXPECT_LT(lo, hi) << "the cost varies over the image";
  EXPECT_NEAR(j["per_primary_ray"]["mean"].get<double>() * 40 * 30 * 2, sum, 1e-6 * sum);

  const std::vector<amalgam::Vec3> png = amalgam::read_image((d / "c.png").string(), w, h);
  ASSERT_EQ(w, 40);
  ASSERT_EQ(h, 30 + 1 + 6 + 11) << "picture, black row, colour bar, its numbers";
  const std::vector<amalgam::Vec3> expected =
      amalgam::log_colours(counts, amalgam::own_range(counts));
  for (std::size_t i = 0; i < counts.size(); ++i)
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(amalgam::linear_to_srgb(png[i][c]), amalgam::linear_to_srgb(expected[i][c]),
                  0.5 / 255 + 1e-6)
          << "pixel " << i << " channel " << c << " (count " << counts[i] << ")";
  // The most expensive pixel is viridis' top, #fde725 (matplotlib's viridis(1.0)).
  const std::size_t top = std::max_element(counts.begin(), counts.end()) - counts.begin();
  EXPECT_NEAR(amalgam::linear_to_srgb(png[top].x) * 255, 0xfd, 1.0);
  EXPECT_NEAR(amalgam::linear_to_srgb(png[top].y) * 255, 0xe7, 1.0);
  EXPECT_NEAR(amalgam::linear_to_srgb(png[top].z) * 255, 0x25, 1.0);
  fs::remove_all(d);
}

TEST(Cli, StatsToStdout) {
  const fs::path d = temp_dir();
  const CliRun r = run("render builtin:line --width 8 --height 8 --spp 1 --out " +
                       (d / "l.pfm").string() + " --stats -");
  ASSERT_EQ(r.status, 0);
  EXPECT_EQ(nlohmann::json::parse(r.out)["rays"]["primary"], 64);
  fs::remove_all(d);
}

struct BadCase {
  const char* args;
  const char* expect_in_message;
};

TEST(Cli, BadInputExitsTwoWithOneLineAndNoOutput) {
  const fs::path d = temp_dir();
  const std::string out = (d / "never.png").string();
  const BadCase cases[] = {
      {"render builtin:line --renderer fast", "--renderer"},
      {"render builtin:line --opacity maybe", "--opacity"},
      {"render builtin:line --level 9", "--level 9"},
      {"render builtin:line --level -1", "--level"},
      {"render builtin:line --footprint 0", "--footprint"},
      {"render builtin:line --set n=1", "n=1"},
      {"render builtin:line --set bogus=3", "bogus"},
      {"render builtin:line --set depth", "depth"},
      {"render builtin:nothing", "builtin:nothing"},
      {"render /no/such/scene.json", "/no/such/scene.json"},
      {"render builtin:line --width 0", "--width"},
      {"render builtin:prisms --set view=side", "view=side"},
      {"render builtin:line --set n=8 --set depth=30", "2^58"},
      {"render builtin:line --order random", "--order"},
      {"render builtin:line --cost-range 0,10", "--cost-range 0,10"},
      {"render builtin:line --cost-range -1,10", "--cost-range -1,10"},
      {"render builtin:line --cost-range 10,1", "--cost-range 10,1"},
      {"render builtin:line --cost-range 10,10", "--cost-range 10,10"},
      {"render builtin:line --cost-range 10", "--cost-range 10"},
      {"render builtin:line --cost-range 1,2,3", "--cost-range 1,2,3"},
      {"render builtin:line --cost-range a,b", "--cost-range a,b"},
      {"render builtin:line --cost-range 1,inf", "--cost-range 1,inf"},
      {"render builtin:line --level-image x.bmp", "--level-image"},
  };
  for (const BadCase& c : cases) {
    const std::string err = (d / "err.txt").string();
    const CliRun r = run(std::string(c.args) + " --out " + out, err);
    EXPECT_EQ(r.status, 2) << c.args;
    EXPECT_FALSE(fs::exists(out)) << c.args;
    std::ifstream in(err);
    std::string line, rest;
    std::getline(in, line);
    EXPECT_NE(line.find(c.expect_in_message), std::string::npos) << c.args << " -> " << line;
    EXPECT_FALSE(std::getline(in, rest)) << "one line only: " << c.args;
  }
  const CliRun t = run("trace builtin:line --origin 1,2", (d / "err.txt").string());
  EXPECT_EQ(t.status, 2);
  EXPECT_EQ(run("render builtin:line").status, 2) << "--out is required";
  EXPECT_EQ(run("").status, 2) << "a subcommand is required";
  fs::remove_all(d);
}

// Meshes are imported by a helper process (AMALGAM_IMPORT_HELPER names it; here a stand-in,
// tests/io/fake_importer.cpp, that aborts as Assimp 5.2 does on some corrupt files): its crash
// is bad input, one line, exit 2; a helper that cannot be started is a runtime failure, exit 1.
TEST(Cli, AnImporterCrashIsOneLineExitTwoAndAMissingImporterExitOne) {
  const fs::path d = temp_dir();
  const std::string mesh = (d / "tri.obj").string(), out = (d / "never.png").string(),
                    err = (d / "err.txt").string();
  std::ofstream(mesh) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  ::setenv("AMALGAM_IMPORT_HELPER", AMALGAM_FAKE_IMPORTER, 1);
  const CliRun crash = run("render " + mesh + " --out " + out, err);
  ::setenv("AMALGAM_IMPORT_HELPER", (d / "no-such-helper").c_str(), 1);
  const CliRun missing = run("render " + mesh + " --out " + out);
  ::unsetenv("AMALGAM_IMPORT_HELPER");
  EXPECT_EQ(crash.status, 2);
  EXPECT_EQ(missing.status, 1);
  EXPECT_FALSE(fs::exists(out));
  std::ifstream in(err);
  std::string line, rest;
  std::getline(in, line);
  EXPECT_EQ(line,
            "amalgam: " + mesh + ": the importer crashed on this file (signal 6); is it corrupt?");
  EXPECT_FALSE(std::getline(in, rest)) << "one line only";
  EXPECT_EQ(run("render " + mesh + " --width 8 --height 8 --spp 1 --quiet --out " + out).status, 0)
      << "the real helper, found next to amalgam";
  fs::remove_all(d);
}

TEST(Cli, HelpForEverySubcommand) {
  for (const char* sub : {"", "render", "trace", "scenes", "experiment"}) {
    const CliRun r = run(std::string(sub) + " --help");
    EXPECT_EQ(r.status, 0) << sub;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << sub;
  }
  const CliRun v = run("--version");
  EXPECT_EQ(v.status, 0);
  EXPECT_EQ(v.out.rfind("amalgam ", 0), 0u) << v.out;
  EXPECT_EQ(std::count(v.out.begin(), v.out.end(), '\n'), 1) << v.out;
  // experiment --help names every experiment, so a user need not read the docs to pick one.
  const CliRun e = run("experiment --help");
  for (const char* name : {"worst-traditional", "expected", "noise", "linear-cost"})
    EXPECT_NE(e.out.find(name), std::string::npos) << name;
  const CliRun s = run("scenes");
  EXPECT_EQ(s.status, 0);
  for (const char* name : {"builtin:line", "builtin:prisms", "builtin:poisson", "builtin:demo"})
    EXPECT_NE(s.out.find(name), std::string::npos) << name;
}

/// The names in directory `d`, sorted.
std::vector<std::string> entries(const fs::path& d) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

using amalgam::test::slurp;

/// The lines of `err_file`.
std::vector<std::string> lines_of(const fs::path& err_file) {
  std::ifstream in(err_file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// A write that fails half-way (an injected error: the file size limit of `ulimit -f`, which
// binds root too, with SIGXFSZ ignored so that write(2) returns EFBIG): exit 1, an error naming
// the image, the previous file intact byte for byte, no temporary left; for every image format.
TEST(Cli, AWriteFailingHalfWayLeavesThePreviousFileIntact) {
  const fs::path d = temp_dir() / "halfway";
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string err = (temp_dir() / "halfway-err.txt").string();
  for (const char* ext : {"pfm", "png", "exr"}) {
    SCOPED_TRACE(ext);
    const fs::path out = d / (std::string("x.") + ext);
    std::ofstream(out, std::ios::binary) << "the previous " << ext;
    // 128 x 128 noisy pixels: far more than the 4 KiB allowed, whatever the compression.
    const std::string cmd = "bash -c \"trap '' XFSZ; ulimit -f 4; exec " +
                            std::string(AMALGAM_BINARY) +
                            " render builtin:prisms --set depth=6 --width 128 --height 128 "
                            "--spp 1 --quiet --out " +
                            out.string() + "\" 2>" + err;
    const int st = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(st));
    EXPECT_EQ(WEXITSTATUS(st), 1);
    // The first line names the image and why; a renderer that goes on to save the finished
    // render in a checkpoint, and to list what was not written, may add lines of its own.
    const std::vector<std::string> lines = lines_of(err);
    ASSERT_GE(lines.size(), 1u);
    EXPECT_EQ(lines[0].rfind("amalgam: " + out.string() + ": ", 0), 0u) << lines[0];
    for (const std::string& l : lines) EXPECT_EQ(l.rfind("amalgam: ", 0), 0u) << l;
    EXPECT_EQ(slurp(out), std::string("the previous ") + ext);
    EXPECT_EQ(entries(d).size(), 1u) << "a temporary was left: " << entries(d).back();
    fs::remove(out);
  }
  // The same command without the limit succeeds: the limit is what failed it.
  const fs::path out = d / "x.pfm";
  EXPECT_EQ(run("render builtin:prisms --set depth=6 --width 128 --height 128 --spp 1 --quiet "
                "--out " +
                out.string())
                .status,
            0);
  EXPECT_EQ(fs::file_size(out), std::string("PF\n128 128\n-1.0\n").size() + 128u * 128u * 12u);
  fs::remove_all(d);
}

}  // namespace cli
}  // namespace

namespace {
namespace cli {  // per file: the tests are compiled in batches

TEST(CliLimits, MaxMemoryFailsEarlyWithAClearMessage) {
  const std::string err = (temp_dir() / "mem.txt").string();
  const std::string out = (temp_dir() / "mem.png").string();
  const CliRun r =
      run("render builtin:line --width 20000 --height 20000 --max-memory 100M --out " + out, err);
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(out));
  const std::string line = first_line(err);
  EXPECT_NE(line.find("--max-memory"), std::string::npos) << line;
  EXPECT_NE(line.find("GiB"), std::string::npos) << line;
}

// Subdivision is checked against the limit before it is done: Wuson.ply subdivided 6 times
// (1.5e7 triangles, 700 MiB of them alone) with --max-memory 100M used to be refused only after
// the subdivision, at a 906 MB peak and 3-4 s; now at once, naming the key.
TEST(CliLimits, MaxMemoryRefusesASubdivisionBeforeDoingIt) {
  const fs::path d = temp_dir();
  {
    std::ofstream f(d / "fine.json");
    f << R"({"meshes": [{"file": "/usr/share/assimp/models/PLY/Wuson.ply", "subdivide": 6}]})";
  }
  const std::string out = (d / "fine.png").string(), err = (d / "err.txt").string();
  const auto t0 = std::chrono::steady_clock::now();
  const CliRun r = run("render " + (d / "fine.json").string() +
                           " --width 8 --height 8 --spp 1 --max-memory 100M --out " + out,
                       err);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(out));
  const std::string line = first_line(err);
  EXPECT_NE(line.find("/meshes/0/subdivide: subdividing 6 times gives"), std::string::npos) << line;
  EXPECT_NE(line.find("more than --max-memory 100.0 MiB"), std::string::npos) << line;
  fs::remove_all(d);
}

TEST(CliLimits, MaxMemoryCountsInstancedScenes) {
  // 100,000 instances of Wuson.ply (3.7e8 triangles, kept as instances): about 40 MiB by the
  // estimate (MemoryModel), refused before building with 30 MiB.
  const fs::path d = temp_dir();
  {
    std::ofstream f(d / "many.json");
    f << R"({"meshes": [{"name": "w", "file": "/usr/share/assimp/models/PLY/Wuson.ply"}],
             "instances": [{"mesh": "w", "grid": {"nx": 400, "nz": 250, "spacing": 2}}]})";
  }
  const std::string out = (d / "many.png").string(), err = (d / "err.txt").string();
  const CliRun r = run("render " + (d / "many.json").string() +
                           " --width 8 --height 8 --spp 1 --max-memory 30M --out " + out,
                       err);
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(out));
  const std::string line = first_line(err);
  EXPECT_NE(line.find("the scene needs about"), std::string::npos) << line;
  // With room for it, the same scene renders.
  const CliRun ok = run("render " + (d / "many.json").string() +
                        " --width 8 --height 8 --spp 1 --max-memory 1G --quiet --out " + out);
  EXPECT_EQ(ok.status, 0);
  EXPECT_TRUE(fs::exists(out));
  fs::remove_all(d);
}

/// Starts `cmd` (its stdout read later by `finish`): several renders run side by side.
FILE* start(const std::string& cmd) {
  return popen(cmd.c_str(), "r");
}

std::string finish(FILE* p) {
  std::string out;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  pclose(p);
  return out;
}

// The progress bar (with its ETA) appears on a terminal after a second, never on a pipe, and
// --quiet turns it off on a terminal too (with the closing summary line). The three renders run
// side by side, so each lasts the same (> 1 s: long enough for the bar to show).
// On a terminal, a scene that takes a while to load shows what it is doing (reading, building and
// baking), here at once (AMALGAM_PROGRESS_AFTER=0 instead of after a second); the line is ended
// before the render's bar; not on a pipe.
TEST(CliLimits, LoadPhasesShownOnATerminal) {
  const fs::path d = temp_dir();
  const std::string args = "AMALGAM_PROGRESS_AFTER=0 " + std::string(AMALGAM_BINARY) + " render " +
                           AMALGAM_SOURCE_DIR +
                           "/scenes/spider-field.json --width 32 --height 24 --spp 1 --out ";
  ASSERT_EQ(std::system("command -v script >/dev/null 2>&1"), 0) << "script(1) (bsdutils) missing";
  const std::string tty_out =
      finish(start("script -qec '" + args + (d / "t.pfm").string() + "' /dev/null"));
  const std::string plain_out = finish(start(args + (d / "p.pfm").string() + " 2>&1"));
  EXPECT_NE(tty_out.find("building and baking"), std::string::npos) << tty_out;
  const std::size_t wrote = tty_out.find("amalgam: wrote");
  ASSERT_NE(wrote, std::string::npos) << tty_out;
  EXPECT_LT(tty_out.rfind("building and baking"), wrote);
  EXPECT_TRUE(wrote > 0 && tty_out[wrote - 1] == '\n') << tty_out;
  EXPECT_EQ(plain_out.find("building and baking"), std::string::npos) << plain_out;
}

TEST(CliLimits, ProgressBarOnlyOnATerminal) {
  const fs::path d = temp_dir();
  const std::string args = std::string(AMALGAM_BINARY) +
                           " render builtin:prisms --set depth=8 --set view=corner --width 256 "
                           "--height 256 --spp 20 --threads 1 --out ";
  ASSERT_EQ(std::system("command -v script >/dev/null 2>&1"), 0) << "script(1) (bsdutils) missing";
  // A pseudo-terminal (util-linux `script`) for the second and third.
  FILE* plain = start(args + (d / "p.pfm").string() + " 2>&1");
  FILE* tty = start("script -qec '" + args + (d / "t.pfm").string() + "' /dev/null");
  FILE* quiet = start("script -qec '" + args + (d / "q.pfm").string() + " --quiet' /dev/null");
  const std::string plain_out = finish(plain), tty_out = finish(tty), quiet_out = finish(quiet);
  // Not a terminal: no progress bar.
  EXPECT_EQ(plain_out.find("ETA"), std::string::npos) << plain_out;
  // A terminal: the bar with its ETA.
  EXPECT_NE(tty_out.find("ETA"), std::string::npos) << tty_out;
  EXPECT_NE(tty_out.find("spp"), std::string::npos) << tty_out;
  EXPECT_NE(tty_out.find("amalgam: wrote"), std::string::npos) << tty_out;
  // The summary starts a line of its own, after the bar's line is ended.
  EXPECT_NE(tty_out.find("\namalgam: wrote"), std::string::npos) << tty_out;
  // A terminal with --quiet: nothing at all, and the image is still written.
  EXPECT_EQ(quiet_out.find("ETA"), std::string::npos) << quiet_out;
  EXPECT_EQ(quiet_out.find("amalgam: wrote"), std::string::npos) << quiet_out;
  EXPECT_EQ(quiet_out.find_first_not_of("\r\n"), std::string::npos) << quiet_out;
  for (const char* f : {"p.pfm", "t.pfm", "q.pfm"}) EXPECT_TRUE(fs::exists(d / f)) << f;
  fs::remove_all(d);
}

}  // namespace cli
}  // namespace

// End-to-end tests of the `amalgam` binary: the outside contract of CONTRACT.md.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status;
  std::string out;
};

// Runs the binary with `args` (a shell-quoted string); stdout captured, stderr to err_file.
CliRun run(const std::string& args, const std::string& err_file = "/dev/null") {
  const std::string cmd = std::string(AMALGAM_BINARY) + " " + args + " 2>" + err_file;
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("amalgam-cli-" + std::to_string(getpid()));
  fs::create_directories(d);
  return d;
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

TEST(Cli, RenderWritesImageCostImageAndStats) {
  const fs::path d = temp_dir();
  const CliRun r =
      run("render builtin:prisms --set depth=4 --level 2 --width 40 --height 30 --spp 2 "
          "--out " +
          (d / "a.png").string() + " --cost-image " + (d / "c.png").string() + " --stats " +
          (d / "s.json").string());
  ASSERT_EQ(r.status, 0);
  EXPECT_GT(fs::file_size(d / "a.png"), 100u);
  EXPECT_GT(fs::file_size(d / "c.png"), 100u);
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
  const CliRun s = run("scenes");
  EXPECT_EQ(s.status, 0);
  for (const char* name : {"builtin:line", "builtin:prisms", "builtin:poisson", "builtin:demo"})
    EXPECT_NE(s.out.find(name), std::string::npos) << name;
}

}  // namespace

namespace {

TEST(CliLimits, MaxMemoryFailsEarlyWithAClearMessage) {
  const std::string err = (temp_dir() / "mem.txt").string();
  const std::string out = (temp_dir() / "mem.png").string();
  const CliRun r =
      run("render builtin:line --width 20000 --height 20000 --max-memory 100M --out " + out, err);
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(out));
  std::ifstream in(err);
  std::string line;
  std::getline(in, line);
  EXPECT_NE(line.find("--max-memory"), std::string::npos) << line;
  EXPECT_NE(line.find("GiB"), std::string::npos) << line;
}

TEST(CliLimits, MaxMemoryCountsInstancedScenes) {
  // 100,000 instances of Wuson.ply (3.7e8 triangles, kept as instances): about 21 MB of
  // per-instance data beyond the film's 64 MiB allowance, so 80 MiB is too little.
  const fs::path d = temp_dir();
  {
    std::ofstream f(d / "many.json");
    f << R"({"meshes": [{"name": "w", "file": "/usr/share/assimp/models/PLY/Wuson.ply"}],
             "instances": [{"mesh": "w", "grid": {"nx": 400, "nz": 250, "spacing": 2}}]})";
  }
  const std::string out = (d / "many.png").string(), err = (d / "err.txt").string();
  const CliRun r = run("render " + (d / "many.json").string() +
                           " --width 8 --height 8 --spp 1 --max-memory 80M --out " + out,
                       err);
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(out));
  std::ifstream in(err);
  std::string line;
  std::getline(in, line);
  EXPECT_NE(line.find("scene and film need"), std::string::npos) << line;
  // With room for it, the same scene renders.
  const CliRun ok = run("render " + (d / "many.json").string() +
                        " --width 8 --height 8 --spp 1 --max-memory 1G --quiet --out " + out);
  EXPECT_EQ(ok.status, 0);
  EXPECT_TRUE(fs::exists(out));
  fs::remove_all(d);
}

TEST(CliLimits, ProgressBarOnlyOnATerminal) {
  const fs::path d = temp_dir();
  const std::string args = std::string(AMALGAM_BINARY) +
                           " render builtin:prisms --set depth=8 --set view=corner --width 256 "
                           "--height 256 --spp 20 --threads 1 --out " +
                           (d / "p.pfm").string();
  // Not a terminal: no progress bar.
  const CliRun plain = run(args.substr(std::string(AMALGAM_BINARY).size()) + " 2>&1");
  EXPECT_EQ(plain.out.find("ETA"), std::string::npos) << plain.out;
  // A pseudo-terminal (util-linux `script`): the bar with its ETA appears after a second.
  ASSERT_EQ(std::system("command -v script >/dev/null 2>&1"), 0) << "script(1) (bsdutils) missing";
  FILE* p = popen(("script -qec '" + args + "' /dev/null").c_str(), "r");
  std::string tty;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) tty.append(buf, n);
  pclose(p);
  EXPECT_NE(tty.find("ETA"), std::string::npos) << tty;
  EXPECT_NE(tty.find("spp"), std::string::npos) << tty;
  fs::remove_all(d);
}

}  // namespace

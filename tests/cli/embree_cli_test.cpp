// `--tracer embree` on the command line: what it refuses (exit 2, one line), what it reports.

#include <gtest/gtest.h>
// OpenEXR 3.1's headers trip -Wunused-parameter under clang.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#pragma GCC diagnostic pop
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_support.h"

namespace {
namespace embree_cli {  // per file: the tests are compiled in batches

namespace fs = std::filesystem;

struct CliResult {
  int status;
  std::string out, err;
};

CliResult run(const std::string& args) {
  const fs::path err = amalgam::test::scratch_dir("amalgam-embree-cli") / "stderr.txt";
  const auto r =
      amalgam::test::run_command(std::string(AMALGAM_BINARY) + " " + args + " 2>" + err.string());
  return {r.status, r.out, amalgam::test::slurp(err)};
}

// Per test process: ctest runs these tests in parallel.
const std::string kOut = (amalgam::test::scratch_dir("amalgam-embree-cli") / "out.pfm").string();
const std::string kRender =
    "render builtin:prisms --set depth=3 --width 16 --height 12 --spp 1 "
    "--quiet --out " +
    kOut;

/// One line on stderr naming `word`, exit 2, no image.
void expect_refused(const std::string& args, const std::string& word) {
  fs::remove(kOut);
  const CliResult r = run(args);
  EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(word), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(kOut)) << args;
}

TEST(CliEmbree, UnknownTracerIsRefused) {
  expect_refused(kRender + " --tracer optix", "--tracer");
}

#if defined(AMALGAM_HAVE_EMBREE)
TEST(CliEmbree, OptionsThatChooseOrBlendAmalgamsAreRefused) {
  const std::string e = kRender + " --tracer embree";
  expect_refused(e + " --renderer scale-sensitive", "--renderer scale-sensitive");
  expect_refused(e + " --level 1", "--level");
  expect_refused(e + " --footprint 2", "--footprint");
  expect_refused(e + " --opacity deterministic", "--opacity deterministic");
  expect_refused(e + " --order sorted", "--order");
  expect_refused(e + " --order unsorted", "--order");
  expect_refused(e + " --cost-image /tmp/amalgam-embree-cost.png", "--cost-image");
  expect_refused("trace builtin:prisms --tracer embree --footprint 2", "--footprint");
  // A builtin too large to list for Embree: refused before any rendering.
  expect_refused("render builtin:line --set depth=30 --tracer embree --quiet --out " + kOut,
                 "primitives");
}

TEST(CliEmbree, RendersAndReportsWhatItMeasured) {
  const CliResult r = run(kRender + " --tracer embree --renderer traditional --stats -");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(kOut));
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["tracer"], "embree");
  EXPECT_EQ(j["renderer"], "traditional");
  EXPECT_TRUE(j["tests"].is_null());
  EXPECT_TRUE(j["per_primary_ray"].is_null());
  EXPECT_TRUE(j["opacity"].is_null());
  EXPECT_TRUE(j["order"].is_null());
  EXPECT_EQ(j["rays"]["primary"], 16 * 12);
  EXPECT_GE(j["time_s"]["embree_build"].get<double>(), 0.0);
  EXPECT_GE(j["time_s"]["render"].get<double>(), 0.0);
  const CliResult t = run("trace builtin:line --tracer embree");
  ASSERT_EQ(t.status, 0) << t.err;
  const nlohmann::json h = nlohmann::json::parse(t.out);
  EXPECT_EQ(h["hit"]["object"]["kind"], "primitive");
  EXPECT_EQ(h["rays"]["primary"], 1);
  // Its EXR has every layer but the cost (Embree counts no tests), rather than a cost of zeros.
  const std::string exr = (amalgam::test::scratch_dir("amalgam-embree-cli") / "out.exr").string();
  const CliResult e =
      run("render builtin:prisms --set depth=3 --width 16 --height 12 --spp 1 --tracer embree "
          "--renderer traditional --quiet --out " +
          exr);
  ASSERT_EQ(e.status, 0) << e.err;
  {
    Imf::InputFile in(exr.c_str());
    const Imf::ChannelList& ch = in.header().channels();
    EXPECT_EQ(ch.findChannel("cost.Y"), nullptr);
    for (const char* name : {"R", "G", "B", "level.Y", "Z", "N.X", "albedo.R"})
      EXPECT_NE(ch.findChannel(name), nullptr) << name;
  }
  fs::remove(exr);
  // amalgam's tracer says so too.
  const CliResult a = run(kRender + " --stats -");
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(nlohmann::json::parse(a.out)["tracer"], "amalgam");
  fs::remove(kOut);
}
#else
TEST(CliEmbree, ABuildWithoutEmbreeSaysSo) {
  expect_refused(kRender + " --tracer embree", "built without Embree");
}
#endif

}  // namespace embree_cli
}  // namespace

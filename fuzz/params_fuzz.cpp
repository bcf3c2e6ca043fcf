/// libFuzzer target: the shared command-line options (CLI11 + `CommonOptions`, as in
/// apps/amalgam), `--set key=value` parsing (`Params`), `parse_vec3` (--origin/--direction),
/// and building builtin scenes with the fuzzed parameters (`load_scene("builtin:...")` and
/// `check_options`). Nothing is rendered: builtins are implicit, so valid huge scenes are
/// cheap to build but not to render.
///
/// Input: one command-line argument per line (the first is the SCENE), e.g.
///   builtin:prisms\n--set\ndepth=3\n--level\n2
/// A SCENE that is not builtin:NAME is replaced by builtin:prisms (no file access).
///
/// Run: scripts/fuzz.sh, or build-asan/params_fuzz -max_total_time=3600 fuzz/corpus/params

#include <CLI/CLI.hpp>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "../apps/amalgam/common.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace amalgam;
  std::vector<std::string> args{"amalgam"};
  std::string cur;
  for (std::size_t i = 0; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n') {
      args.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) args.push_back(cur);
  if (args.size() > 64) return 0;

  for (std::size_t i = 1; i < args.size(); ++i) {
    try {
      (void)cli::parse_vec3(args[i], "--origin");
    } catch (const InputError&) {
    }
  }

  CLI::App app("fuzz");
  cli::CommonOptions common;
  common.add_to(app);
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::Error&) {
    return 0;  // CLI11 reports bad usage (exit status 2 in the real binary)
  }
  try {
    common.finish();
    if (common.scene.rfind("builtin:", 0) != 0) common.scene = "builtin:prisms";
    const Params params = common.params();
    const LoadedScene scene = load_scene(common.scene, params);
    check_options(scene, common.options);
    (void)scene.info();
  } catch (const InputError&) {
  }
  return 0;
}

/// libFuzzer target: the scene JSON parser (`parse_scene_json`), then building a hierarchy
/// from what it accepted and rendering a 4 x 4 image of it. Any exception other than
/// InputError, any sanitizer report, any hang is a bug: bad input must become one clear
/// InputError.
///
/// Run: scripts/fuzz.sh (short, CI) or, for a long run,
///   build-asan/scene_json_fuzz -max_total_time=3600 fuzz/corpus/scene_json

#include <cstddef>
#include <cstdint>
#include <string>

#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace amalgam;
  const std::string text(reinterpret_cast<const char*>(data), size);
  SceneFileConfig config;
  config.max_triangles = 20'000;  // keeps instancing seeds (Wuson grids) fast per input
  config.max_instances = 20'000;  // likewise: a grid of 42 x 66,663 instances (2.8 million,
                                  // allowed by default) took over 20 s under ASan (long run)
  try {
    // Relative mesh paths resolve against /nonexistent: only absolute paths (the seeds'
    // /usr/share/assimp/models meshes) reach the importer.
    SceneDescription d = parse_scene_json(text, "/nonexistent/fuzz.json", config);
    Environment env = std::move(d.env);
    LoadedScene s{"fuzz", build_hierarchy(std::move(d)), std::move(env)};
    RenderOptions o;
    o.width = o.height = 4;
    o.spp = 1;
    o.threads = 1;
    (void)render(s, o);
  } catch (const InputError&) {
    // Rejected with a message: fine.
  }
  return 0;
}

/// libFuzzer target: mesh import through our loader (`mesh_scene`: Assimp via `import_mesh`,
/// then the default camera and lights), then building a hierarchy from small results. The
/// first byte picks the file extension (byte % 6: 0 .obj, 1 .ply, 2 .gltf, 3 .glb, 4 .off,
/// 5 .stl; the seeds use the digits '0'..'5'); the rest is the file.
///
/// Run: scripts/fuzz.sh, or build-asan/mesh_fuzz -max_total_time=3600 fuzz/corpus/mesh

#include <cstddef>
#include <cstdint>
#include <string>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/load/load_scene.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace amalgam;
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".obj", ".ply", ".gltf", ".glb", ".off", ".stl"};
  const fuzz::TempFile file("amalgam-mesh-fuzz", kExtensions[data[0] % 6], data + 1, size - 1);
  SceneFileConfig config;
  config.max_triangles = 100'000;
  try {
    SceneDescription d = mesh_scene(file.path(), config);
    if (d.prims.size() <= 5'000) (void)build_explicit(std::move(d.prims), std::move(d.materials));
  } catch (const InputError&) {
  }
  return 0;
}

#pragma once
/// \file Reading triangle meshes with Assimp (OBJ, PLY, glTF 2, and whatever else it reads).
///
/// Assimp 5.2 aborts or crashes on some corrupt files that no header check catches (the fuzzer
/// keeps finding them: tests/fuzz_regressions_test.cpp). So it never runs inside amalgam: each
/// import starts the helper executable `amalgam-import` (apps/amalgam-import, installed next to
/// `amalgam`) with posix_spawn, which is safe from a multi-threaded process, and reads the
/// result from its stdout (io/import_protocol.h). A helper that dies is one InputError.

#include <cstdint>
#include <string>
#include <vector>

#include "amalgam/scene/description.h"

namespace amalgam {

/// A mesh as imported: triangles (node transforms already applied) and one surface per
/// material of the file, in the file's coordinates, with the file's base-colour textures,
/// cameras and lights.
struct ImportedMesh {
  std::vector<Primitive> triangles;  ///< all kTriangle; `material` indexes `materials`
  std::vector<Surface> materials;    ///< never empty; `texture` indexes `textures`
  std::vector<TexCoords> uvs;        ///< per triangle when a material is textured, or empty
  /// Per triangle when the file gives vertex normals for any mesh (or they were generated,
  /// ImportConfig::smooth_normals), else empty; zero for the triangles of meshes without.
  std::vector<VertexNormals> normals;
  std::vector<Texture> textures;         ///< decoded base-colour images (`mean` set)
  std::vector<NamedCamera> cameras;      ///< glTF perspective cameras, in file order
  std::vector<Light> lights;             ///< point and directional lights
  Bbox bounds;                           ///< of `triangles`; never empty
  std::uint64_t dropped_degenerate = 0;  ///< zero-area triangles left out
  std::vector<std::string> warnings;     ///< what Assimp repaired or ignored, one line each
  /// What the file holds that is not rendered (a spot light, emission, a texture that cannot
  /// be read, ...), one line each, naming it: for the user (the CLI prints them).
  std::vector<std::string> dropped;
  /// Every other file the import read (as opened): an OBJ's material library, a glTF's
  /// buffers, textures. Inputs, like the mesh itself, that an output must never replace (the
  /// CLI checks).
  std::vector<std::string> files_read;
};

/// Settings for `import_mesh`.
struct ImportConfig {
  /// More triangles than this is an InputError (before any are copied).
  std::uint64_t max_triangles = 50'000'000;
  /// Bytes the helper may allocate (its RLIMIT_DATA; 0: no limit): an import that needs more
  /// is an InputError naming `limit_name` ("the importer ran out of memory under ..."). Not
  /// applied in a build under AddressSanitizer, whose shadow memory counts against the limit.
  std::uint64_t max_bytes = 0;
  std::string limit_name = "the memory limit";
  /// Generates smooth vertex normals (Assimp's, angle-weighted, split at creases above 80
  /// degrees) for the meshes of the file that have none. Off: such meshes render faceted.
  bool smooth_normals = false;
  /// Seconds the helper may take from its start to the end of its reply, after which it is
  /// killed and the import is an InputError. 0: the environment variable
  /// AMALGAM_IMPORT_TIMEOUT (seconds) if set, else 300 s plus 1 s per MiB of the file.
  double timeout_seconds = 0;
  /// The helper executable that runs Assimp. Empty: the first that exists of the environment
  /// variable AMALGAM_IMPORT_HELPER (if set and not empty); `amalgam-import` in the directory
  /// of the running executable (/proc/self/exe: the installed CLI); the one an installed CMake
  /// package registered (register_import_helper: a program built with find_package(amalgam));
  /// the one in the install's bin directory as seen from the shared object that holds this
  /// code (the installed Python module); the configured install prefix's; the build tree's.
  std::string helper;
};

/// Imports the triangles of `path` with Assimp: faces triangulated, node transforms baked
/// in, points and lines dropped, zero-area triangles dropped. Each material's colour is its
/// base colour factor (glTF 2 `baseColorFactor`) if present, else its diffuse colour; its
/// base-colour (or diffuse) texture, from a file beside the mesh or embedded, is decoded in
/// the helper (io/image_decode.h; one that cannot be read is a line of `dropped`, and the material
/// keeps its colour). glTF cameras and Assimp's point and directional lights are returned
/// (docs/import.md). Throws InputError, one line "<path>: <problem>", when Assimp cannot read the
/// file, when it reports corrupt data it repaired (faces with out-of-range or missing indices,
/// vertex counts that do not fit the primitive mode), when a vertex is NaN or infinite, when
/// no triangle with non-zero area is left, or when the importer crashes on it ("the importer
/// crashed on this file (signal N); is it corrupt?"), when it runs out of `max_bytes` or
/// time (ImportConfig), or when check_mesh_file (io/mesh_check.h) refuses it. Throws RuntimeError
/// when the helper cannot be found or started, or is not a compatible build. Never prints: Assimp's
/// logger stays silent and the helper's stderr goes to /dev/null. Thread-safe: concurrent imports
/// run in separate helpers. A helper never outlives the process that started it.
ImportedMesh import_mesh(const std::string& path, const ImportConfig& config = {});

/// Names the helper of an installed amalgam for ImportConfig::helper's search. The CMake
/// package (find_package(amalgam)) compiles a call into every program that links amalgam::io,
/// with the path of the `amalgam-import` installed beside the package, wherever the install
/// was moved; a program may call it too. Thread-safe; the last call wins.
void register_import_helper(std::string path);

}  // namespace amalgam

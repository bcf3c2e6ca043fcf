#pragma once
/// \file Reading triangle meshes with Assimp (OBJ, PLY, glTF 2, and whatever else it reads).

#include <cstdint>
#include <string>
#include <vector>

#include "amalgam/scene/scene.h"

namespace amalgam {

/// A mesh as imported: triangles (node transforms already applied) and one surface per
/// material of the file, in the file's coordinates.
struct ImportedMesh {
  std::vector<Primitive> triangles;      ///< all kTriangle; `material` indexes `materials`
  std::vector<Surface> materials;        ///< never empty
  Bbox bounds;                           ///< of `triangles`; never empty
  std::uint64_t dropped_degenerate = 0;  ///< zero-area triangles left out
  std::vector<std::string> warnings;     ///< what Assimp repaired or ignored, one line each
};

/// Settings for `import_mesh`.
struct ImportConfig {
  /// More triangles than this is an InputError (before any are copied).
  std::uint64_t max_triangles = 50'000'000;
};

/// Imports the triangles of `path` with Assimp: faces triangulated, node transforms baked
/// in, points and lines dropped, zero-area triangles dropped. Each material's colour is its
/// base colour factor (glTF 2 `baseColorFactor`) if present, else its diffuse colour; textures
/// are ignored. Throws InputError, one line "<path>: <problem>", when Assimp cannot read the
/// file, when it reports corrupt data it repaired (faces with out-of-range or missing indices,
/// vertex counts that do not fit the primitive mode), when a vertex is NaN or infinite, or
/// when no triangle with non-zero area is left. Never prints: Assimp's logger stays silent.
ImportedMesh import_mesh(const std::string& path, const ImportConfig& config = {});

}  // namespace amalgam

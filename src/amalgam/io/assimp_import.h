#pragma once
/// \file The mesh import proper, with Assimp. It runs only in the amalgam-import helper process
/// (apps/amalgam-import), never inside amalgam: Assimp 5.2 aborts or crashes on some corrupt
/// files, and import_mesh (io/mesh_import.h) turns a dead helper into one InputError.

#include <string>

#include "amalgam/io/mesh_import.h"

namespace amalgam {

/// Imports `path` as import_mesh documents (faces triangulated, node transforms baked in,
/// points, lines and zero-area triangles dropped, base or diffuse colours), in this process.
/// Throws InputError "<path>: <problem>" (one line); never prints: Assimp's logger is
/// captured. Not thread-safe (Assimp's logger is process-wide).
ImportedMesh import_with_assimp(const std::string& path, const ImportConfig& config);

/// "<path>: the importer ran out of memory under <config.limit_name> (is the file corrupt?)".
std::string out_of_memory_message(const std::string& path, const ImportConfig& config);

}  // namespace amalgam

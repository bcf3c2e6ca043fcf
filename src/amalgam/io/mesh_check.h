#pragma once
/// \file Checks of a mesh file before Assimp reads it (io/mesh_import.h): what Assimp 5.2
/// trusts, silently repairs, or crashes on.

#include <cstdint>
#include <string>

namespace amalgam {

/// Throws InputError "<path>: <problem>" for what Assimp would read without complaint but
/// wrongly, or only after allocating without bound:
/// - OFF and PLY element counts that the file's size cannot possibly hold (the testmodels'
///   invalid/OutOfMemory.off declares 3.5e11 vertices and takes a minute to fail);
/// - OFF face indices that are not whole numbers below the vertex count (-1, 1.5);
/// - a PLY header (by extension or by content) whose grammar is broken: Assimp 5.2 crashes on
///   some (found by fuzz/mesh_fuzz.cpp; tests/fuzz_regressions_test.cpp);
/// - a binary glTF (`.glb`, or any file starting with `glTF`) whose header or chunks declare
///   more bytes than the file has (Assimp allocates what a chunk declares: 2 GB for a 200-byte
///   file);
/// - glTF JSON (a `.gltf` file or a GLB's JSON chunk) with a `byteOffset` or `byteStride`
///   that is not a non-negative integer (Assimp reads such a member as 0).
/// Other files, and what Assimp itself reports, pass.
void check_mesh_file(const std::string& path);

namespace detail {
/// The glTF part of check_mesh_file, for a file of `size` bytes starting with `magic`.
void check_gltf(const std::string& path, const std::string& ext, const char (&magic)[4],
                std::uint64_t size);
}  // namespace detail

}  // namespace amalgam

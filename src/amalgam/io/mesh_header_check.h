#pragma once
/// \file Checks of a mesh file's text header before Assimp reads it (io/mesh_import.h).

#include <string>

namespace amalgam {

/// Some formats declare element counts in a text header and Assimp trusts them (the
/// testmodels' invalid/OutOfMemory.off declares 3.5e11 vertices and takes a minute to fail):
/// rejects OFF and PLY counts that the file's size cannot possibly hold. For PLY (by extension
/// or by content) also checks the header's grammar, on which Assimp 5.2 crashes when malformed
/// (found by fuzz/mesh_fuzz.cpp; tests/fuzz_regressions_test.cpp). Throws InputError
/// "<path>: <problem>"; other files pass unchecked.
void check_mesh_header(const std::string& path);

}  // namespace amalgam

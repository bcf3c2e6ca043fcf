#pragma once
/// \file How the amalgam-import helper (apps/amalgam-import) returns an import to import_mesh
/// (io/mesh_import.h) over a pipe.
///
/// A reply is: a hello string naming the protocol version and the sizes of the raw records,
/// then a status byte (0: a mesh, 1: an InputError's message). A mesh follows as the counts of
/// triangles, materials, dropped triangles, warnings, texture coordinates, textures, cameras,
/// lights, dropped-feature lines and texture files; the raw arrays (Primitive, Surface, TexCoords,
/// Light and Bbox are trivially copyable, and both ends are built together); each texture as its
/// width, height (32 bits each), wrap modes (a byte each) and RGB bytes; each camera as its name
/// and raw Camera; then the warnings, the dropped-feature lines and the texture files read. An
/// error follows as its message. Strings are a 64-bit length and the bytes.

#include <cstdint>
#include <string>

#include "amalgam/io/mesh_import.h"

namespace amalgam::import_protocol {

/// Writes the reply for a successful import to `fd`. False when the pipe fails.
bool send_mesh(int fd, const ImportedMesh& mesh);

/// Writes the reply for a failed import (`message`: the InputError's what()) to `fd`.
bool send_error(int fd, const std::string& message);

/// One reply as read.
struct Reply {
  enum class Kind {
    kMesh,          ///< `mesh` holds the import
    kError,         ///< `error` holds the InputError's message
    kIncompatible,  ///< the helper speaks another protocol (`error` holds its hello)
    kBroken,        ///< the stream ended early or holds impossible counts (a crash)
  };
  Kind kind = Kind::kBroken;
  ImportedMesh mesh;
  std::string error;
};

/// Textures the helper sends at most (it drops larger ones with a warning): sides up to
/// kMaxTextureSide texels, kMaxTextureBytes of texels in all, kMaxTextures of them.
inline constexpr std::uint32_t kMaxTextureSide = 16384;
inline constexpr std::uint64_t kMaxTextureBytes = std::uint64_t{1} << 30;
inline constexpr std::uint64_t kMaxTextures = 4096;

/// Reads one reply from `fd`. More than `max_triangles` triangles, more than 2^32 materials,
/// texture coordinates for some triangles only, textures beyond the limits above, a texture
/// index out of range or strings beyond 16 MiB are kBroken, so a broken helper cannot make
/// the reader allocate without bound.
Reply receive(int fd, std::uint64_t max_triangles);

}  // namespace amalgam::import_protocol

#pragma once
/// \file Decoding texture images (PNG with libpng, JPEG with libjpeg, EXR with OpenEXR, TGA,
/// BMP, PSD, GIF and HDR with stb_image) for the mesh import
/// helper: it runs only there (apps/amalgam-import), so a corrupt image that crashes a decoder
/// is one failed import, never a crash of amalgam.

#include <cstddef>
#include <cstdint>
#include <string>

#include "amalgam/scene/texture.h"

namespace amalgam {

/// Decodes an image (its format told by its first bytes, not its name) into 8-bit sRGB RGB
/// texels (alpha dropped, grey expanded, 16-bit reduced; the linear colours of EXR and HDR
/// clamped to [0, 1] and encoded). Images with more than `max_texels` texels or a side beyond
/// `max_side` are refused from their header. On failure returns false and sets `why` (one
/// line, e.g. "not an image format amalgam reads (...)", "corrupt PNG data: ...").
bool decode_image(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                  std::uint32_t max_side, Texture& out, std::string& why);

}  // namespace amalgam

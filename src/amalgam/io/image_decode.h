#pragma once
/// \file Decoding texture images (PNG with libpng, JPEG with libjpeg) for the mesh import
/// helper: it runs only there (apps/amalgam-import), so a corrupt image that crashes a decoder
/// is one failed import, never a crash of amalgam.

#include <cstddef>
#include <cstdint>
#include <string>

#include "amalgam/scene/texture.h"

namespace amalgam {

/// Decodes a PNG or JPEG image (told apart by its first bytes) into 8-bit sRGB RGB texels
/// (alpha dropped, grey expanded, 16-bit reduced). Images with more than `max_texels` texels
/// or a side beyond `max_side` are refused. On failure returns false and sets `why` (one
/// line, e.g. "not a PNG or JPEG image", "corrupt PNG data: ...").
bool decode_image(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                  std::uint32_t max_side, Texture& out, std::string& why);

}  // namespace amalgam

#pragma once
/// \file PNG via libpng (io/image.h dispatches here by extension). Failures throw
/// codec::Failure with the reason only (io/codec.h).

#include <string>
#include <utility>
#include <vector>

#include "amalgam/math/vec.h"
#include "amalgam/util/atomic_file.h"

namespace amalgam::codec {

/// Writes 8-bit sRGB RGB with an sRGB chunk and one tEXt chunk per (key, value) of `text`
/// (keys of 1 to 79 Latin-1 characters); pixels as write_image takes them.
void write_png(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels,
               const std::vector<std::pair<std::string, std::string>>& text = {});

/// Reads 8/16-bit grey, grey+alpha, RGB, RGBA or palette PNG (alpha ignored, sRGB decoded).
std::vector<Vec3> read_png(const std::string& path, int& width, int& height);

}  // namespace amalgam::codec

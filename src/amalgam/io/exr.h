#pragma once
/// \file OpenEXR (io/image.h dispatches here by extension). Failures throw codec::Failure with
/// the reason only (io/codec.h), or OpenEXR's own exceptions.

#include <string>
#include <vector>

#include "amalgam/math/vec.h"
#include "amalgam/util/atomic_file.h"

namespace amalgam::codec {

/// Writes half-float RGB (ZIP compression, no alpha channel); values beyond half's range are
/// clamped to +-65504, infinities and NaN kept.
void write_exr(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels);

/// Reads through OpenEXR's RGBA interface (alpha ignored), any data window.
std::vector<Vec3> read_exr(const std::string& path, int& width, int& height);

}  // namespace amalgam::codec

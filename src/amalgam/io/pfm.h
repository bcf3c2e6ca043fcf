#pragma once
/// \file PFM, the portable float map (io/image.h dispatches here by extension). Failures throw
/// codec::Failure with the reason only (io/codec.h).

#include <string>
#include <vector>

#include "amalgam/math/vec.h"
#include "amalgam/util/atomic_file.h"

namespace amalgam::codec {

/// Writes little-endian 32-bit float RGB ("PF", scale -1.0, rows bottom-to-top).
void write_pfm(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels);

/// Reads colour "PF" or grey "Pf", either endianness (the scale's magnitude is ignored).
std::vector<Vec3> read_pfm(const std::string& path, int& width, int& height);

}  // namespace amalgam::codec

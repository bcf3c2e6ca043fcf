#pragma once
/// \file OpenEXR (io/image.h dispatches here by extension). Failures throw codec::Failure with
/// the reason only (io/codec.h), or OpenEXR's own exceptions.

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "amalgam/math/vec.h"
#include "amalgam/util/atomic_file.h"

namespace amalgam::codec {

/// One float32 channel of a multi-channel file: pixel (x, y) is the float at
/// base + (y * width + x) * stride bytes.
struct ExrChannel {
  std::string name;  ///< "R", "Z", "albedo.G", ...
  const float* base = nullptr;
  std::size_t stride = sizeof(float);
};

/// Writes float32 channels (ZIP compression, scan lines top to bottom) with string attributes
/// in the header. Throws Failure on I/O errors.
void write_exr_channels(AtomicFile& out, int width, int height,
                        const std::vector<ExrChannel>& channels,
                        const std::vector<std::pair<std::string, std::string>>& attributes);

/// Writes float32 RGB (ZIP compression, no alpha channel): exact, unlike half (11-bit
/// significand, so integers above 2048 are rounded).
void write_exr(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels,
               const std::vector<std::pair<std::string, std::string>>& attributes = {});

/// Reads the R, G and B channels as float32 (converted from whatever type they are stored in;
/// other channels, e.g. the layers of `render --out x.exr`, are ignored), any data window. A
/// file without R, G and B (e.g. luminance only) is read through OpenEXR's RGBA interface.
std::vector<Vec3> read_exr(const std::string& path, int& width, int& height);
/// The size of an OpenEXR file's data window, from its header alone; false if unreadable.
bool exr_size(const std::string& path, int& width, int& height);

}  // namespace amalgam::codec

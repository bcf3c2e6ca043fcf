#pragma once
/// \file Image files: writing (PNG, PFM, OpenEXR) and reading, by extension. The codecs are
/// png.h, pfm.h and exr.h; false colour is colormap.h.
///
/// Writing is atomic (util/atomic_file.h): on any failure an ImageIoError is thrown and `path`
/// is either left untouched or holds a complete file.

#include <string>
#include <utility>
#include <vector>

#include "amalgam/math/vec.h"
#include "amalgam/util/error.h"

namespace amalgam {

/// Thrown by every function here on failure. what() is one line naming the file and the reason.
/// A RuntimeError (exit status 1): callers that read user-given images and want a bad one to
/// count as bad input convert it to an InputError (as `amalgam compare` does).
struct ImageIoError : RuntimeError {
  using RuntimeError::RuntimeError;
};

/// Whether `path` names an image format write_image writes (.png, .pfm, .exr, any case).
bool is_image_path(const std::string& path);

/// Writes a width x height image; pixel (x, y) is linear_rgb[y * width + x], y = 0 the top row.
/// The format follows the extension of `path` (case-insensitive):
///   .png  8-bit sRGB (values clamped to [0, 1], sRGB transfer function, rounded);
///   .pfm  little-endian 32-bit float RGB ("PF", scale -1.0, rows stored bottom-to-top);
///   .exr  float32 RGB (OpenEXR, ZIP compression, no alpha channel, i.e. opaque).
/// `text` (key, value) pairs are stored as PNG tEXt chunks or OpenEXR string attributes (a PFM
/// has no place for them: they are dropped).
/// Throws ImageIoError for any other extension, for a size mismatch, or on any I/O error.
using ImageText = std::vector<std::pair<std::string, std::string>>;
void write_image(const std::string& path, int width, int height,
                 const std::vector<Vec3>& linear_rgb, const ImageText& text = {});

/// Reads a .png (8/16-bit grey, grey+alpha, RGB, RGBA or palette; alpha is ignored and sRGB
/// is decoded to linear), .pfm (colour "PF" or grey "Pf", either endianness; the magnitude of
/// the scale is ignored) or .exr (its R, G and B channels as float; other layers ignored) file.
/// Sets width and height and returns pixels in the same layout write_image takes. Throws
/// ImageIoError naming the file on any error.
std::vector<Vec3> read_image(const std::string& path, int& width, int& height);

/// The width and height an image's header declares, read without decoding its pixels; false
/// when the header cannot be read (read_image then says why).
bool image_size(const std::string& path, int& width, int& height);

}  // namespace amalgam

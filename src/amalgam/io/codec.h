#pragma once
/// \file What the image codecs (png.h, pfm.h, exr.h) share. Internal to io/: the codecs throw
/// `codec::Failure` carrying the reason only, and image.cpp names the file.

#include <cerrno>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>

namespace amalgam::codec {

/// A codec's failure: what() is the reason only ("not a PNG file"), without the path.
struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The text of an errno value ("No such file or directory").
inline std::string errno_text(int err) {
  return std::error_code(err, std::generic_category()).message();
}

using FilePtr = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

/// `path` opened for binary reading; throws Failure when it cannot be opened.
inline FilePtr open_for_reading(const std::string& path) {
  std::FILE* fp = std::fopen(path.c_str(), "rb");
  if (!fp) throw Failure("cannot open for reading: " + errno_text(errno));
  return FilePtr(fp, &std::fclose);
}

}  // namespace amalgam::codec

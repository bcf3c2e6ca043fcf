#pragma once
/// \file What the image codecs (png.h, pfm.h, exr.h) share. Internal to io/: the codecs throw
/// `codec::Failure` carrying the reason only, and image.cpp names the file.

#include <unistd.h>

#include <cerrno>
#include <cstdint>
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

/// Refuses an image whose decoding needs more bytes (`bytes_per_pixel` for each of width x
/// height pixels) than this machine's physical memory, before anything is allocated: a file of
/// a few hundred bytes may claim 100000 x 100000 pixels, which ended in std::bad_alloc (or in
/// the machine swapping) instead of a message.
inline void check_fits_in_memory(std::uint64_t width, std::uint64_t height,
                                 std::uint64_t bytes_per_pixel) {
  const long double need = static_cast<long double>(width) * static_cast<long double>(height) *
                           static_cast<long double>(bytes_per_pixel);
  const long double memory = static_cast<long double>(sysconf(_SC_PHYS_PAGES)) *
                             static_cast<long double>(sysconf(_SC_PAGE_SIZE));
  if (need <= memory) return;
  char text[160];
  std::snprintf(text, sizeof text,
                "%llu x %llu pixels: decoding them needs %.1Lf GiB, more than this machine's "
                "memory (%.1Lf GiB)",
                static_cast<unsigned long long>(width), static_cast<unsigned long long>(height),
                need / (1024.0L * 1024 * 1024), memory / (1024.0L * 1024 * 1024));
  throw Failure(text);
}

}  // namespace amalgam::codec

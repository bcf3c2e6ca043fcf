#include "amalgam/io/image.h"

#include <cctype>
#include <cstddef>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>

#include "amalgam/io/exr.h"
#include "amalgam/io/pfm.h"
#include "amalgam/io/png.h"
#include "amalgam/util/atomic_file.h"

namespace amalgam {
namespace {

enum class Format { kPng, kPfm, kExr };

Format image_format(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return Format::kPng;
  if (ext == ".pfm") return Format::kPfm;
  if (ext == ".exr") return Format::kExr;
  throw ImageIoError(path + ": unsupported image format '" + ext +
                     "' (expected .png, .exr or .pfm)");
}

}  // namespace

bool is_image_path(const std::string& path) {
  try {
    (void)image_format(path);
    return true;
  } catch (const ImageIoError&) {
    return false;
  }
}

void write_image(const std::string& path, int width, int height,
                 const std::vector<Vec3>& linear_rgb, const ImageText& text) {
  const Format format = image_format(path);
  if (width <= 0 || height <= 0)
    throw ImageIoError(path + ": invalid image size " + std::to_string(width) + "x" +
                       std::to_string(height));
  if (linear_rgb.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    throw ImageIoError(path + ": " + std::to_string(linear_rgb.size()) + " pixels given for a " +
                       std::to_string(width) + "x" + std::to_string(height) + " image");
  write_atomically<ImageIoError>(path, [&](AtomicFile& out) {
    switch (format) {
      case Format::kPng:
        codec::write_png(out, width, height, linear_rgb, text);
        break;
      case Format::kPfm:
        codec::write_pfm(out, width, height, linear_rgb);
        break;
      case Format::kExr:
        codec::write_exr(out, width, height, linear_rgb, text);
        break;
    }
  });
}

std::vector<Vec3> read_image(const std::string& path, int& width, int& height) {
  const Format format = image_format(path);
  try {
    switch (format) {
      case Format::kPng:
        return codec::read_png(path, width, height);
      case Format::kPfm:
        return codec::read_pfm(path, width, height);
      case Format::kExr:
        return codec::read_exr(path, width, height);
    }
  } catch (const std::bad_alloc&) {
    throw ImageIoError(path + ": not enough memory to decode it");
  } catch (const std::exception& e) {
    throw ImageIoError(path + ": " + one_line(e.what(), std::string::npos));
  }
  throw ImageIoError(path + ": unknown image format");
}

bool image_size(const std::string& path, int& width, int& height) {
  try {
    const Format format = image_format(path);
    if (format == Format::kExr) return codec::exr_size(path, width, height);
    std::ifstream in(path, std::ios::binary);
    unsigned char head[64] = {};
    in.read(reinterpret_cast<char*>(head), sizeof head);
    const std::size_t n = static_cast<std::size_t>(in.gcount());
    if (format == Format::kPng) {
      // The signature, then the IHDR chunk: its length, "IHDR", width and height big-endian.
      static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
      if (n < 24 || std::memcmp(head, kSignature, 8) != 0 || std::memcmp(head + 12, "IHDR", 4))
        return false;
      const auto be32 = [&](int at) {
        return std::uint32_t{head[at]} << 24 | std::uint32_t{head[at + 1]} << 16 |
               std::uint32_t{head[at + 2]} << 8 | std::uint32_t{head[at + 3]};
      };
      if (be32(16) == 0 || be32(16) > 0x7fffffff || be32(20) == 0 || be32(20) > 0x7fffffff)
        return false;
      width = static_cast<int>(be32(16)), height = static_cast<int>(be32(20));
      return true;
    }
    // PFM: "PF" or "Pf", then the width and height as text.
    std::istringstream text(std::string(reinterpret_cast<const char*>(head), n));
    std::string magic;
    long long w = 0, h = 0;
    if (!(text >> magic >> w >> h) || (magic != "PF" && magic != "Pf") || w <= 0 || h <= 0 ||
        w > 0x7fffffff || h > 0x7fffffff)
      return false;
    width = static_cast<int>(w), height = static_cast<int>(h);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace amalgam

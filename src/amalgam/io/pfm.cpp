#include "amalgam/io/pfm.h"

#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "amalgam/io/codec.h"

namespace amalgam::codec {
namespace {

std::uint32_t byte_swap(std::uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

}  // namespace

void write_pfm(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels) {
  const std::string header =
      "PF\n" + std::to_string(width) + " " + std::to_string(height) + "\n-1.0\n";
  out.write(header.data(), header.size());
  std::vector<std::uint32_t> row(static_cast<std::size_t>(width) * 3);
  for (int y = height - 1; y >= 0; --y) {  // PFM stores the bottom row first
    const Vec3* src = pixels.data() + static_cast<std::size_t>(y) * width;
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) {
        std::uint32_t bits = std::bit_cast<std::uint32_t>(src[x][c]);
        if constexpr (std::endian::native == std::endian::big) bits = byte_swap(bits);
        row[3 * static_cast<std::size_t>(x) + c] = bits;
      }
    out.write(row.data(), row.size() * sizeof(std::uint32_t));
  }
}

std::vector<Vec3> read_pfm(const std::string& path, int& width, int& height) {
  std::string data;
  {
    FilePtr fp = open_for_reading(path);
    char chunk[1 << 16];
    std::size_t n;
    while ((n = std::fread(chunk, 1, sizeof chunk, fp.get())) > 0) data.append(chunk, n);
    if (std::ferror(fp.get())) throw Failure("read failed: " + errno_text(errno));
  }
  const auto is_space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  if (data.size() < 3 || data[0] != 'P' || (data[1] != 'F' && data[1] != 'f') || !is_space(data[2]))
    throw Failure("not a PFM file (expected a 'PF' or 'Pf' header)");
  const int channels = data[1] == 'F' ? 3 : 1;
  std::size_t pos = 2;
  const auto token = [&]() {
    while (pos < data.size() && is_space(data[pos])) ++pos;
    const std::size_t begin = pos;
    while (pos < data.size() && !is_space(data[pos])) ++pos;
    return data.substr(begin, pos - begin);
  };
  const auto dimension = [&](const std::string& t) {
    if (t.empty() || t.size() > 9 || t.find_first_not_of("0123456789") != std::string::npos ||
        std::stoi(t) <= 0)
      throw Failure("invalid PFM header: bad dimension '" + t + "'");
    return std::stoi(t);
  };
  const int w = dimension(token());
  const int h = dimension(token());
  const std::string scale_text = token();
  char* end = nullptr;
  const double scale = std::strtod(scale_text.c_str(), &end);
  if (scale_text.empty() || *end != '\0' || !std::isfinite(scale) || scale == 0.0)
    throw Failure("invalid PFM header: bad scale '" + scale_text + "'");
  // Exactly one whitespace character ends the header (tolerate a CR LF pair).
  if (pos >= data.size()) throw Failure("truncated PFM file");
  if (data[pos] == '\r' && pos + 1 < data.size() && data[pos + 1] == '\n') ++pos;
  ++pos;

  const std::uint64_t count = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
  const std::uint64_t need = count * static_cast<std::uint64_t>(channels) * 4;
  if (data.size() - pos < need)
    throw Failure("truncated PFM pixel data (expected " + std::to_string(need) + " bytes, found " +
                  std::to_string(data.size() - pos) + ")");
  const bool swap = (scale < 0) != (std::endian::native == std::endian::little);
  const char* raster = data.data() + pos;
  const auto value = [&](std::uint64_t index) {
    std::uint32_t bits;
    std::memcpy(&bits, raster + 4 * index, 4);
    return std::bit_cast<float>(swap ? byte_swap(bits) : bits);
  };
  std::vector<Vec3> pixels(count);
  for (int y = 0; y < h; ++y) {
    const std::uint64_t file_row = static_cast<std::uint64_t>(h - 1 - y);  // bottom row first
    for (int x = 0; x < w; ++x) {
      const std::uint64_t i = (file_row * static_cast<std::uint64_t>(w) + x) * channels;
      Vec3& out = pixels[static_cast<std::size_t>(y) * w + x];
      if (channels == 3)
        out = {value(i), value(i + 1), value(i + 2)};
      else
        out.x = out.y = out.z = value(i);
    }
  }
  width = w;
  height = h;
  return pixels;
}

}  // namespace amalgam::codec

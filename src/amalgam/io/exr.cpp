#include "amalgam/io/exr.h"

// OpenEXR 3.1's headers trip -Wunused-parameter under clang when not included as system headers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfRgba.h>
#include <ImfRgbaFile.h>
#include <ImfStdIO.h>
#pragma GCC diagnostic pop
#include <sys/types.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "amalgam/io/codec.h"

namespace amalgam::codec {
namespace {

/// An Imf::OStream over a C stream. Failures throw and are also remembered, because OpenEXR
/// swallows exceptions raised while it finishes the file in RgbaOutputFile's destructor.
class StdioOStream final : public Imf::OStream {
 public:
  StdioOStream(std::FILE* fp, const char* name) : Imf::OStream(name), fp_(fp) {}
  void write(const char c[], int n) override {
    if (n > 0 && std::fwrite(c, 1, static_cast<std::size_t>(n), fp_) != static_cast<std::size_t>(n))
      fail("write failed: " + errno_text(errno));
  }
  std::uint64_t tellp() override {
    const off_t p = ::ftello(fp_);
    if (p < 0) fail("cannot query file position: " + errno_text(errno));
    return static_cast<std::uint64_t>(p);
  }
  void seekp(std::uint64_t pos) override {
    if (::fseeko(fp_, static_cast<off_t>(pos), SEEK_SET) != 0)
      fail("cannot seek: " + errno_text(errno));
  }
  const std::string& error() const { return error_; }

 private:
  void fail(const std::string& why) {
    if (error_.empty()) error_ = why;
    throw Failure(why);
  }
  std::FILE* fp_;
  std::string error_;
};

}  // namespace

void write_exr(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels) {
  constexpr float kHalfMax = 65504.0f;
  const auto to_half = [&](float v) {
    return half(std::isfinite(v) ? std::clamp(v, -kHalfMax, kHalfMax) : v);
  };
  std::vector<Imf::Rgba> rgba(pixels.size());
  for (std::size_t i = 0; i < pixels.size(); ++i)
    rgba[i] =
        Imf::Rgba(to_half(pixels[i].x), to_half(pixels[i].y), to_half(pixels[i].z), half(1.0f));
  StdioOStream stream(out.stream(), out.temp_path().c_str());
  {
    Imf::Header header(width, height);
    Imf::RgbaOutputFile file(stream, header, Imf::WRITE_RGB);
    file.setFrameBuffer(rgba.data(), 1, static_cast<std::size_t>(width));
    file.writePixels(height);
  }  // the destructor writes the line offset table
  if (!stream.error().empty()) throw Failure(stream.error());
}

std::vector<Vec3> read_exr(const std::string& path, int& width, int& height) {
  std::ifstream is(path, std::ios::binary);
  if (!is) throw Failure("cannot open for reading: " + errno_text(errno));
  Imf::StdIFStream stream(is, path.c_str());
  Imf::RgbaInputFile file(stream);
  const Imath::Box2i dw = file.dataWindow();
  const std::int64_t w = static_cast<std::int64_t>(dw.max.x) - dw.min.x + 1;
  const std::int64_t h = static_cast<std::int64_t>(dw.max.y) - dw.min.y + 1;
  if (w <= 0 || h <= 0 || w > 0x7fffffff || h > 0x7fffffff)
    throw Failure("invalid OpenEXR data window");
  std::vector<Imf::Rgba> rgba(static_cast<std::size_t>(w * h));
  // OpenEXR addresses the frame buffer by absolute pixel coordinates.
  const std::ptrdiff_t origin =
      -static_cast<std::ptrdiff_t>(dw.min.x) -
      static_cast<std::ptrdiff_t>(dw.min.y) * static_cast<std::ptrdiff_t>(w);
  file.setFrameBuffer(rgba.data() + origin, 1, static_cast<std::size_t>(w));
  file.readPixels(dw.min.y, dw.max.y);
  std::vector<Vec3> pixels(rgba.size());
  for (std::size_t i = 0; i < rgba.size(); ++i)
    pixels[i] = {float(rgba[i].r), float(rgba[i].g), float(rgba[i].b)};
  width = static_cast<int>(w);
  height = static_cast<int>(h);
  return pixels;
}

}  // namespace amalgam::codec

#include "amalgam/io/exr.h"

// OpenEXR 3.1's headers trip -Wunused-parameter under clang when not included as system headers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfRgba.h>
#include <ImfRgbaFile.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>
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

void write_exr_channels(AtomicFile& out, int width, int height,
                        const std::vector<ExrChannel>& channels,
                        const std::vector<std::pair<std::string, std::string>>& attributes) {
  StdioOStream stream(out.stream(), out.temp_path().c_str());
  {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
    Imf::FrameBuffer fb;
    for (const ExrChannel& c : channels) {
      header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
      // OpenEXR takes a non-const base; it only reads from it when writing.
      fb.insert(c.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(c.base)),
                                   c.stride, c.stride * static_cast<std::size_t>(width)));
    }
    Imf::OutputFile file(stream, header);
    file.setFrameBuffer(fb);
    file.writePixels(height);
  }  // the destructor writes the line offset table
  if (!stream.error().empty()) throw Failure(stream.error());
}

void write_exr(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels,
               const std::vector<std::pair<std::string, std::string>>& attributes) {
  static_assert(sizeof(Vec3) == 3 * sizeof(float));
  const float* base = pixels.empty() ? nullptr : &pixels[0].x;
  write_exr_channels(
      out, width, height,
      {{"R", base, sizeof(Vec3)}, {"G", base + 1, sizeof(Vec3)}, {"B", base + 2, sizeof(Vec3)}},
      attributes);
}

namespace {

std::vector<Vec3> read_exr_rgba(const std::string& path, int& width, int& height) {
  std::ifstream is(path, std::ios::binary);
  if (!is) throw Failure("cannot open for reading: " + errno_text(errno));
  Imf::StdIFStream stream(is, path.c_str());
  Imf::RgbaInputFile file(stream);
  const Imath::Box2i dw = file.dataWindow();
  const std::int64_t w = static_cast<std::int64_t>(dw.max.x) - dw.min.x + 1;
  const std::int64_t h = static_cast<std::int64_t>(dw.max.y) - dw.min.y + 1;
  if (w <= 0 || h <= 0 || w > 0x7fffffff || h > 0x7fffffff)
    throw Failure("invalid OpenEXR data window");
  check_fits_in_memory(w, h, sizeof(Imf::Rgba) + sizeof(Vec3));
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

}  // namespace

bool exr_size(const std::string& path, int& width, int& height) {
  std::ifstream is(path, std::ios::binary);
  if (!is) return false;
  try {
    Imf::StdIFStream stream(is, path.c_str());
    const Imf::InputFile file(stream);
    const Imath::Box2i dw = file.header().dataWindow();
    const std::int64_t w = static_cast<std::int64_t>(dw.max.x) - dw.min.x + 1;
    const std::int64_t h = static_cast<std::int64_t>(dw.max.y) - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > 0x7fffffff || h > 0x7fffffff) return false;
    width = static_cast<int>(w), height = static_cast<int>(h);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

std::vector<Vec3> read_exr(const std::string& path, int& width, int& height) {
  std::ifstream is(path, std::ios::binary);
  if (!is) throw Failure("cannot open for reading: " + errno_text(errno));
  Imf::StdIFStream stream(is, path.c_str());
  Imf::InputFile file(stream);
  const Imf::ChannelList& channels = file.header().channels();
  if (!channels.findChannel("R") || !channels.findChannel("G") || !channels.findChannel("B")) {
    return read_exr_rgba(path, width, height);
  }
  const Imath::Box2i dw = file.header().dataWindow();
  const std::int64_t w = static_cast<std::int64_t>(dw.max.x) - dw.min.x + 1;
  const std::int64_t h = static_cast<std::int64_t>(dw.max.y) - dw.min.y + 1;
  if (w <= 0 || h <= 0 || w > 0x7fffffff || h > 0x7fffffff)
    throw Failure("invalid OpenEXR data window");
  check_fits_in_memory(w, h, sizeof(Vec3));
  std::vector<Vec3> pixels(static_cast<std::size_t>(w * h));
  // OpenEXR addresses the frame buffer by absolute pixel coordinates.
  const std::ptrdiff_t origin =
      -static_cast<std::ptrdiff_t>(dw.min.x) -
      static_cast<std::ptrdiff_t>(dw.min.y) * static_cast<std::ptrdiff_t>(w);
  char* base = reinterpret_cast<char*>(pixels.data() + origin);
  const std::size_t ys = sizeof(Vec3) * static_cast<std::size_t>(w);
  Imf::FrameBuffer fb;
  fb.insert("R", Imf::Slice(Imf::FLOAT, base, sizeof(Vec3), ys));
  fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), sizeof(Vec3), ys));
  fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), sizeof(Vec3), ys));
  file.setFrameBuffer(fb);
  file.readPixels(dw.min.y, dw.max.y);
  width = static_cast<int>(w);
  height = static_cast<int>(h);
  return pixels;
}

}  // namespace amalgam::codec

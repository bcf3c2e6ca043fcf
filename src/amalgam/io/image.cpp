#include "amalgam/io/image.h"

// OpenEXR 3.1's headers trip -Wunused-parameter under clang when not included as system headers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfRgba.h>
#include <ImfRgbaFile.h>
#include <ImfStdIO.h>
#pragma GCC diagnostic pop
#include <png.h>
#include <unistd.h>

#include "amalgam/util/atomic_file.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>

namespace amalgam {
namespace {

namespace fs = std::filesystem;

/// Internal failure carrying only the reason; the public functions prefix the path.
struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string errno_text(int err) {
  return std::error_code(err, std::generic_category()).message();
}

enum class Format { kPng, kPfm, kExr };

Format image_format(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") return Format::kPng;
  if (ext == ".pfm") return Format::kPfm;
  if (ext == ".exr") return Format::kExr;
  throw ImageIoError(path + ": unsupported image format '" + ext +
                     "' (expected .png, .exr or .pfm)");
}

// ---- sRGB transfer function ---------------------------------------------------------------

double linear_to_srgb(double v) {
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

double srgb_to_linear(double s) {
  return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

std::uint8_t encode_srgb8(float v) {
  if (!(v > 0.0f)) return 0;  // also NaN
  if (v >= 1.0f) return 255;
  return static_cast<std::uint8_t>(std::lround(linear_to_srgb(v) * 255.0));
}

using FilePtr = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

FilePtr open_for_reading(const std::string& path) {
  std::FILE* fp = std::fopen(path.c_str(), "rb");
  if (!fp) throw Failure("cannot open for reading: " + errno_text(errno));
  return FilePtr(fp, &std::fclose);
}

// ---- PNG -----------------------------------------------------------------------------------
// libpng reports errors by longjmp. The functions that call setjmp keep only trivially
// destructible locals and never longjmp across C++ frames, so no destructor is skipped.

struct PngErrorState {
  char message[256] = "unknown libpng error";
};

void png_error_handler(png_structp png, png_const_charp msg) {
  auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
  if (state && msg) std::snprintf(state->message, sizeof state->message, "%s", msg);
  png_longjmp(png, 1);
}

void png_warning_handler(png_structp, png_const_charp) {}

/// Writes 8-bit RGB rows (top row first). Returns false with err.message set on failure.
bool png_write_rgb8(std::FILE* fp, int width, int height, const std::uint8_t* rgb,
                    PngErrorState& err) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, png_error_handler, png_warning_handler);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, fp);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(png, info);
  const std::size_t stride = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y) png_write_row(png, rgb + static_cast<std::size_t>(y) * stride);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

void write_png(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels) {
  std::vector<std::uint8_t> rgb(pixels.size() * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    rgb[3 * i + 0] = encode_srgb8(pixels[i].x);
    rgb[3 * i + 1] = encode_srgb8(pixels[i].y);
    rgb[3 * i + 2] = encode_srgb8(pixels[i].z);
  }
  PngErrorState err;
  if (!png_write_rgb8(out.stream(), width, height, rgb.data(), err))
    throw Failure(std::string("PNG encoding failed: ") + err.message);
}

struct PngLayout {
  png_uint_32 width = 0, height = 0;
  int channels = 0, bit_depth = 0;
  std::size_t rowbytes = 0;
};

/// Decodes a PNG whose 8-byte signature has already been consumed into buf, as 8- or 16-bit
/// (big-endian) samples with 1 to 4 channels. Returns false with err.message set on failure.
bool png_read_samples(std::FILE* fp, std::vector<std::uint8_t>& buf, PngLayout& layout,
                      PngErrorState& err) {
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, png_error_handler, png_warning_handler);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, fp);
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  const int colour_type = png_get_color_type(png, info);
  if (colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour_type == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8)
    png_set_expand_gray_1_2_4_to_8(png);
  if (colour_type & PNG_COLOR_MASK_ALPHA) png_set_strip_alpha(png);
  png_set_gray_to_rgb(png);
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  layout.width = png_get_image_width(png, info);
  layout.height = png_get_image_height(png, info);
  layout.channels = png_get_channels(png, info);
  layout.bit_depth = png_get_bit_depth(png, info);
  layout.rowbytes = png_get_rowbytes(png, info);
  try {
    buf.assign(layout.rowbytes * layout.height, 0);
  } catch (...) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw;
  }
  for (int pass = 0; pass < passes; ++pass)
    for (png_uint_32 y = 0; y < layout.height; ++y)
      png_read_row(png, buf.data() + y * layout.rowbytes, nullptr);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

std::vector<Vec3> read_png(const std::string& path, int& width, int& height) {
  FilePtr fp = open_for_reading(path);
  png_byte signature[8] = {};
  if (std::fread(signature, 1, 8, fp.get()) != 8 || png_sig_cmp(signature, 0, 8) != 0)
    throw Failure("not a PNG file");
  std::vector<std::uint8_t> buf;
  PngLayout layout;
  PngErrorState err;
  if (!png_read_samples(fp.get(), buf, layout, err))
    throw Failure(std::string("invalid PNG: ") + err.message);
  if ((layout.bit_depth != 8 && layout.bit_depth != 16) || layout.channels < 1 ||
      layout.channels > 4 || layout.width > 0x7fffffffu || layout.height > 0x7fffffffu)
    throw Failure("unsupported PNG sample layout");

  std::array<float, 256> lut8{};
  for (int i = 0; i < 256; ++i) lut8[i] = static_cast<float>(srgb_to_linear(i / 255.0));
  const bool wide = layout.bit_depth == 16;
  const int bytes = wide ? 2 : 1;
  auto sample = [&](const std::uint8_t* p) {
    return wide ? static_cast<float>(srgb_to_linear(((p[0] << 8) | p[1]) / 65535.0)) : lut8[*p];
  };
  std::vector<Vec3> pixels(static_cast<std::size_t>(layout.width) * layout.height);
  for (png_uint_32 y = 0; y < layout.height; ++y) {
    const std::uint8_t* row = buf.data() + y * layout.rowbytes;
    for (png_uint_32 x = 0; x < layout.width; ++x) {
      const std::uint8_t* p = row + static_cast<std::size_t>(x) * layout.channels * bytes;
      Vec3& out = pixels[static_cast<std::size_t>(y) * layout.width + x];
      if (layout.channels >= 3)
        out = {sample(p), sample(p + bytes), sample(p + 2 * bytes)};
      else
        out.x = out.y = out.z = sample(p);
    }
  }
  width = static_cast<int>(layout.width);
  height = static_cast<int>(layout.height);
  return pixels;
}

// ---- PFM -----------------------------------------------------------------------------------

std::uint32_t byte_swap(std::uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

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

// ---- OpenEXR -------------------------------------------------------------------------------

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

// ---- false colour --------------------------------------------------------------------------

/// The viridis colour map (van der Walt & Smith, released CC0 with matplotlib), sampled at
/// t = k / 32 in sRGB; linear interpolation between samples stays within 2/255 of the full
/// 256-entry table.
constexpr std::array<std::array<float, 3>, 33> kViridisSrgb = {{
    {0.2670f, 0.0049f, 0.3294f}, {0.2770f, 0.0502f, 0.3755f}, {0.2823f, 0.0946f, 0.4170f},
    {0.2829f, 0.1354f, 0.4530f}, {0.2789f, 0.1749f, 0.4830f}, {0.2708f, 0.2133f, 0.5066f},
    {0.2593f, 0.2507f, 0.5244f}, {0.2454f, 0.2867f, 0.5370f}, {0.2302f, 0.3213f, 0.5455f},
    {0.2148f, 0.3545f, 0.5510f}, {0.2000f, 0.3864f, 0.5545f}, {0.1861f, 0.4173f, 0.5567f},
    {0.1733f, 0.4474f, 0.5579f}, {0.1613f, 0.4770f, 0.5581f}, {0.1497f, 0.5064f, 0.5573f},
    {0.1384f, 0.5358f, 0.5551f}, {0.1281f, 0.5651f, 0.5509f}, {0.1209f, 0.5945f, 0.5442f},
    {0.1203f, 0.6238f, 0.5343f}, {0.1310f, 0.6529f, 0.5208f}, {0.1554f, 0.6815f, 0.5032f},
    {0.1930f, 0.7096f, 0.4812f}, {0.2415f, 0.7366f, 0.4545f}, {0.2986f, 0.7624f, 0.4230f},
    {0.3629f, 0.7867f, 0.3866f}, {0.4330f, 0.8091f, 0.3453f}, {0.5081f, 0.8292f, 0.2992f},
    {0.5873f, 0.8470f, 0.2489f}, {0.6694f, 0.8622f, 0.1954f}, {0.7529f, 0.8751f, 0.1427f},
    {0.8359f, 0.8861f, 0.1025f}, {0.9166f, 0.8961f, 0.1008f}, {0.9932f, 0.9062f, 0.1439f},
}};

/// Viridis at t in [0, 1], as linear RGB.
Vec3 viridis_linear(double t) {
  constexpr int kSegments = static_cast<int>(kViridisSrgb.size()) - 1;
  const double s = std::clamp(t, 0.0, 1.0) * kSegments;
  const int k = std::min(static_cast<int>(s), kSegments - 1);
  const double f = s - k;
  Vec3 out;
  for (int c = 0; c < 3; ++c) {
    const double srgb = kViridisSrgb[k][c] * (1.0 - f) + kViridisSrgb[k + 1][c] * f;
    out[c] = static_cast<float>(srgb_to_linear(srgb));
  }
  return out;
}

}  // namespace

void write_image(const std::string& path, int width, int height,
                 const std::vector<Vec3>& linear_rgb) {
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
        write_png(out, width, height, linear_rgb);
        break;
      case Format::kPfm:
        write_pfm(out, width, height, linear_rgb);
        break;
      case Format::kExr:
        write_exr(out, width, height, linear_rgb);
        break;
    }
  });
}

std::vector<Vec3> read_image(const std::string& path, int& width, int& height) {
  const Format format = image_format(path);
  try {
    switch (format) {
      case Format::kPng:
        return read_png(path, width, height);
      case Format::kPfm:
        return read_pfm(path, width, height);
      case Format::kExr:
        return read_exr(path, width, height);
    }
  } catch (const std::exception& e) {
    throw ImageIoError(path + ": " + one_line(e.what(), std::string::npos));
  }
  throw ImageIoError(path + ": unknown image format");
}

std::vector<Vec3> false_colour(const std::vector<double>& values, bool log_scale,
                               double* vmax_out) {
  double vmax = 0.0;
  for (double v : values)
    if (std::isfinite(v) && v > vmax) vmax = v;
  const double denom = log_scale ? std::log1p(vmax) : vmax;
  std::vector<Vec3> colours;
  colours.reserve(values.size());
  for (double v : values) {
    double t;
    if (std::isnan(v) || v <= 0.0)
      t = 0.0;
    else if (v >= vmax)  // the maximum itself, or +inf
      t = 1.0;
    else  // here 0 < v < vmax, so denom > 0
      t = (log_scale ? std::log1p(v) : v) / denom;
    colours.push_back(viridis_linear(t));
  }
  if (vmax_out) *vmax_out = vmax;
  return colours;
}

}  // namespace amalgam

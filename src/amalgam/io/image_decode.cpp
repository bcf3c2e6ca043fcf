#include "amalgam/io/image_decode.h"

// clang-format off
#include <cstdio>  // jpeglib.h needs FILE and size_t declared first
#include <jpeglib.h>
#include <jerror.h>  // after jpeglib.h: the warning codes (JWRN_*)
// clang-format on
#include <Iex.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfRgbaFile.h>
#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>

#include "amalgam/io/srgb.h"

// stb_image (Debian's libstb-dev) for the formats without a stricter library here: libpng
// checks every chunk's CRC and libjpeg reports a file cut short, where stb_image decodes both
// silently, so PNG and JPEG stay with them. PNM and PIC are left out: stb_image's PNM header
// parser overflows a signed int on a long number (undefined behaviour, found by
// fuzz/image_fuzz.cpp), and neither is a texture format in practice.
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_STDIO
#define STBI_NO_PNG
#define STBI_NO_JPEG
#define STBI_NO_PNM
#define STBI_NO_PIC
#define STBI_MAX_DIMENSIONS (1 << 16)
#include <stb/stb_image.h>

namespace amalgam {
namespace {

bool too_large(std::uint64_t w, std::uint64_t h, std::uint64_t max_texels, std::uint32_t max_side,
               std::string& why) {
  if (w == 0 || h == 0) {
    why = "the image is empty";
    return true;
  }
  if (w > max_side || h > max_side || w * h > max_texels) {
    why = "the image is " + std::to_string(w) + "x" + std::to_string(h) +
          " texels, more than the limit (" + std::to_string(max_side) + " per side, " +
          std::to_string(max_texels) + " in all)";
    return true;
  }
  return false;
}

bool decode_png(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                std::uint32_t max_side, Texture& out, std::string& why) {
  png_image image;  // libpng's simplified API: no longjmp reaches this frame
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, data, size)) {
    why = std::string("corrupt PNG data: ") + image.message;
    png_image_free(&image);
    return false;
  }
  if (too_large(image.width, image.height, max_texels, max_side, why)) {
    png_image_free(&image);
    return false;
  }
  // RGBA, not RGB: without alpha in the output libpng would composite onto black; 8-bit sRGB
  // output is not premultiplied, so dropping alpha keeps the colours as stored.
  image.format = PNG_FORMAT_RGBA;
  std::vector<std::uint8_t> rgba(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, rgba.data(), 0, nullptr)) {
    why = std::string("corrupt PNG data: ") + image.message;
    png_image_free(&image);
    return false;
  }
  out.width = image.width, out.height = image.height;
  const std::size_t n = static_cast<std::size_t>(image.width) * image.height;
  out.texels.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) out.texels[3 * i + k] = rgba[4 * i + k];
  return true;
}

struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

extern "C" void jpeg_fail(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegError*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

extern "C" void jpeg_quiet(j_common_ptr) {}  // nothing printed

/// Warnings: a file cut short (libjpeg fills the missing rows with grey) fails as corrupt data;
/// other recoverable oddities (extraneous bytes before a marker, common in real files) pass.
extern "C" void jpeg_warning(j_common_ptr cinfo, int level) {
  const int code = cinfo->err->msg_code;
  if (level < 0 && (code == JWRN_JPEG_EOF || code == JWRN_HIT_MARKER)) jpeg_fail(cinfo);
}

/// Decodes into `*pixels` (malloc'ed, RGB rows; the caller frees it). Only trivially
/// destructible locals, as longjmp skips destructors.
bool decode_jpeg_raw(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                     std::uint32_t max_side, std::uint8_t** pixels, std::uint32_t* width,
                     std::uint32_t* height, char* message, std::size_t message_size) {
  jpeg_decompress_struct cinfo;
  JpegError err;
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = jpeg_fail;
  err.mgr.output_message = jpeg_quiet;
  err.mgr.emit_message = jpeg_warning;
  *pixels = nullptr;
  if (setjmp(err.jump)) {
    std::snprintf(message, message_size, "corrupt JPEG data: %s", err.message);
    jpeg_destroy_decompress(&cinfo);
    std::free(*pixels);
    *pixels = nullptr;
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
  jpeg_read_header(&cinfo, TRUE);
  const std::uint64_t w = cinfo.image_width, h = cinfo.image_height;
  if (w == 0 || h == 0 || w > max_side || h > max_side || w * h > max_texels) {
    std::snprintf(message, message_size, "too large");
    jpeg_destroy_decompress(&cinfo);
    *width = static_cast<std::uint32_t>(w), *height = static_cast<std::uint32_t>(h);
    return false;
  }
  cinfo.out_color_space = JCS_RGB;  // grey and YCbCr converted; CMYK fails with a message
  jpeg_start_decompress(&cinfo);
  if (cinfo.output_components != 3) {
    std::snprintf(message, message_size, "unsupported JPEG colour space");
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  *pixels = static_cast<std::uint8_t*>(std::malloc(static_cast<std::size_t>(3 * w * h)));
  if (*pixels == nullptr) {
    std::snprintf(message, message_size, "out of memory");
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = *pixels + static_cast<std::size_t>(cinfo.output_scanline) * 3 * w;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  *width = static_cast<std::uint32_t>(w), *height = static_cast<std::uint32_t>(h);
  return true;
}

bool decode_jpeg(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                 std::uint32_t max_side, Texture& out, std::string& why) {
  std::uint8_t* pixels = nullptr;
  std::uint32_t w = 0, h = 0;
  char message[JMSG_LENGTH_MAX + 32] = "";
  if (!decode_jpeg_raw(data, size, max_texels, max_side, &pixels, &w, &h, message,
                       sizeof message)) {
    if (std::strcmp(message, "too large") != 0 || !too_large(w, h, max_texels, max_side, why))
      why = message;
    return false;
  }
  out.width = w, out.height = h;
  out.texels.assign(pixels, pixels + std::size_t{3} * w * h);
  std::free(pixels);
  return true;
}

/// An EXR file in memory, as OpenEXR reads it (a read past the end throws, as from a file).
class MemoryStream final : public Imf::IStream {
 public:
  MemoryStream(const std::uint8_t* data, std::size_t size)
      : Imf::IStream("texture"), data_(data), size_(size) {}
  bool read(char c[], int n) override {
    if (n < 0 || static_cast<std::size_t>(n) > size_ - pos_)
      throw Iex::InputExc("the file is shorter than its header says");
    std::memcpy(c, data_ + pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return pos_ < size_;
  }
  std::uint64_t tellg() override { return pos_; }
  void seekg(std::uint64_t pos) override {
    if (pos > size_) throw Iex::InputExc("a seek past the end of the file");
    pos_ = static_cast<std::size_t>(pos);
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
};

/// OpenEXR sizes an attribute's value from the size the file declares before reading it, so a
/// header claiming a 2 GB string attribute has it allocate and clear 2 GB first (10 s under
/// the sanitizers, found by fuzz/image_fuzz.cpp). The declared sizes are checked against the
/// bytes the file has, header by header (a multi-part file has several, then an empty one).
bool exr_headers_fit(const std::uint8_t* d, std::size_t n, std::string& why) {
  why = "corrupt EXR data: the header is cut short";
  if (n < 8) return false;
  const bool multipart = (d[5] & 0x10) != 0;  // version flag bit 12
  std::size_t at = 8;
  auto skip_name = [&] {  // a null-terminated name
    while (at < n && d[at] != 0) ++at;
    return at++ < n;
  };
  do {
    for (;;) {
      if (at >= n) return false;
      if (d[at] == 0) {  // the end of this header
        ++at;
        break;
      }
      if (!skip_name() || !skip_name() || n - at < 4) return false;
      std::uint32_t bytes = 0;
      for (int k = 3; k >= 0; --k) bytes = bytes << 8 | d[at + static_cast<std::size_t>(k)];
      at += 4;
      if (bytes > n - at) {
        why = "corrupt EXR data: an attribute claims " + std::to_string(bytes) +
              " bytes, more than the file has";
        return false;
      }
      at += bytes;
    }
  } while (multipart && at < n && d[at] != 0);
  return true;
}

/// EXR through OpenEXR's RGBA interface (any channel type; luminance-only files as grey):
/// linear colours, stored as 8-bit sRGB like every texture (clamped to [0, 1], as a base colour
/// is a reflectance).
bool decode_exr(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                std::uint32_t max_side, Texture& out, std::string& why) {
  if (!exr_headers_fit(data, size, why)) return false;
  try {
    // OpenEXR's own limits, checked as the header is read: without them a header claiming a
    // huge data window or tile makes it allocate line or tile buffers for it first.
    const int side = static_cast<int>(std::min<std::uint32_t>(max_side, 1u << 30));
    Imf::Header::setMaxImageSize(side, side);
    Imf::Header::setMaxTileSize(side, side);
    MemoryStream stream(data, size);
    Imf::RgbaInputFile file(stream, 1);
    const Imath::Box2i win = file.dataWindow();
    const std::int64_t w = std::int64_t{win.max.x} - win.min.x + 1;
    const std::int64_t h = std::int64_t{win.max.y} - win.min.y + 1;
    if (w <= 0 || h <= 0) {
      why = "the image is empty";
      return false;
    }
    if (too_large(static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h), max_texels,
                  max_side, why))
      return false;
    std::vector<Imf::Rgba> pixels(static_cast<std::size_t>(w * h));
    file.setFrameBuffer(pixels.data() - win.min.x - win.min.y * w, 1, static_cast<std::size_t>(w));
    file.readPixels(win.min.y, win.max.y);
    out.width = static_cast<std::uint32_t>(w), out.height = static_cast<std::uint32_t>(h);
    out.texels.resize(3 * pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      out.texels[3 * i] = encode_srgb8(pixels[i].r);
      out.texels[3 * i + 1] = encode_srgb8(pixels[i].g);
      out.texels[3 * i + 2] = encode_srgb8(pixels[i].b);
    }
    return true;
  } catch (const std::exception& e) {
    why = std::string("corrupt EXR data: ") + e.what();
    return false;
  }
}

/// The bytes of an image for stb_image's reader, which notes a read past the end: stb_image
/// reads missing bytes as zeros and returns success, so a file cut short would be a silently
/// black texture. Files under stb_image's 128-byte buffer are served padded with zeros to it
/// (its format tests read up to that far); a read past data and padding is the overrun.
struct StbSource {
  const std::uint8_t* data;
  std::size_t size, pos = 0;
  bool overrun = false;
  std::size_t served() const { return std::max<std::size_t>(size, 128); }

  static int read(void* user, char* out, int n) {
    auto* s = static_cast<StbSource*>(user);
    if (s->pos >= s->served() && n > 0) s->overrun = true;
    const std::size_t k = std::min(static_cast<std::size_t>(std::max(n, 0)), s->served() - s->pos);
    for (std::size_t i = 0; i < k; ++i, ++s->pos)
      out[i] = static_cast<char>(s->pos < s->size ? s->data[s->pos] : 0);
    return static_cast<int>(k);
  }
  static void skip(void* user, int n) {
    auto* s = static_cast<StbSource*>(user);
    const std::size_t to = s->pos + static_cast<std::size_t>(std::max(n, 0));
    if (n < 0 || to > s->served()) s->overrun = n > 0;
    s->pos = std::min(n < 0 ? s->pos : to, s->served());
  }
  static int eof(void* user) {
    auto* s = static_cast<StbSource*>(user);
    return s->pos >= s->served() ? 1 : 0;
  }
};

/// TGA, BMP, PSD, GIF (first frame) and HDR (Radiance) through stb_image; HDR is
/// linear, stored as 8-bit sRGB as an EXR is. A file shorter than its image is refused.
bool decode_stb(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                std::uint32_t max_side, Texture& out, std::string& why) {
  if (size > static_cast<std::size_t>(INT32_MAX)) {
    why = "the image file is larger than 2 GiB";
    return false;
  }
  const int len = static_cast<int>(size);
  int w = 0, h = 0, channels = 0;
  if (!stbi_info_from_memory(data, len, &w, &h, &channels)) {
    why = "not an image format amalgam reads (PNG, JPEG, EXR, TGA, BMP, PSD, GIF, HDR)";
    return false;
  }
  if (too_large(static_cast<std::uint64_t>(std::max(w, 0)),
                static_cast<std::uint64_t>(std::max(h, 0)), max_texels, max_side, why))
    return false;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  const stbi_io_callbacks io{&StbSource::read, &StbSource::skip, &StbSource::eof};
  StbSource source{data, size};
  std::vector<std::uint8_t> texels(3 * n);
  bool decoded = false;
  if (stbi_is_hdr_from_memory(data, len)) {
    std::unique_ptr<float, void (*)(void*)> rgb(
        stbi_loadf_from_callbacks(&io, &source, &w, &h, &channels, 3), stbi_image_free);
    decoded = rgb != nullptr && static_cast<std::size_t>(w) * static_cast<std::size_t>(h) == n;
    for (std::size_t i = 0; decoded && i < 3 * n; ++i) texels[i] = encode_srgb8(rgb.get()[i]);
  } else {
    std::unique_ptr<stbi_uc, void (*)(void*)> rgb(
        stbi_load_from_callbacks(&io, &source, &w, &h, &channels, 3), stbi_image_free);
    decoded = rgb != nullptr && static_cast<std::size_t>(w) * static_cast<std::size_t>(h) == n;
    if (decoded) std::copy(rgb.get(), rgb.get() + 3 * n, texels.begin());
  }
  if (!decoded) {
    const char* reason = stbi_failure_reason();
    why = std::string("corrupt image data: ") + (reason != nullptr ? reason : "unknown");
    return false;
  }
  if (source.overrun) {
    why = "the image file ends before its texels do (" + std::to_string(size) + " bytes)";
    return false;
  }
  out.width = static_cast<std::uint32_t>(w), out.height = static_cast<std::uint32_t>(h);
  out.texels = std::move(texels);
  return true;
}

}  // namespace

bool decode_image(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                  std::uint32_t max_side, Texture& out, std::string& why) {
  static const std::uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size >= 8 && std::memcmp(data, kPng, 8) == 0)
    return decode_png(data, size, max_texels, max_side, out, why);
  if (size >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff)
    return decode_jpeg(data, size, max_texels, max_side, out, why);
  static const std::uint8_t kExr[4] = {0x76, 0x2f, 0x31, 0x01};
  if (size >= 4 && std::memcmp(data, kExr, 4) == 0)
    return decode_exr(data, size, max_texels, max_side, out, why);
  return decode_stb(data, size, max_texels, max_side, out, why);
}

}  // namespace amalgam

#include "amalgam/io/image_decode.h"

// clang-format off
#include <cstdio>  // jpeglib.h needs FILE and size_t declared first
#include <jpeglib.h>
#include <jerror.h>  // after jpeglib.h: the warning codes (JWRN_*)
// clang-format on
#include <png.h>

#include <csetjmp>
#include <cstdlib>
#include <cstring>

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

}  // namespace

bool decode_image(const std::uint8_t* data, std::size_t size, std::uint64_t max_texels,
                  std::uint32_t max_side, Texture& out, std::string& why) {
  static const std::uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size >= 8 && std::memcmp(data, kPng, 8) == 0)
    return decode_png(data, size, max_texels, max_side, out, why);
  if (size >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff)
    return decode_jpeg(data, size, max_texels, max_side, out, why);
  why = "not a PNG or JPEG image";
  return false;
}

}  // namespace amalgam

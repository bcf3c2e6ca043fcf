#include "amalgam/io/png.h"

#include <png.h>

#include <algorithm>
#include <array>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "amalgam/io/codec.h"
#include "amalgam/io/srgb.h"

namespace amalgam::codec {
namespace {

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
                    const std::vector<png_text>& text, PngErrorState& err) {
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
  if (!text.empty()) png_set_text(png, info, text.data(), static_cast<int>(text.size()));
  png_write_info(png, info);
  const std::size_t stride = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y) png_write_row(png, rgb + static_cast<std::size_t>(y) * stride);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
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
    // The samples and, per pixel, the three floats read_png makes of them.
    check_fits_in_memory(layout.width, layout.height,
                         layout.rowbytes / std::max<png_uint_32>(layout.width, 1) + 12);
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

}  // namespace

void write_png(AtomicFile& out, int width, int height, const std::vector<Vec3>& pixels,
               const std::vector<std::pair<std::string, std::string>>& text) {
  std::vector<std::uint8_t> rgb(pixels.size() * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    rgb[3 * i + 0] = encode_srgb8(pixels[i].x);
    rgb[3 * i + 1] = encode_srgb8(pixels[i].y);
    rgb[3 * i + 2] = encode_srgb8(pixels[i].z);
  }
  std::vector<png_text> chunks;
  for (const auto& [key, value] : text) {
    if (key.empty() || key.size() > 79) throw Failure("PNG text key must have 1 to 79 characters");
    png_text t{};
    t.compression = PNG_TEXT_COMPRESSION_NONE;
    t.key = const_cast<char*>(key.c_str());  // libpng copies the text; it does not modify it
    t.text = const_cast<char*>(value.c_str());
    t.text_length = value.size();
    chunks.push_back(t);
  }
  PngErrorState err;
  if (!png_write_rgb8(out.stream(), width, height, rgb.data(), chunks, err))
    throw Failure(std::string("PNG encoding failed: ") + err.message);
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

}  // namespace amalgam::codec

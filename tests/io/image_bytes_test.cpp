// Image files checked against something other than our own reader and writer: PNG bytes
// decoded (and encoded) here with zlib alone, against sRGB values computed by hand from the
// IEC 61966-2-1 transfer function; EXR files read (and written) here through OpenEXR's generic
// channel interface, not the RGBA one image.cpp uses. A consistently wrong gamma, swapped
// channels or a flipped image pass a round trip; they fail here.

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

// OpenEXR 3.1's headers trip -Wunused-parameter under clang when not included as system headers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#pragma GCC diagnostic pop

#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "amalgam/io/image.h"

namespace amalgam {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("amalgam_image_bytes_" + std::to_string(getpid()));
  fs::create_directories(d);
  return d / name;
}

/// Removes a file of temp_file, and its directory once empty.
void remove_temp(const fs::path& path) {
  std::error_code ec;
  fs::remove(path, ec);
  fs::remove(path.parent_path(), ec);  // fails while not empty
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  return (std::uint32_t(std::uint8_t(s[at])) << 24) |
         (std::uint32_t(std::uint8_t(s[at + 1])) << 16) |
         (std::uint32_t(std::uint8_t(s[at + 2])) << 8) | std::uint32_t(std::uint8_t(s[at + 3]));
}

/// An 8-bit RGB PNG decoded with zlib and the five PNG filters (PNG spec, section 9), nothing
/// of libpng: width, height and the samples row by row. Fails the test on anything else.
struct DecodedPng {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
  std::uint8_t at(int x, int y, int c) const { return rgb[(std::size_t(y) * width + x) * 3 + c]; }
};

DecodedPng decode_png(const std::string& file) {
  DecodedPng out;
  const std::string sig = "\x89PNG\r\n\x1a\n";
  EXPECT_EQ(file.substr(0, 8), sig) << "not a PNG signature";
  std::string idat;
  bool srgb_chunk = false;
  for (std::size_t at = 8; at + 12 <= file.size();) {
    const std::uint32_t len = be32(file, at);
    const std::string type = file.substr(at + 4, 4);
    const std::string data = file.substr(at + 8, len);
    const std::uint32_t crc = be32(file, at + 8 + len);
    EXPECT_EQ(crc, crc32(crc32(0, reinterpret_cast<const Bytef*>(type.data()), 4),
                         reinterpret_cast<const Bytef*>(data.data()), len))
        << "CRC of chunk " << type;
    if (type == "IHDR") {
      out.width = int(be32(data, 0));
      out.height = int(be32(data, 4));
      EXPECT_EQ(int(std::uint8_t(data[8])), 8) << "bit depth";
      EXPECT_EQ(int(std::uint8_t(data[9])), 2) << "colour type RGB";
      EXPECT_EQ(int(std::uint8_t(data[12])), 0) << "not interlaced";
    } else if (type == "IDAT") {
      idat += data;
    } else if (type == "sRGB") {
      srgb_chunk = true;
    }
    at += 12 + len;
  }
  EXPECT_TRUE(srgb_chunk) << "the file should declare sRGB";
  const std::size_t stride = std::size_t(out.width) * 3;
  std::vector<std::uint8_t> raw((stride + 1) * out.height);
  uLongf raw_len = raw.size();
  EXPECT_EQ(
      uncompress(raw.data(), &raw_len, reinterpret_cast<const Bytef*>(idat.data()), idat.size()),
      Z_OK);
  EXPECT_EQ(raw_len, raw.size());
  out.rgb.assign(stride * out.height, 0);
  for (int y = 0; y < out.height; ++y) {
    const std::uint8_t filter = raw[y * (stride + 1)];
    const std::uint8_t* in = &raw[y * (stride + 1) + 1];
    std::uint8_t* row = &out.rgb[y * stride];
    const std::uint8_t* up = y ? &out.rgb[(y - 1) * stride] : nullptr;
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= 3 ? row[i - 3] : 0, b = up ? up[i] : 0, c = (up && i >= 3) ? up[i - 3] : 0;
      int pred = 0;
      switch (filter) {
        case 0:
          pred = 0;
          break;
        case 1:
          pred = a;
          break;
        case 2:
          pred = b;
          break;
        case 3:
          pred = (a + b) / 2;
          break;
        case 4: {
          const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
          pred = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
          break;
        }
        default:
          ADD_FAILURE() << "unknown filter " << int(filter);
      }
      row[i] = std::uint8_t(in[i] + pred);
    }
  }
  return out;
}

void put_chunk(std::string& f, const std::string& type, const std::string& data) {
  for (int s = 24; s >= 0; s -= 8) f.push_back(char((data.size() >> s) & 0xff));
  f += type + data;
  const uLong crc = crc32(crc32(0, reinterpret_cast<const Bytef*>(type.data()), 4),
                          reinterpret_cast<const Bytef*>(data.data()), uInt(data.size()));
  for (int s = 24; s >= 0; s -= 8) f.push_back(char((crc >> s) & 0xff));
}

/// A PNG of 8-bit RGB (`channels` = 3) or grey (1) samples, encoded here with zlib.
std::string encode_png(int w, int h, int channels, const std::vector<std::uint8_t>& samples) {
  std::string raw;
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);  // filter: none
    raw.append(reinterpret_cast<const char*>(&samples[std::size_t(y) * w * channels]),
               std::size_t(w) * channels);
  }
  std::vector<Bytef> z(compressBound(raw.size()));
  uLongf zlen = z.size();
  EXPECT_EQ(compress(z.data(), &zlen, reinterpret_cast<const Bytef*>(raw.data()), raw.size()),
            Z_OK);
  std::string ihdr;
  for (std::uint32_t v : {std::uint32_t(w), std::uint32_t(h)})
    for (int s = 24; s >= 0; s -= 8) ihdr.push_back(char((v >> s) & 0xff));
  ihdr += std::string{char(8), char(channels == 3 ? 2 : 0), 0, 0, 0};
  std::string f = "\x89PNG\r\n\x1a\n";
  put_chunk(f, "IHDR", ihdr);
  put_chunk(f, "IDAT", std::string(reinterpret_cast<const char*>(z.data()), zlen));
  put_chunk(f, "IEND", "");
  return f;
}

// Linear values and their 8-bit sRGB codes, worked by hand from IEC 61966-2-1:
// s = 12.92 v for v <= 0.0031308, else 1.055 v^(1/2.4) - 0.055; code = round(255 s).
//   0.5   -> 0.735357 -> 187.52 -> 188  (the well-known "50 % linear grey is sRGB 188")
//   0.18  -> 0.461356 -> 117.65 -> 118  (18 % grey card)
//   0.05  -> 0.247801 ->  63.19 ->  63
//   0.002 -> 0.025840 ->   6.59 ->   7  (linear segment)
struct Encoded {
  float linear;
  int code;
};
constexpr Encoded kEncoded[] = {{0.0f, 0},   {0.002f, 7}, {0.05f, 63}, {0.18f, 118},
                                {0.5f, 188}, {1.0f, 255}, {2.5f, 255}};

TEST(ImageBytes, PngWriterStoresSrgbCodesComputedByHand) {
  // One row per known value: red = the value, green = the next one, blue = 0; 2 pixels a row,
  // the second one black, so a flip of rows or columns or a channel swap shows.
  const int n = int(std::size(kEncoded)), w = 2;
  std::vector<Vec3> px;
  for (int i = 0; i < n; ++i) {
    px.push_back({kEncoded[i].linear, kEncoded[(i + 1) % n].linear, 0.0f});
    px.push_back({0.0f, 0.0f, 0.0f});
  }
  const fs::path path = temp_file("known.png");
  write_image(path.string(), w, n, px);
  const DecodedPng png = decode_png(read_bytes(path));
  ASSERT_EQ(png.width, w);
  ASSERT_EQ(png.height, n);
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(png.at(0, i, 0), kEncoded[i].code) << "red of linear " << kEncoded[i].linear;
    EXPECT_EQ(png.at(0, i, 1), kEncoded[(i + 1) % n].code) << "green, row " << i;
    EXPECT_EQ(png.at(0, i, 2), 0) << "blue, row " << i;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(png.at(1, i, c), 0) << "second pixel, row " << i;
  }
  remove_temp(path);
}

// The other direction: codes written here, read by read_image, decoded to linear by hand:
// v = s / 12.92 for s <= 0.04045, else ((s + 0.055) / 1.055)^2.4, s = code / 255.
//   128 -> 0.2158605   188 -> 0.5028865   64 -> 0.0512695   10 -> 0.0030353   255 -> 1
TEST(ImageBytes, PngReaderDecodesSrgbCodesToLinearComputedByHand) {
  struct Decoded {
    int code;
    double linear;
  };
  const Decoded known[] = {{0, 0.0},         {10, 0.0030353},  {64, 0.0512695},
                           {128, 0.2158605}, {188, 0.5028865}, {255, 1.0}};
  const int n = int(std::size(known));
  // RGB: one pixel per known code in red, green 0, blue code 10.
  std::vector<std::uint8_t> rgb;
  for (const Decoded& k : known) rgb.insert(rgb.end(), {std::uint8_t(k.code), 0, 10});
  const fs::path path = temp_file("written-here.png");
  std::ofstream(path, std::ios::binary) << encode_png(1, n, 3, rgb);
  int w = 0, h = 0;
  const std::vector<Vec3> px = read_image(path.string(), w, h);
  ASSERT_EQ(w, 1);
  ASSERT_EQ(h, n);
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR(px[i].x, known[i].linear, 2e-6) << "code " << known[i].code << ", row " << i;
    EXPECT_EQ(px[i].y, 0.0f) << "row " << i;
    EXPECT_NEAR(px[i].z, 0.0030353, 2e-6) << "row " << i;
  }
  // Grey: one sample spread to all three channels.
  std::vector<std::uint8_t> grey;
  for (const Decoded& k : known) grey.push_back(std::uint8_t(k.code));
  std::ofstream(path, std::ios::binary | std::ios::trunc) << encode_png(n, 1, 1, grey);
  const std::vector<Vec3> g = read_image(path.string(), w, h);
  ASSERT_EQ(w, n);
  ASSERT_EQ(h, 1);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(g[i][c], known[i].linear, 2e-6) << "grey " << i;
  remove_temp(path);
}

// EXR: float32 (not half: exact integers beyond 2048) in channels named R, G and B (no alpha),
// the first row the top one. Any float must come back bit-exact.
TEST(ImageBytes, ExrHoldsFloatChannelsRGBTopRowFirst) {
  const int w = 3, h = 2;
  const std::vector<Vec3> px = {{0.5f, 2.0f, 1000.5f},        {0.0f, -3.0f, 0.125f},
                                {1.0f, 0.25f, 4.0f},          {8.0f, 0.75f, 0.0f},
                                {16777216.0f, 2049.0f, 0.1f}, {0.0625f, 5.0f, 7.0f}};
  const fs::path path = temp_file("known.exr");
  write_image(path.string(), w, h, px);
  Imf::InputFile in(path.c_str());
  const Imf::ChannelList& channels = in.header().channels();
  std::vector<std::string> names;
  for (auto c = channels.begin(); c != channels.end(); ++c) {
    names.push_back(c.name());
    EXPECT_EQ(c.channel().type, Imf::FLOAT) << c.name();
  }
  EXPECT_EQ(names, (std::vector<std::string>{"B", "G", "R"})) << "RGB, no alpha";
  const Imath::Box2i dw = in.header().dataWindow();
  ASSERT_EQ(dw.max.x - dw.min.x + 1, w);
  ASSERT_EQ(dw.max.y - dw.min.y + 1, h);
  std::vector<float> r(w * h), g(w * h), b(w * h);
  Imf::FrameBuffer fb;
  const std::size_t xs = sizeof(float), ys = sizeof(float) * w;
  const long origin = dw.min.x + long(dw.min.y) * w;
  fb.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(r.data() - origin), xs, ys));
  fb.insert("G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(g.data() - origin), xs, ys));
  fb.insert("B", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(b.data() - origin), xs, ys));
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  for (int i = 0; i < w * h; ++i) {
    EXPECT_EQ(r[i], px[i].x) << "R of pixel " << i;
    EXPECT_EQ(g[i], px[i].y) << "G of pixel " << i;
    EXPECT_EQ(b[i], px[i].z) << "B of pixel " << i;
  }
  remove_temp(path);
}

TEST(ImageBytes, ExrReaderTakesChannelsByName) {
  // Written here with OpenEXR's generic interface, channels in FLOAT (not half), the reader
  // must put R, G and B where they belong and keep the row order.
  const int w = 2, h = 2;
  std::vector<float> r = {1, 2, 3, 4}, g = {10, 20, 30, 40}, b = {0.5f, 0.25f, 0.125f, 8};
  const fs::path path = temp_file("written-here.exr");
  {
    Imf::Header header(w, h);
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile out(path.c_str(), header);
    Imf::FrameBuffer fb;
    const std::size_t xs = sizeof(float), ys = sizeof(float) * w;
    fb.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(r.data()), xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(g.data()), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(b.data()), xs, ys));
    out.setFrameBuffer(fb);
    out.writePixels(h);
  }
  int rw = 0, rh = 0;
  const std::vector<Vec3> px = read_image(path.string(), rw, rh);
  ASSERT_EQ(rw, w);
  ASSERT_EQ(rh, h);
  for (int i = 0; i < w * h; ++i) EXPECT_EQ(px[i], (Vec3{r[i], g[i], b[i]})) << "pixel " << i;
  remove_temp(path);
}

}  // namespace
}  // namespace amalgam

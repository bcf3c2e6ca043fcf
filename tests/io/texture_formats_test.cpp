// Texture image formats beyond PNG and JPEG (docs/import.md): TGA, BMP, HDR through stb_image
// and EXR through OpenEXR, decoded in the import helper into the same 8-bit sRGB texels, rows
// top to bottom; linear formats (EXR, HDR) encoded with the sRGB curve.

#include <OpenEXR/ImfRgbaFile.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "amalgam/io/mesh_import.h"
#include "amalgam/io/srgb.h"
#include "test_models.h"

namespace amalgam {
namespace texture_formats_test {

namespace fs = std::filesystem;
using test::kModels;

struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("amalgam_texfmt_" + std::to_string(getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

void write(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

/// Imports a one-triangle OBJ whose material's base colour is the image `image` beside it.
ImportedMesh import_with_texture(const fs::path& dir, const std::string& image) {
  write(dir / "m.mtl", "newmtl t\nKd 1 1 1\nmap_Kd " + image + "\n");
  write(dir / "a.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\n"
        "f 1/1 2/2 3/3\n");
  return import_mesh((dir / "a.obj").string());
}

std::vector<std::uint8_t> rgb(std::initializer_list<int> v) {
  return std::vector<std::uint8_t>(v.begin(), v.end());
}

TEST(TextureFormats, TgaRowsBottomUpAndBgrComeOutTopDownRgb) {
  REQUIRE_MODELS();
  Scratch s;
  // Uncompressed true-colour 2 x 2, origin bottom left (descriptor 0): the file's first row is
  // the image's bottom row; each texel is stored B, G, R.
  std::string tga("\0\0\2\0\0\0\0\0\0\0\0\0\2\0\2\0\x18\0", 18);
  const std::uint8_t texels[12] = {0,   0, 255, 0,  255, 0,    // bottom: red, green
                                   255, 0, 0,   10, 20,  30};  // top: blue, (30, 20, 10)
  tga.append(reinterpret_cast<const char*>(texels), 12);
  write(s.dir / "t.tga", tga);
  const ImportedMesh m = import_with_texture(s.dir, "t.tga");
  ASSERT_EQ(m.textures.size(), 1u) << (m.dropped.empty() ? "" : m.dropped[0]);
  EXPECT_TRUE(m.dropped.empty());
  EXPECT_EQ(m.textures[0].width, 2u);
  EXPECT_EQ(m.textures[0].texels, rgb({0, 0, 255, 30, 20, 10, 255, 0, 0, 0, 255, 0}));
  EXPECT_EQ(m.materials[m.triangles[0].material].texture, 0);
}

TEST(TextureFormats, ExrIsLinearAndEncodedAsSrgb) {
  REQUIRE_MODELS();
  Scratch s;
  std::vector<Imf::Rgba> px = {{0.5f, 0.25f, 1.0f, 1.0f},
                               {0.0f, 2.0f, 0.0031308f, 1.0f},  // 2.0 clamped to 1
                               {0.18f, 0.18f, 0.18f, 1.0f},
                               {1.0f, 0.0f, 0.0f, 1.0f}};
  {
    Imf::RgbaOutputFile out((s.dir / "t.exr").c_str(), 2, 2, Imf::WRITE_RGBA);
    out.setFrameBuffer(px.data(), 1, 2);
    out.writePixels(2);
  }
  const ImportedMesh m = import_with_texture(s.dir, "t.exr");
  ASSERT_EQ(m.textures.size(), 1u) << (m.dropped.empty() ? "" : m.dropped[0]);
  std::vector<std::uint8_t> want;
  for (const Imf::Rgba& p : px)
    for (const half c : {p.r, p.g, p.b}) want.push_back(encode_srgb8(float(c)));
  EXPECT_EQ(m.textures[0].texels, want);
  EXPECT_EQ(want[0], 188);  // linear 0.5 is sRGB 188
  EXPECT_EQ(want[4], 255);
}

TEST(TextureFormats, RadianceHdrIsLinearAndEncodedAsSrgb) {
  REQUIRE_MODELS();
  Scratch s;
  // Two flat RGBE texels (a width under 8 is never run-length encoded): mantissas / 256 times
  // 2^(exponent - 128): (0.5, 0.25, 1) and (0.125, 0, 0.0625).
  std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
  hdr += std::string("\x40\x20\x80\x81\x40\x00\x20\x7f", 8);
  write(s.dir / "t.hdr", hdr);
  const ImportedMesh m = import_with_texture(s.dir, "t.hdr");
  ASSERT_EQ(m.textures.size(), 1u) << (m.dropped.empty() ? "" : m.dropped[0]);
  EXPECT_EQ(m.textures[0].texels, rgb({encode_srgb8(0.5f), encode_srgb8(0.25f), 255,
                                       encode_srgb8(0.125f), 0, encode_srgb8(0.0625f)}));
}

TEST(TextureFormats, ABmpCutShortIsRefusedAndTheWholeOneRead) {
  REQUIRE_MODELS();
  Scratch s;
  const fs::path bmp = kModels / "MD2/sydney.bmp";
  fs::copy_file(bmp, s.dir / "whole.bmp");
  const ImportedMesh m = import_with_texture(s.dir, "whole.bmp");
  ASSERT_EQ(m.textures.size(), 1u) << (m.dropped.empty() ? "" : m.dropped[0]);
  EXPECT_EQ(m.textures[0].width, 308u);
  EXPECT_EQ(m.textures[0].height, 193u);
  std::ifstream in(bmp, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), {}};
  write(s.dir / "short.bmp", bytes.substr(0, bytes.size() - 1));
  const ImportedMesh c = import_with_texture(s.dir, "short.bmp");
  EXPECT_TRUE(c.textures.empty());
  ASSERT_EQ(c.dropped.size(), 1u);
  EXPECT_NE(c.dropped[0].find("ends before its texels do"), std::string::npos) << c.dropped[0];
}

// spider.fbx names its textures by absolute Windows paths of the machine it was made on
// ("D:\\projects\\...\\OBJ\\drkwood2.jpg"): with the images beside it, they are read by file
// name, and one warning says so.
TEST(TextureFormats, PathsFromAnotherMachineAreReadByFileNameWithAWarning) {
  REQUIRE_MODELS();
  Scratch s;
  fs::copy_file(kModels / "FBX/spider.fbx", s.dir / "spider.fbx");
  const ImportedMesh none = import_mesh((s.dir / "spider.fbx").string());
  EXPECT_TRUE(none.textures.empty());
  for (const fs::directory_entry& e : fs::directory_iterator(kModels / "OBJ"))
    if (e.path().extension() == ".jpg") fs::copy_file(e.path(), s.dir / e.path().filename());
  const ImportedMesh m = import_mesh((s.dir / "spider.fbx").string());
  EXPECT_EQ(m.textures.size(), 4u);  // four materials, four images
  std::string all;
  for (const std::string& line : m.dropped) all += line + "\n";
  const auto at = all.find("textures not where the file says, read by file name beside it");
  ASSERT_NE(at, std::string::npos) << all;
  EXPECT_NE(all.find("'D:\\projects", at), std::string::npos) << all;
  EXPECT_EQ(all.find("cannot be read"), std::string::npos) << all;
}

// The COLLADA duck's texture is a TGA: read, so the duck renders textured.
TEST(TextureFormats, TheColladaDuckIsTextured) {
  REQUIRE_MODELS();
  const ImportedMesh m = import_mesh((kModels / "Collada/duck.dae").string());
  ASSERT_EQ(m.textures.size(), 1u);
  EXPECT_EQ(m.textures[0].width, 512u);
  EXPECT_EQ(m.textures[0].height, 512u);
  for (const std::string& line : m.dropped)
    EXPECT_EQ(line.find("cannot be read"), std::string::npos) << line;
}

}  // namespace texture_formats_test
}  // namespace amalgam

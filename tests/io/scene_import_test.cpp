// What a mesh import brings beyond triangles (docs/import.md): base-colour textures (sampled
// at the counted hit, baked as their mean), glTF cameras and the view options, point and
// directional lights, and one warning line for each kind of content that is not rendered.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <variant>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/shading.h"
#include "amalgam/scene/texture.h"

namespace amalgam {
namespace {

namespace fs = std::filesystem;
const fs::path kGltf = "/usr/share/assimp/models/glTF2";

#define REQUIRE_GLTF_MODELS()          \
  ASSERT_TRUE(fs::is_directory(kGltf)) \
      << kGltf << " is missing: install Debian's assimp-testmodels package (scripts/deps.sh)"

/// A 2 x 1 texture: left texel `l`, right texel `r` (sRGB bytes).
Texture two_texels(std::uint8_t l, std::uint8_t r, Wrap wrap = Wrap::kRepeat) {
  Texture t;
  t.width = 2, t.height = 1;
  t.texels = {l, l, l, r, r, r};
  t.wrap_u = t.wrap_v = wrap;
  finish_texture(t);
  return t;
}

TEST(Texture, SrgbDecodingAndMean) {
  EXPECT_EQ(srgb_to_linear(0), 0.0f);
  EXPECT_EQ(srgb_to_linear(255), 1.0f);
  EXPECT_NEAR(srgb_to_linear(128), 0.2158605f, 1e-6f);  // IEC 61966-2-1
  const Texture t = two_texels(0, 255);
  EXPECT_NEAR(t.mean.x, 0.5f, 1e-7f);  // the mean of the linear values, not of the bytes
}

TEST(Texture, BilinearBetweenTexelCentresWithWrapModes) {
  const Texture t = two_texels(0, 255);
  // Texel centres at u = 0.25 and 0.75; halfway between them: the mean.
  EXPECT_NEAR(sample(t, 0.25f, 0.5f).x, 0.0f, 1e-6f);
  EXPECT_NEAR(sample(t, 0.75f, 0.5f).x, 1.0f, 1e-6f);
  EXPECT_NEAR(sample(t, 0.5f, 0.5f).x, 0.5f, 1e-6f);
  EXPECT_NEAR(sample(t, 0.625f, 0.5f).y, 0.75f, 1e-6f);
  // Repeat: u = 0 lies between the right texel (wrapped round) and the left one.
  EXPECT_NEAR(sample(t, 0.0f, 0.5f).x, 0.5f, 1e-6f);
  EXPECT_NEAR(sample(t, 3.25f, 7.0f).x, 0.0f, 1e-6f);
  // Clamp to the edge: left of the first centre is the first texel.
  const Texture c = two_texels(0, 255, Wrap::kClamp);
  EXPECT_NEAR(sample(c, 0.0f, 0.5f).x, 0.0f, 1e-6f);
  EXPECT_NEAR(sample(c, -5.0f, 0.5f).x, 0.0f, 1e-6f);
  EXPECT_NEAR(sample(c, 9.0f, 0.5f).x, 1.0f, 1e-6f);
  // Mirror: [1, 2) shows the image reversed.
  const Texture m = two_texels(0, 255, Wrap::kMirror);
  EXPECT_NEAR(sample(m, 1.25f, 0.5f).x, 1.0f, 1e-6f);
  EXPECT_NEAR(sample(m, 1.75f, 0.5f).x, 0.0f, 1e-6f);
  // Not finite: a colour of the image, never a crash.
  const float nan = std::nanf("");
  EXPECT_TRUE(std::isfinite(sample(t, nan, INFINITY).x));
}

TEST(Texture, TriangleHitCarriesTheBarycentricsOfItsPoint) {
  const Vec3 a{0, 0, 0}, b{4, 0, 0}, c{0, 2, 0};
  const auto hit = intersect_triangle(Ray::make({1, 0.5f, 3}, {0, 0, -1}), a, b, c);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->b1, 0.25f, 1e-6f);  // weight of b: x / 4
  EXPECT_NEAR(hit->b2, 0.25f, 1e-6f);  // weight of c: y / 2
}

/// A unit quad in z = 0 of two triangles whose texture coordinates map it onto
/// [u0, u1] x [0, 1], material 0 textured with `tex` and colour factor `factor`.
ExplicitHierarchy textured_quad(const Texture& tex, Vec3 factor, const BuildConfig& cfg = {},
                                float u0 = 0.0f, float u1 = 1.0f) {
  std::vector<Primitive> prims = {Primitive::triangle({0, 0, 0}, {1, 0, 0}, {1, 1, 0}),
                                  Primitive::triangle({0, 0, 0}, {1, 1, 0}, {0, 1, 0})};
  TexCoords t0, t1;
  t0.u[0] = u0, t0.v[0] = 0, t0.u[1] = u1, t0.v[1] = 0, t0.u[2] = u1, t0.v[2] = 1;
  t1.u[0] = u0, t1.v[0] = 0, t1.u[1] = u1, t1.v[1] = 1, t1.u[2] = u0, t1.v[2] = 1;
  Surface s;
  s.colour = factor;
  s.texture = 0;
  return build_explicit(prims, {s}, cfg, {t0, t1},
                        std::make_shared<const std::vector<Texture>>(std::vector<Texture>{tex}));
}

TEST(Texture, SurfaceAtTheHitIsTheTextureTimesTheFactor) {
  const Texture tex = two_texels(0, 255);
  const ExplicitHierarchy h = textured_quad(tex, {0.5f, 1.0f, 0.25f});
  for (const float x : {0.1f, 0.6f, 0.9f}) {
    const Ray ray = Ray::make({x, 0.3f, 1}, {0, 0, -1});
    for (PrimId p = 0; p < h.prims.size(); ++p) {
      const auto hit = h.intersect(p, ray);
      if (!hit) continue;
      const Surface s = surface_at(h, p, *hit);
      const Vec3 want = sample(tex, x, 0.3f) * Vec3{0.5f, 1.0f, 0.25f};
      EXPECT_NEAR(s.colour.x, want.x, 1e-5f) << x;
      EXPECT_NEAR(s.colour.z, want.z, 1e-5f) << x;
      EXPECT_EQ(s.texture, -1);
    }
  }
}

TEST(Texture, MeanOverATriangleMatchesDenseSampling) {
  Texture t;
  t.width = 3, t.height = 2;
  t.texels = {10, 200, 30, 250, 0, 90, 60, 60, 60, 255, 255, 255, 0, 0, 0, 128, 20, 200};
  finish_texture(t);
  TexCoords c;
  c.u[0] = -0.3f, c.v[0] = 0.1f, c.u[1] = 1.7f, c.v[1] = 0.4f, c.u[2] = 0.5f, c.v[2] = 2.2f;
  // Reference: 800 x 800 grid of barycentric points, inside the triangle.
  Vec3 ref{};
  int n = 0;
  for (int i = 0; i < 800; ++i)
    for (int j = 0; i + j < 800; ++j) {
      float u, v;
      interpolate(c, (static_cast<float>(i) + 0.3f) / 800.0f,
                  (static_cast<float>(j) + 0.3f) / 800.0f, u, v);
      ref += sample(t, u, v);
      ++n;
    }
  ref = ref / static_cast<float>(n);
  const Vec3 got = mean_over_triangle(t, c);
  EXPECT_NEAR(got.x, ref.x, 0.01f);
  EXPECT_NEAR(got.y, ref.y, 0.01f);
  EXPECT_NEAR(got.z, ref.z, 0.01f);
}

BuildConfig bake_rays(int rays) {
  BuildConfig cfg;
  cfg.bake.rays = rays;
  return cfg;
}

TEST(Texture, AmalgamsBakeTheMeanTextureColourTimesTheFactor) {
  const Vec3 factor{0.5f, 1.0f, 0.25f};
  // A texture mapped once onto its geometry: the mean over the texels. (A 2 x 2 checker, the
  // same on both sides of the quad's diagonal, so that both triangles have that mean.)
  Texture checker;
  checker.width = 2, checker.height = 2;
  checker.texels = {40, 40, 40, 230, 230, 230, 230, 230, 230, 40, 40, 40};
  finish_texture(checker);
  const ExplicitHierarchy h = textured_quad(checker, factor, bake_rays(64));
  const Vec3 want = checker.mean * factor;
  const Vec3 got = h.appearances[0].surface.colour;
  EXPECT_NEAR(got.x, want.x, 0.01f * want.x);
  EXPECT_NEAR(got.y, want.y, 0.01f * want.y);
  EXPECT_NEAR(got.z, want.z, 0.01f * want.z);
  EXPECT_EQ(h.appearances[0].surface.texture, -1);
  // Part of an atlas: the mean over the area the coordinates cover, not over all texels. Texels
  // dark, dark, bright, bright, clamped; the quad shows u in [0.125, 0.375]: dark only.
  Texture atlas;
  atlas.width = 4, atlas.height = 1;
  atlas.texels = {20, 20, 20, 20, 20, 20, 240, 240, 240, 240, 240, 240};
  atlas.wrap_u = atlas.wrap_v = Wrap::kClamp;
  finish_texture(atlas);
  const ExplicitHierarchy part = textured_quad(atlas, factor, bake_rays(64), 0.125f, 0.375f);
  const Vec3 dark = Vec3{1, 1, 1} * srgb_to_linear(20) * factor;
  EXPECT_NEAR(part.appearances[0].surface.colour.x, dark.x, 1e-6f);
  EXPECT_NEAR(part.appearances[0].surface.colour.z, dark.z, 1e-6f);
  EXPECT_GT(atlas.mean.x * factor.x, 10.0f * dark.x);  // what the texels' mean would give
}

TEST(Texture, CopiesOfATexturedTriangleBakeItsColourAndOthersTheirOwn) {
  // The bake computes a texture's mean once per distinct (material, coordinates): copies share
  // it, and any other coordinates or material get their own. Three variants of one small
  // triangle (over the dark texels only, over the bright ones, the dark ones under a second
  // material), each copied 1,500 times far apart (4,500 triangles: the parallel path), one
  // triangle per leaf, so that every leaf's colour is its triangle's.
  Texture tex;  // texels dark, dark, bright, bright, clamped
  tex.width = 4, tex.height = 1;
  tex.texels = {20, 20, 20, 20, 20, 20, 240, 240, 240, 240, 240, 240};
  tex.wrap_u = tex.wrap_v = Wrap::kClamp;
  finish_texture(tex);
  Surface dim, bright;
  dim.colour = {0.5f, 0.5f, 0.5f}, dim.texture = 0;
  bright.colour = {1.0f, 0.25f, 1.0f}, bright.texture = 0;
  TexCoords left, right;
  left.u[0] = 0.05f, left.u[1] = 0.35f, left.u[2] = 0.05f;     // dark texels only
  right.u[0] = 0.65f, right.u[1] = 0.95f, right.u[2] = 0.65f;  // bright only
  for (TexCoords* c : {&left, &right}) c->v[0] = 0.1f, c->v[1] = 0.1f, c->v[2] = 0.9f;
  struct Variant {
    TexCoords uv;
    std::uint32_t material;
  };
  const Variant variants[3] = {{left, 0}, {right, 0}, {left, 1}};
  std::vector<Primitive> prims;
  std::vector<TexCoords> uvs;
  for (int k = 0; k < 4500; ++k) {
    const Vec3 at{static_cast<float>(k % 75) * 3.0f, static_cast<float>(k / 75) * 3.0f, 0};
    prims.push_back(
        Primitive::triangle(at, at + Vec3{1, 0, 0}, at + Vec3{0, 1, 0}, variants[k % 3].material));
    uvs.push_back(variants[k % 3].uv);
  }
  auto textures = std::make_shared<const std::vector<Texture>>(std::vector<Texture>{tex});
  for (const bool parallel : {true, false}) {
    BuildConfig cfg;
    cfg.leaf_size = 1;
    cfg.parallel = parallel;
    cfg.bake.rays = 32;
    const ExplicitHierarchy h = build_explicit(prims, {dim, bright}, cfg, uvs, textures);
    const Vec3 want[3] = {dim.colour * srgb_to_linear(20), dim.colour * srgb_to_linear(240),
                          bright.colour * srgb_to_linear(20)};
    int checked = 0;
    for (std::size_t i = 0; i < h.nodes.size(); ++i) {
      const ExplicitNode& n = h.nodes[i];
      if (!n.leaf || h.appearances[i].opacity == 0.0f) continue;
      ASSERT_EQ(n.count, 1u);
      const PrimId p = n.first;
      const int v = (h.uvs[p].u[0] > 0.5f ? 1 : 0) + (h.prims[p].material == 1 ? 2 : 0);
      ASSERT_LT(v, 3);
      const Vec3 got = h.appearances[i].surface.colour;
      ASSERT_NEAR(got.x, want[v].x, 1e-5f) << "leaf " << i << ", variant " << v;
      ASSERT_NEAR(got.y, want[v].y, 1e-5f) << "leaf " << i << ", variant " << v;
      ++checked;
    }
    EXPECT_GT(checked, 4000) << parallel;
  }
}

TEST(Texture, BoxTexturedImportsItsTextureAndEveryVariantTheSameImage) {
  REQUIRE_GLTF_MODELS();
  const ImportedMesh plain = import_mesh((kGltf / "BoxTextured-glTF/BoxTextured.gltf").string());
  const ImportedMesh embedded =
      import_mesh((kGltf / "BoxTextured-glTF-Embedded/BoxTextured.gltf").string());
  const ImportedMesh binary =
      import_mesh((kGltf / "BoxTextured-glTF-Binary/BoxTextured.glb").string());
  for (const ImportedMesh* m : {&plain, &embedded, &binary}) {
    ASSERT_EQ(m->textures.size(), 1u);
    EXPECT_EQ(m->textures[0].width, 211u);  // CesiumLogoFlat.png
    EXPECT_EQ(m->textures[0].height, 211u);
    EXPECT_EQ(m->uvs.size(), m->triangles.size());
    EXPECT_EQ(m->materials[m->triangles[0].material].texture, 0);
    EXPECT_TRUE(m->dropped.empty()) << m->dropped.front();  // everything in it is rendered
  }
  // The file beside the mesh, a data URI and a .glb buffer: the same texels.
  EXPECT_EQ(plain.textures[0].texels, embedded.textures[0].texels);
  EXPECT_EQ(binary.textures[0].texels, embedded.textures[0].texels);
  // The plain variant's sampler mirrors u and clamps v; the others repeat (as their files say).
  EXPECT_EQ(plain.textures[0].wrap_u, Wrap::kMirror);
  EXPECT_EQ(plain.textures[0].wrap_v, Wrap::kClamp);
  EXPECT_EQ(embedded.textures[0].wrap_u, Wrap::kRepeat);
  // The Cesium logo: white, blue and green areas.
  const Texture& t = embedded.textures[0];
  std::size_t blue = 0, green = 0;
  for (std::size_t i = 0; i < t.texels.size(); i += 3) {
    const int r = t.texels[i], g = t.texels[i + 1], b = t.texels[i + 2];
    blue += b > r + 60 && b > g;
    green += g > r + 40 && g > b + 40;
  }
  const std::size_t n = t.texels.size() / 3;
  EXPECT_GT(blue, n / 10);
  EXPECT_GT(green, n / 10);
}

TEST(Texture, TexturesAreInTheContentHash) {
  REQUIRE_GLTF_MODELS();
  const std::string path = (kGltf / "BoxTextured-glTF-Embedded/BoxTextured.gltf").string();
  SceneDescription d = mesh_scene(path);
  SceneDescription changed = d;
  changed.textures[0].texels[12345] ^= 1;
  const auto hash = [&](SceneDescription s) {
    LoadedScene l{"box", build_hierarchy(std::move(s)), Environment{}};
    return content_hash(l);
  };
  const std::uint64_t h0 = hash(d);
  EXPECT_EQ(hash(d), h0);
  EXPECT_NE(hash(changed), h0);
  SceneDescription moved = d;
  moved.uvs[3].u[1] += 0.125f;
  EXPECT_NE(hash(moved), h0);
}

TEST(Texture, ObjDiffuseMapsWithWindowsPathsAreRead) {
  REQUIRE_GLTF_MODELS();
  const ImportedMesh m = import_mesh("/usr/share/assimp/models/OBJ/spider.obj");
  EXPECT_EQ(m.textures.size(), 5u);  // map_Kd .\name.jpg, five JPEG files
  EXPECT_EQ(m.uvs.size(), m.triangles.size());
  EXPECT_TRUE(m.dropped.empty()) << m.dropped.front();
}

fs::path scratch_dir() {
  const fs::path d =
      fs::temp_directory_path() / ("amalgam_scene_import_" + std::to_string(getpid()));
  fs::create_directories(d);
  return d;
}

struct Scratch {
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(scratch_dir(), ec);
  }
} g_scratch;

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

TEST(Texture, AMissingTextureIsOneWarningAndTheBaseColour) {
  REQUIRE_GLTF_MODELS();
  const fs::path d = scratch_dir() / "missing";
  fs::create_directories(d);
  fs::copy_file(kGltf / "BoxTextured-glTF/BoxTextured.gltf", d / "BoxTextured.gltf");
  fs::copy_file(kGltf / "BoxTextured-glTF/BoxTextured0.bin", d / "BoxTextured0.bin");
  const ImportedMesh m = import_mesh((d / "BoxTextured.gltf").string());
  EXPECT_TRUE(m.textures.empty());
  EXPECT_TRUE(m.uvs.empty());
  ASSERT_EQ(m.dropped.size(), 1u);
  EXPECT_NE(m.dropped[0].find("CesiumLogoFlat.png"), std::string::npos) << m.dropped[0];
  EXPECT_NE(m.dropped[0].find("no such file"), std::string::npos) << m.dropped[0];
  // A corrupt image: the same, with the decoder's reason (decoded in the helper, not here).
  write(d / "CesiumLogoFlat.png", "\x89PNG\r\n\x1a\n this is not a PNG stream");
  const ImportedMesh c = import_mesh((d / "BoxTextured.gltf").string());
  EXPECT_TRUE(c.textures.empty());
  ASSERT_EQ(c.dropped.size(), 1u);
  EXPECT_NE(c.dropped[0].find("corrupt PNG data"), std::string::npos) << c.dropped[0];
}

TEST(Texture, ObjCorruptJpegAndMissingCoordinatesWarnAndRender) {
  REQUIRE_GLTF_MODELS();
  const fs::path d = scratch_dir() / "obj";
  fs::create_directories(d);
  write(d / "m.mtl", "newmtl bad\nKd 0.5 0.25 1\nmap_Kd bad.jpg\nnewmtl good\nmap_Kd good.jpg\n");
  // A JPEG that fails in its header (libjpeg's error exit, not a crash); real JPEG texels.
  write(d / "bad.jpg", std::string("\xff\xd8\xff\xe0\x00\x02garbage", 14));
  fs::copy_file("/usr/share/assimp/models/OBJ/SpiderTex.jpg", d / "good.jpg");
  write(d / "a.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
        "usemtl bad\nf 1/1 2/2 3/3\n");
  const ImportedMesh a = import_mesh((d / "a.obj").string());
  EXPECT_EQ(a.textures.size(), 1u);  // good.jpg: every material of the library is read
  EXPECT_EQ(a.materials[a.triangles[0].material].texture, -1);
  ASSERT_EQ(a.dropped.size(), 1u);
  EXPECT_NE(a.dropped[0].find("corrupt JPEG data"), std::string::npos) << a.dropped[0];
  EXPECT_NE(a.dropped[0].find("'bad.jpg'"), std::string::npos) << a.dropped[0];
  EXPECT_EQ(a.materials[a.triangles[0].material].colour, (Vec3{0.5f, 0.25f, 1.0f}));
  // A textured material on a mesh without texture coordinates: its colour alone, said once.
  write(d / "b.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl good\nf 1 2 3\n");
  const ImportedMesh b = import_mesh((d / "b.obj").string());
  ASSERT_EQ(b.textures.size(), 1u);
  EXPECT_EQ(b.materials[b.triangles[0].material].texture, -1);
  ASSERT_EQ(b.dropped.size(), 2u);  // bad.jpg again, and the coordinates
  EXPECT_NE(b.dropped[1].find("no texture coordinates"), std::string::npos) << b.dropped[1];
}

// Textures are hostile input too: an image that claims 65535 x 65535 texels (refused from
// its header, before any texel is allocated), a PNG, a JPEG and a TGA cut in half (each
// decoder would fill the rest in), a file in no image format: each is one warning naming it,
// its material renders with its colour, the rest of the mesh imports, quickly.
TEST(Texture, HostileAndTruncatedImagesAreOneWarningEachAndTheColour) {
  REQUIRE_GLTF_MODELS();
  const fs::path d = scratch_dir() / "hostile";
  fs::create_directories(d);
  const char huge_png[] =
      "\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\xff\xff\x00\x00"
      "\xff\xff\x08\x02\x00\x00\x00\x39\x67\x4e\x07\x00\x00\x00\x0b\x49\x44\x41\x54\x78\x9c\x63"
      "\x60\x40\x05\x00\x00\x10\x00\x01\x39\xbd\x8f\x65\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42"
      "\x60\x82";
  write(d / "huge.png", std::string(huge_png, sizeof huge_png - 1));
  auto half_of = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), {}};
    return bytes.substr(0, bytes.size() / 2);
  };
  write(d / "half.png", half_of(kGltf / "BoxTextured-glTF/CesiumLogoFlat.png"));
  write(d / "half.jpg", half_of("/usr/share/assimp/models/OBJ/SpiderTex.jpg"));
  write(d / "half.tga", half_of("/usr/share/assimp/models/Collada/duckCM.tga"));
  write(d / "notes.txt", "a text file named as a texture\n");
  std::string mtl, obj = "mtllib m.mtl\nvt 0 0\nvt 1 0\nvt 0 1\n";
  const char* images[] = {"huge.png", "half.png", "half.jpg", "half.tga", "notes.txt"};
  for (int i = 0; i < 5; ++i) {
    mtl += "newmtl m" + std::to_string(i) + "\nKd 0.5 0.25 " + std::to_string(0.2 * (i + 1)) +
           "\nmap_Kd " + images[i] + "\n";
    obj += "v " + std::to_string(2 * i) + " 0 0\nv " + std::to_string(2 * i + 1) + " 0 0\nv " +
           std::to_string(2 * i) + " 1 0\nusemtl m" + std::to_string(i) + "\nf " +
           std::to_string(3 * i + 1) + "/1 " + std::to_string(3 * i + 2) + "/2 " +
           std::to_string(3 * i + 3) + "/3\n";
  }
  write(d / "m.mtl", mtl);
  write(d / "a.obj", obj);
  const auto t0 = std::chrono::steady_clock::now();
  const ImportedMesh m = import_mesh((d / "a.obj").string());
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(10));
  ASSERT_EQ(m.triangles.size(), 5u);
  for (const Primitive& t : m.triangles) {
    const Surface& s = m.materials[t.material];
    EXPECT_EQ(s.texture, -1);
    EXPECT_EQ(s.colour.x, 0.5f);
  }
  std::string all;
  for (const std::string& line : m.dropped) all += line + "\n";
  for (const char* image : images)
    EXPECT_NE(all.find(std::string("'") + image + "'"), std::string::npos) << image << "\n" << all;
  EXPECT_NE(all.find("65535x65535 texels"), std::string::npos) << all;
  EXPECT_NE(all.find("ends before its texels do"), std::string::npos) << all;
  EXPECT_NE(all.find("not an image format amalgam reads"), std::string::npos) << all;
}

TEST(GltfCamera, TheFirstPerspectiveCameraAsTheFileGivesIt) {
  REQUIRE_GLTF_MODELS();
  const std::string path = (kGltf / "cameras/Cameras.gltf").string();
  const SceneDescription d = mesh_scene(path);
  ASSERT_EQ(d.cameras.size(), 1u);  // the second is orthographic
  EXPECT_EQ(d.cameras[0].name, "nodes[1]");
  const Camera& c = d.env.camera;
  // Node translation (0.5, 0.5, 3); looking down -z; yfov 0.7 rad.
  EXPECT_EQ(c.position, (Vec3{0.5f, 0.5f, 3.0f}));
  EXPECT_EQ(normalize(c.look_at - c.position), (Vec3{0, 0, -1}));
  EXPECT_EQ(c.up, (Vec3{0, 1, 0}));
  EXPECT_NEAR(c.vfov_deg, 0.7 * 180.0 / std::numbers::pi, 1e-4);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find("orthographic"), std::string::npos) << d.warnings[0];
  EXPECT_NE(d.warnings[0].find("'nodes[2]'"), std::string::npos) << d.warnings[0];
}

TEST(GltfCamera, ChooseCameraByNameIndexAndOverride) {
  REQUIRE_GLTF_MODELS();
  LoadedScene s = load_scene_path((kGltf / "cameras/Cameras.gltf").string());
  const Camera file = s.env.camera;
  const std::uint64_t h0 = content_hash(s);
  choose_camera(s, {"nodes[1]", {}, {}, {}, {}});
  EXPECT_EQ(s.env.camera.position, file.position);
  choose_camera(s, {"0", {}, {}, {}, {}});
  EXPECT_EQ(content_hash(s), h0);
  for (const char* bad : {"1", "nodes[2]", "x", "-1"}) {
    try {
      choose_camera(s, {bad, {}, {}, {}, {}});
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cameras: 0 'nodes[1]'"), std::string::npos) << e.what();
    }
  }
  // The override is part of the content hash (so of a checkpoint's fingerprint).
  choose_camera(s, {"", Vec3{0.5f, 0.5f, 5}, {}, {}, 30.0f});
  EXPECT_EQ(s.env.camera.position, (Vec3{0.5f, 0.5f, 5}));
  EXPECT_EQ(s.env.camera.vfov_deg, 30.0f);
  EXPECT_EQ(s.env.camera.look_at, file.look_at);
  EXPECT_NE(content_hash(s), h0);
  EXPECT_THROW(choose_camera(s, {"", {}, Vec3{0.5f, 0.5f, 5}, {}, {}}), InputError);  // at eye
  EXPECT_THROW(choose_camera(s, {"", {}, {}, Vec3{0, 0, 1}, {}}), InputError);        // along view
  EXPECT_THROW(choose_camera(s, {"", {}, {}, {}, 180.0f}), InputError);
}

TEST(GltfCamera, DefaultLightsFollowAChosenView) {
  REQUIRE_GLTF_MODELS();
  LoadedScene s = load_scene_path((kGltf / "BoxTextured-glTF-Embedded/BoxTextured.gltf").string());
  ASSERT_TRUE(s.default_lights);
  EXPECT_THROW(choose_camera(s, {"0", {}, {}, {}, {}}), InputError);  // the file has none
  choose_camera(s, {"", Vec3{0, 0, 4}, Vec3{0, 0, 0}, {}, {}});
  ASSERT_EQ(s.env.lights.size(), 2u);
  EXPECT_EQ(s.env.lights[1].position, (Vec3{0, 0, 4}));  // the fill light at the eye
}

// A mesh without a camera (an STL, whose up axis is z) framed by --up alone: the same 3/4 view
// about z (camera above along z, in front on the -y side), lights turned with it; with +y, the
// default view exactly.
TEST(DefaultView, UpAloneFramesTheMeshAboutThatUp) {
  REQUIRE_GLTF_MODELS();
  LoadedScene s = load_scene_path("/usr/share/assimp/models/STL/Spider_binary.stl");
  ASSERT_TRUE(s.framed_camera);
  const Camera y_up = s.env.camera;
  const Vec3 key_y = s.env.lights[0].direction;
  const Bbox b = std::visit([](const auto& h) { return h.bounds(h.root()); }, s.hierarchy);
  const Vec3 centre = b.center();
  EXPECT_GT(y_up.position.y, centre.y);
  choose_camera(s, {"", {}, {}, Vec3{0, 1, 0}, {}});
  EXPECT_EQ(s.env.camera.position, y_up.position);
  EXPECT_EQ(s.env.lights[0].direction, key_y);
  choose_camera(s, {"", {}, {}, Vec3{0, 0, 2}, {}});
  const Camera& z_up = s.env.camera;
  EXPECT_EQ(z_up.up, (Vec3{0, 0, 2}));
  EXPECT_EQ(z_up.look_at, centre);
  EXPECT_GT(z_up.position.z - centre.z, 0.3f * length(z_up.position - centre));  // above
  EXPECT_LT(z_up.position.y, centre.y);                                          // in front
  EXPECT_NEAR(length(z_up.position - centre), length(y_up.position - centre), 1e-3f);
  EXPECT_LT(s.env.lights[0].direction.z, -0.5f);  // the key light shines down along z
  // With --eye, --up only sets the camera's up, as for any camera.
  choose_camera(s, {"", Vec3{0, -30, 5}, {}, Vec3{0, 0, 1}, {}});
  EXPECT_EQ(s.env.camera.position, (Vec3{0, -30, 5}));
}

/// One triangle with three KHR_lights_punctual lights: a point light, a directional light
/// pointing down, a spot light pointing down from (1, 4, 0).
constexpr const char* kLightsGltf = R"({
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {"KHR_lights_punctual": {"lights": [
    {"type": "point", "color": [1, 0.5, 0.25], "intensity": 20},
    {"type": "directional", "intensity": 3},
    {"type": "spot", "intensity": 5, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}]}},
  "scenes": [{"nodes": [0, 1, 2, 3]}],
  "nodes": [
    {"mesh": 0},
    {"name": "bulb", "translation": [0, 2, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}},
    {"name": "sun", "rotation": [-0.70710678, 0, 0, 0.70710678],
     "extensions": {"KHR_lights_punctual": {"light": 1}}},
    {"name": "torch", "translation": [1, 4, 0], "rotation": [-0.70710678, 0, 0, 0.70710678],
     "extensions": {"KHR_lights_punctual": {"light": 2}}}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"byteLength": 36,
    "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}]
})";

TEST(GltfLights, PointDirectionalAndSpotLightsInTheSceneUnits) {
  const fs::path p = scratch_dir() / "lights.gltf";
  write(p, kLightsGltf);
  const SceneDescription d = mesh_scene(p.string());
  EXPECT_FALSE(d.default_lights);
  ASSERT_EQ(d.env.lights.size(), 3u);
  const Light& point = d.env.lights[0];
  EXPECT_EQ(point.kind, LightKind::kPoint);
  EXPECT_EQ(point.position, (Vec3{0, 2, 3}));
  EXPECT_EQ(point.intensity, (Vec3{20, 10, 5}));  // colour x intensity (cd) as W/sr
  const Light& sun = d.env.lights[1];
  EXPECT_EQ(sun.kind, LightKind::kDirectional);
  EXPECT_NEAR(sun.direction.y, -1.0f, 1e-6f);
  EXPECT_NEAR(std::fabs(sun.direction.z), 0.0f, 1e-6f);
  EXPECT_EQ(sun.intensity, (Vec3{3, 3, 3}));  // lux as irradiance
  // The spot light: at its node, along its node's -z (turned to point down), with glTF's
  // half-angles from the axis.
  const Light& spot = d.env.lights[2];
  EXPECT_EQ(spot.kind, LightKind::kSpot);
  EXPECT_EQ(spot.position, (Vec3{1, 4, 0}));
  EXPECT_NEAR(spot.direction.y, -1.0f, 1e-6f);
  EXPECT_EQ(spot.intensity, (Vec3{5, 5, 5}));
  EXPECT_NEAR(spot.cos_inner, std::cos(0.2f), 1e-6f);
  EXPECT_NEAR(spot.cos_outer, std::cos(0.5f), 1e-6f);
  EXPECT_TRUE(d.warnings.empty()) << d.warnings[0];
}

TEST(GltfLights, SkinsAndAnimationsWarnOnceEach) {
  REQUIRE_GLTF_MODELS();
  const SceneDescription d = mesh_scene((kGltf / "simple_skin/simple_skin.gltf").string());
  ASSERT_EQ(d.warnings.size(), 2u);
  const auto has = [&](const char* what) {
    return std::count_if(d.warnings.begin(), d.warnings.end(),
                         [&](const std::string& w) { return w.find(what) != std::string::npos; });
  };
  EXPECT_EQ(has("skins ignored"), 1);
  EXPECT_EQ(has("animations ignored"), 1);
}

}  // namespace
}  // namespace amalgam

// End-to-end: scenes imported faithfully (docs/import.md). Textured glTF renders textured,
// the cameras of glTF and other formats and the view options, one warning line per dropped
// kind of content, the --camera errors, `info`, and the warning on a view that shows nothing.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "amalgam/io/image.h"
#include "cli_support.h"

namespace {
namespace import_cli {  // per file: the tests are compiled in batches

namespace fs = std::filesystem;
const fs::path kGltf = "/usr/share/assimp/models/glTF2";

struct CliResult {
  int status;
  std::string err;
};

fs::path scratch() {
  return amalgam::test::scratch_dir("amalgam-import-cli");
}

/// Runs the binary with `args` (shell-quoted); stdout discarded, stderr returned.
CliResult run(const std::string& args) {
  const fs::path err = scratch() / "stderr.txt";
  const int status = amalgam::test::run_command(std::string(AMALGAM_BINARY) + " " + args +
                                                " >/dev/null 2>" + err.string())
                         .status;
  return {status, amalgam::test::slurp(err)};
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// Renders `scene` (quoted into the command) at 96 x 96, 1 spp, traditional (every hit a
/// primitive, so textures show at full detail), with `extra` options; returns the PNG's path.
fs::path render(const std::string& scene, const std::string& name, const std::string& extra = "") {
  const fs::path out = scratch() / (name + ".png");
  const CliResult r = run("render '" + scene + "' --renderer traditional --width 96 --height 96 " +
                          "--spp 1 --quiet --out " + out.string() + " " + extra);
  EXPECT_EQ(r.status, 0) << r.err;
  return out;
}

std::vector<amalgam::Vec3> pixels(const fs::path& png) {
  int w = 0, h = 0;
  return amalgam::read_image(png.string(), w, h);
}

std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

/// Variance of the pixels' chroma (each channel minus the pixel's mean): texture colours,
/// not shading, which scales all channels alike.
double chroma_variance(const std::vector<amalgam::Vec3>& px) {
  double sum = 0, sum2 = 0;
  for (const amalgam::Vec3& p : px) {
    const double m = (p.x + p.y + p.z) / 3.0;
    for (const double c : {p.x - m, p.y - m, p.z - m}) sum += c, sum2 += c * c;
  }
  const double n = 3.0 * static_cast<double>(px.size());
  return sum2 / n - (sum / n) * (sum / n);
}

TEST(SceneImportCli, BoxTexturedRendersTexturedAndTheVariantsAlike) {
  ASSERT_TRUE(fs::is_directory(kGltf)) << "install assimp-testmodels (scripts/deps.sh)";
  const std::string gltf = (kGltf / "BoxTextured-glTF-Embedded/BoxTextured.gltf").string();
  const fs::path textured = render(gltf, "textured");
  // The same box with a plain white material (a scene file overriding the mesh's material).
  const fs::path json = scratch() / "white.json";
  std::ofstream(json) << R"({"meshes": [{"file": ")" << gltf
                      << R"(", "material": {"colour": [1, 1, 1]}}]})";
  const fs::path white = render(json.string(), "white");
  // Measured: about 16 times (the white box's chroma is the warm lights on it and the
  // bluish background).
  const double tv = chroma_variance(pixels(textured)), wv = chroma_variance(pixels(white));
  EXPECT_GT(tv, 8.0 * wv) << tv << " vs " << wv;
  // Logo colours on the box: blue and green pixels.
  int blue = 0, green = 0;
  for (const amalgam::Vec3& p : pixels(textured)) {
    blue += p.z > 1.5f * p.x && p.z > p.y;
    green += p.y > 1.5f * p.x && p.y > 1.5f * p.z;
  }
  EXPECT_GT(blue, 200);
  EXPECT_GT(green, 200);
  // A data URI and a .glb buffer: the same image, byte for byte.
  const fs::path glb = render((kGltf / "BoxTextured-glTF-Binary/BoxTextured.glb").string(), "glb");
  EXPECT_EQ(bytes(glb), bytes(textured));
  // The scale-sensitive renderer shows amalgams baked with the texture's mean: still no warning.
  const CliResult r = run("render '" + gltf + "' --width 16 --height 16 --spp 1 --quiet --out " +
                          (scratch() / "far.png").string());
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.err, "");  // nothing dropped, so nothing said
}

TEST(SceneImportCli, CamerasGltfRendersFromItsCamera) {
  ASSERT_TRUE(fs::is_directory(kGltf)) << "install assimp-testmodels (scripts/deps.sh)";
  const std::string gltf = (kGltf / "cameras/Cameras.gltf").string();
  const fs::path from_file = render(gltf, "camera");
  // The file's values given by hand: node translation (0.5, 0.5, 3), looking down -z, yfov
  // 0.7 rad (printed with enough digits to give the same float).
  char fov[32];
  std::snprintf(fov, sizeof fov, "%.9g", 0.7f / 1.0f * (180.0f / std::numbers::pi_v<float>));
  const fs::path by_hand =
      render(gltf, "by_hand",
             std::string("--eye 0.5,0.5,3 --look-at 0.5,0.5,0 --up 0,1,0 ") + "--fov " + fov);
  EXPECT_EQ(bytes(from_file), bytes(by_hand));
  // The default framing of the same mesh (a scene file without a camera) is another view.
  const fs::path json = scratch() / "framed.json";
  std::ofstream(json) << R"({"meshes": [{"file": ")" << gltf << R"("}]})";
  EXPECT_NE(bytes(render(json.string(), "framed")), bytes(from_file));
  // --camera by name and by index: the same camera.
  EXPECT_EQ(bytes(render(gltf, "by_name", "--camera 'nodes[1]'")), bytes(from_file));
  EXPECT_EQ(bytes(render(gltf, "by_index", "--camera 0")), bytes(from_file));
}

TEST(SceneImportCli, EachDroppedKindIsOneWarningLineNamingIt) {
  ASSERT_TRUE(fs::is_directory(kGltf)) << "install assimp-testmodels (scripts/deps.sh)";
  const CliResult r =
      run("render '" + (kGltf / "cameras/Cameras.gltf").string() +
          "' --width 8 --height 8 --spp 1 --quiet --out " + (scratch() / "w.png").string());
  ASSERT_EQ(r.status, 0);
  const auto l = lines(r.err);
  ASSERT_EQ(l.size(), 1u) << r.err;
  EXPECT_EQ(l[0].rfind("amalgam: warning: ", 0), 0u) << l[0];
  EXPECT_NE(l[0].find("orthographic"), std::string::npos) << l[0];
  EXPECT_NE(l[0].find("'nodes[2]'"), std::string::npos) << l[0];
  // Clearcoat, emission, normal maps, ...: one line for each kind, each naming materials.
  const CliResult c = run("trace '" + (kGltf / "ClearCoat-glTF/ClearCoatTest.gltf").string() + "'");
  ASSERT_EQ(c.status, 0);
  const auto cl = lines(c.err);
  EXPECT_GE(cl.size(), 4u) << c.err;
  int clearcoat = 0, emission = 0;
  for (const std::string& line : cl) {
    EXPECT_EQ(line.rfind("amalgam: warning: ", 0), 0u) << line;
    clearcoat += line.find("clearcoat not rendered, materials: '") != std::string::npos;
    emission += line.find("emission not rendered, materials: 'LabelMaterial'") != std::string::npos;
  }
  EXPECT_EQ(clearcoat, 1) << c.err;
  EXPECT_EQ(emission, 1) << c.err;
}

TEST(SceneImportCli, CameraErrorsAreInputErrors) {
  ASSERT_TRUE(fs::is_directory(kGltf)) << "install assimp-testmodels (scripts/deps.sh)";
  const std::string gltf = (kGltf / "cameras/Cameras.gltf").string();
  const std::string out = " --out " + (scratch() / "e.png").string();
  for (const char* bad : {"1", "nope"}) {
    const CliResult r = run("render '" + gltf + "' --camera " + bad + out);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_NE(r.err.find("(cameras: 0 'nodes[1]')"), std::string::npos) << r.err;
  }
  const CliResult b = run("render builtin:demo --camera 0" + out);
  EXPECT_EQ(b.status, 2);
  EXPECT_NE(b.err.find("defines no cameras"), std::string::npos) << b.err;
  EXPECT_EQ(run("trace builtin:demo --fov 0").status, 2);
  EXPECT_EQ(run("trace builtin:demo --eye 1,2").status, 2);
  EXPECT_EQ(run("trace builtin:demo --eye 0,0,0 --look-at 0,0,0").status, 2);
  // The view options work on any scene.
  const CliResult ok = run("trace builtin:demo --eye 0,3,9 --look-at 0,0,0 --fov 30");
  EXPECT_EQ(ok.status, 0) << ok.err;
}

const fs::path kModels = "/usr/share/assimp/models";

/// `amalgam info ARGS`: its standard output.
std::string info(const std::string& args) {
  const fs::path out = scratch() / "info.txt";
  const int status = amalgam::test::run_command(std::string(AMALGAM_BINARY) + " info " + args +
                                                " >" + out.string() + " 2>/dev/null")
                         .status;
  EXPECT_EQ(status, 0) << args;
  return amalgam::test::slurp(out);
}

// The Collada duck faced its unlit side from the default framing: its camera (Assimp's full
// horizontal angle, 54.43 degrees at aspect 1.5) is the view now, with the file's yfov.
TEST(SceneImportCli, InfoPrintsAColladaFilesCameraAndARenderUsesIt) {
  const std::string duck = (kModels / "Collada/duck.dae").string();
  ASSERT_TRUE(fs::is_regular_file(duck)) << "install assimp-testmodels (scripts/deps.sh)";
  const std::string text = info("'" + duck + "'");
  EXPECT_NE(text.find("cameras     1\n  0 'camera1': --eye "), std::string::npos) << text;
  EXPECT_NE(text.find("--fov 37.849"), std::string::npos) << text;
  EXPECT_NE(text.find("render view the file's first camera 'camera1'\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("primitives  4,212 in "), std::string::npos) << text;
  EXPECT_NE(text.find("lights      1\n  directional toward "), std::string::npos) << text;
  const std::string json = info("'" + duck + "' --json");
  EXPECT_NE(json.find("\"render_camera_from\": \"the file's first camera 'camera1'\""),
            std::string::npos)
      << json;
  // The render's default view is that camera, and the duck is lit: yellow pixels.
  const fs::path seen = render(duck, "duck");
  EXPECT_EQ(bytes(seen), bytes(render(duck, "duck0", "--camera 0")));
  int yellow = 0;
  for (const amalgam::Vec3& p : pixels(seen))
    yellow += p.x > 0.3f && p.y > 0.2f && p.z < 0.5f * p.x;
  EXPECT_GT(yellow, 50);  // measured 97 of 9216 pixels
  // A scene file without cameras: its instances and meshes.
  const std::string demo = info("builtin:demo --eye 0,3,9");
  EXPECT_NE(demo.find("the scene's camera, changed by the view options\n  --eye 0,3,9 "),
            std::string::npos)
      << demo;
}

// A view that shows nothing says why in one warning: no camera ray met the scene, or almost
// no light reaches what it sees (Blender's default cube: a lamp of intensity 1 seven units
// away; measured brightest pixel 0.0072).
TEST(SceneImportCli, AViewThatShowsNothingIsOneWarning) {
  const std::string cube = (kModels / "BLEND/BlenderDefault_276.blend").string();
  const std::string wuson = (kModels / "PLY/Wuson.ply").string();
  ASSERT_TRUE(fs::is_regular_file(cube)) << "install assimp-testmodels (scripts/deps.sh)";
  const std::string out =
      " --width 48 --height 36 --spp 1 --quiet --out " + (scratch() / "dark.png").string();
  const CliResult dark = run("render '" + cube + "'" + out);
  ASSERT_EQ(dark.status, 0) << dark.err;
  EXPECT_NE(dark.err.find(": almost no light reaches what the camera sees (brightest pixel 0.00"),
            std::string::npos)
      << dark.err;
  const CliResult away = run("render '" + wuson + "' --eye 0,0,5 --look-at 0,0,10" + out);
  ASSERT_EQ(away.status, 0) << away.err;
  EXPECT_EQ(lines(away.err).size(), 1u) << away.err;
  EXPECT_NE(away.err.find(": no camera ray met the scene"), std::string::npos) << away.err;
  // Lit views say nothing of the kind.
  for (const std::string& lit : {wuson, (kModels / "Collada/duck.dae").string()}) {
    const CliResult r = run("render '" + lit + "'" + out);
    EXPECT_EQ(r.err.find("camera"), std::string::npos) << r.err;
  }
}

}  // namespace import_cli
}  // namespace

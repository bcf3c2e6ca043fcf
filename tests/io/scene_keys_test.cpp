// The scene-file keys of docs/scene-format.md whose effect is on geometry or the camera: `fit`,
// `subdivide`, `rotate_x_deg` / `rotate_y_deg` / `rotate_z_deg` and the camera's `up`. Each is
// checked by what it does (bounds, triangle counts and areas, where the image shows a thing),
// not only by parsing.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "amalgam/io/json_reader.h"
#include "amalgam/io/scene_json.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

namespace fs = std::filesystem;

/// A directory holding box.obj: the closed box [0, 4] x [0, 2] x [0, 1] (12 triangles;
/// three different extents, so every rotation and scale shows in its bounds).
class SceneKeys : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("amalgam_scene_keys_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    std::ofstream(dir_ / "box.obj") << "v 0 0 0\nv 4 0 0\nv 4 2 0\nv 0 2 0\n"
                                       "v 0 0 1\nv 4 0 1\nv 4 2 1\nv 0 2 1\n"
                                       "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\n"
                                       "f 1 2 6\nf 1 6 5\nf 4 7 3\nf 4 8 7\n"
                                       "f 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  /// The scene of one mesh entry `mesh` (JSON object members after "file": "box.obj").
  SceneDescription scene(const std::string& mesh, const std::string& extra = "") const {
    const fs::path p = dir_ / "scene.json";
    std::ofstream(p) << R"({"meshes": [{"file": "box.obj")" << (mesh.empty() ? "" : ", ") << mesh
                     << "}]" << extra << "}";
    return read_scene_json(p.string());
  }
  fs::path dir_;
};

Bbox bounds_of(const SceneDescription& s) {
  Bbox b;
  for (const Primitive& p : s.prims) b.extend(bounds(p));
  return b;
}

double area(const Primitive& p) {
  return 0.5 * length(cross(p.b - p.a, p.c - p.a));
}

double total_area(const SceneDescription& s) {
  double a = 0;
  for (const Primitive& p : s.prims) a += area(p);
  return a;
}

void expect_box(const Bbox& b, Vec3 lo, Vec3 hi, const char* what) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(b.lo[k], lo[k], 1e-5) << what << ": lo."
                                      << "xyz"[k];
    EXPECT_NEAR(b.hi[k], hi[k], 1e-5) << what << ": hi."
                                      << "xyz"[k];
  }
}

TEST_F(SceneKeys, PlainMeshKeepsItsCoordinates) {
  const SceneDescription s = scene("");
  ASSERT_EQ(s.prims.size(), 12u);
  expect_box(bounds_of(s), {0, 0, 0}, {4, 2, 1}, "no keys");
  EXPECT_NEAR(total_area(s), 2 * (4 * 2 + 4 * 1 + 2 * 1), 1e-4);
}

// fit: s scales uniformly to largest extent s, centred in x and z, resting on y = 0; a
// transform applies after it.
TEST_F(SceneKeys, FitScalesToTheLargestExtentRestingOnYZero) {
  expect_box(bounds_of(scene(R"("fit": 2)")), {-1, 0, -0.25f}, {1, 1, 0.25f}, "fit 2");
  expect_box(bounds_of(scene(R"("fit": 10)")), {-5, 0, -1.25f}, {5, 5, 1.25f}, "fit 10");
  expect_box(bounds_of(scene(R"("fit": 2, "transform": {"translate": [0, 0, 5]})")), {-1, 0, 4.75f},
             {1, 1, 5.25f}, "fit, then translate");
}

// subdivide: n splits every triangle into 4 at its edge midpoints, n times: 4^n as many
// triangles, each a quarter of its parent, on the same surface (same bounds and area).
TEST_F(SceneKeys, SubdivideQuadruplesTrianglesOnTheSameSurface) {
  const SceneDescription plain = scene("");
  for (int n : {1, 2, 3}) {
    SCOPED_TRACE("subdivide " + std::to_string(n));
    const SceneDescription s = scene(R"("subdivide": )" + std::to_string(n));
    EXPECT_EQ(s.prims.size(), 12u << (2 * n));
    expect_box(bounds_of(s), {0, 0, 0}, {4, 2, 1}, "subdivided");
    EXPECT_NEAR(total_area(s), total_area(plain), 1e-3);
    const double quarter = std::pow(0.25, n);
    for (const Primitive& p : s.prims) {
      bool matches = false;  // a quarter^n of one of the box's triangle sizes (4, 2 or 1)
      for (double parent : {4.0, 2.0, 1.0}) matches |= std::fabs(area(p) - parent * quarter) < 1e-5;
      EXPECT_TRUE(matches) << "triangle of area " << area(p);
    }
  }
  // Through load_scene too: the built hierarchy holds the subdivided triangles.
  scene(R"("subdivide": 2)");
  EXPECT_EQ(load_scene((dir_ / "scene.json").string(), Params("")).info().primitives, 12 * 16);
}

// rotate_*_deg: right-handed rotations (counter-clockwise looking down the axis towards the
// origin) of the box [0, 4] x [0, 2] x [0, 1]; in a transform, scale first, then the
// rotations about x, y and z, then translate.
TEST_F(SceneKeys, RotationsTurnTheMeshRightHanded) {
  // About x by 90: (x, y, z) -> (x, -z, y).
  expect_box(bounds_of(scene(R"("transform": {"rotate_x_deg": 90})")), {0, -1, 0}, {4, 0, 2},
             "rotate_x_deg 90");
  // About y by 90: (x, y, z) -> (z, y, -x).
  expect_box(bounds_of(scene(R"("transform": {"rotate_y_deg": 90})")), {0, 0, -4}, {1, 2, 0},
             "rotate_y_deg 90");
  // About z by 90: (x, y, z) -> (-y, x, z).
  expect_box(bounds_of(scene(R"("transform": {"rotate_z_deg": 90})")), {-2, 0, 0}, {0, 4, 1},
             "rotate_z_deg 90");
  // About z by 180 and by -90.
  expect_box(bounds_of(scene(R"("transform": {"rotate_z_deg": 180})")), {-4, -2, 0}, {0, 0, 1},
             "rotate_z_deg 180");
  expect_box(bounds_of(scene(R"("transform": {"rotate_z_deg": -90})")), {0, -4, 0}, {2, 0, 1},
             "rotate_z_deg -90");
  // x then z: (x, y, z) -> (x, -z, y) -> (z, x, y).
  expect_box(bounds_of(scene(R"("transform": {"rotate_x_deg": 90, "rotate_z_deg": 90})")),
             {0, 0, 0}, {1, 4, 2}, "rotate_x_deg then rotate_z_deg");
  // Scale 2, rotate about z by 90, translate by 10 in x: [0,8]x[0,4]x[0,2] -> x in [-4, 0],
  // y in [0, 8] -> x in [6, 10].
  expect_box(
      bounds_of(scene(R"("transform": {"scale": 2, "rotate_z_deg": 90, "translate": [10, 0, 0]})")),
      {6, 0, 0}, {10, 8, 2}, "scale, rotate, translate");
  // A single triangle's vertex, exactly where the rotation puts it: (4, 0, 0) about y by 90.
  const SceneDescription s = scene(R"("transform": {"rotate_y_deg": 90})");
  bool found = false;
  for (const Primitive& p : s.prims)
    for (Vec3 v : {p.a, p.b, p.c}) found |= length(v - Vec3{0, 0, -4}) < 1e-5f;
  EXPECT_TRUE(found) << "vertex (4, 0, 0) should be at (0, 0, -4)";
}

// camera.up: the film's upward direction. A sphere off the view axis in +x shows in the top
// rows of the image with up = +x, in the right columns with the default up = +y.
TEST_F(SceneKeys, CameraUpIsTheTopOfTheImage) {
  const std::string sphere = R"({"spheres": [{"centre": [1.2, 0, 0], "radius": 0.5}],
    "background": [0, 0, 0],
    "lights": [{"type": "directional", "direction": [0, 0, -1], "intensity": [1, 1, 1]}],
    "camera": {"position": [0, 0, 6], "look_at": [0, 0, 0], "vfov": 40)";
  const int w = 32, h = 32;
  RenderOptions o;
  o.width = w, o.height = h, o.spp = 1, o.threads = 2;
  for (const bool up_x : {true, false}) {
    SCOPED_TRACE(up_x ? "up [1, 0, 0]" : "default up");
    const fs::path p = dir_ / "up.json";
    std::ofstream(p) << sphere << (up_x ? R"(, "up": [1, 0, 0]}})" : "}}");
    const LoadedScene s = load_scene(p.string(), Params(""));
    if (up_x) {
      EXPECT_EQ(s.env.camera.up, (Vec3{1, 0, 0}));
    }
    // The ray through the middle of the top edge leans towards up.
    const Ray top = s.env.camera.generate(w * 0.5f, 0, w, h);
    EXPECT_GT(up_x ? top.dir.x : top.dir.y, 0.3f);
    EXPECT_NEAR(up_x ? top.dir.y : top.dir.x, 0.0f, 1e-6f);
    // Where the sphere is: the lit pixels' mean position.
    const RenderOutput r = render(s, o);
    double sx = 0, sy = 0, n = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (luminance(r.image[static_cast<std::size_t>(y) * w + x]) > 0.01f) sx += x, sy += y, ++n;
    ASSERT_GT(n, 10) << "the sphere should be visible";
    const double cx = sx / n - w / 2.0 + 0.5, cy = sy / n - h / 2.0 + 0.5;  // from the centre
    if (up_x) {
      EXPECT_LT(cy, -5) << "up = +x: the sphere (at +x) is in the upper half";
      EXPECT_NEAR(cx, 0, 1.5) << "and centred left to right";
    } else {
      EXPECT_GT(cx, 5) << "up = +y: the sphere (at +x) is in the right half";
      EXPECT_NEAR(cy, 0, 1.5) << "and centred top to bottom";
    }
  }
}

// A key given twice in one object is refused, naming the object (nlohmann::json keeps the last
// one silently: a scene file with two "camera" objects rendered the second); the same key in
// different objects is not a duplicate.
TEST(SceneJsonKeys, AKeyGivenTwiceInOneObjectIsRefused) {
  struct Case {
    std::string text, message;
  };
  const Case cases[] = {
      {R"({"camera": {"fov": 40}, "camera": {"fov": 60}})",
       "f.json: top level: key \"camera\" given twice"},
      {R"({"a": 1, "b": {"c": [1, [2], {"d": 2, "e": {}, "d": 3}]}})",
       "f.json: /b/c/2: key \"d\" given twice"},
      {R"({"x/y": {"k": 1, "k": 1}})", "f.json: /x~1y: key \"k\" given twice"},
  };
  for (const Case& c : cases) {
    try {
      (void)parse_json(c.text, "f.json");
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), c.message);
    }
  }
  EXPECT_NO_THROW((void)parse_json(R"([{"a": 1}, {"a": 2}, {"b": {"a": 3}, "a": 4}])", "f.json"));
  EXPECT_EQ(parse_json(R"({"a": {"x": 1}, "b": {"x": 2}})", "f.json")["b"]["x"], 2);
}

}  // namespace
}  // namespace amalgam

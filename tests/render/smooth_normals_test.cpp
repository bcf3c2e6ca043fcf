// Smooth shading (docs/import.md, "Vertex normals"): the vertex normals a mesh file gives are
// interpolated at the hit, checked against an analytic sphere; --smooth-normals generates them
// for a file without; a file without normals imports none, so its images do not change.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/scene/subdivide.h"

namespace amalgam {
namespace {

namespace fs = std::filesystem;

struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("amalgam_smooth_" + std::to_string(getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

/// A unit sphere about the origin as an OBJ of `rings` x `segments` quads (two triangles each;
/// one at each pole), with `vn` lines (the exact normal at each vertex) when `normals`.
std::string sphere_obj(int rings, int segments, bool normals) {
  std::string obj;
  auto vertex = [&](double theta, double phi) {
    const double x = std::sin(theta) * std::cos(phi), y = std::cos(theta),
                 z = std::sin(theta) * std::sin(phi);
    obj += "v " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
    if (normals)
      obj += "vn " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
  };
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s)
      vertex(std::numbers::pi * r / rings, 2 * std::numbers::pi * s / segments);
  auto index = [&](int r, int s) { return std::to_string(r * (segments + 1) + s + 1); };
  auto corner = [&](int r, int s) {
    const std::string i = index(r, s);
    return normals ? i + "//" + i : i;
  };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      if (r > 0)
        obj += "f " + corner(r, s) + " " + corner(r, s + 1) + " " + corner(r + 1, s + 1) + "\n";
      if (r + 1 < rings)
        obj += "f " + corner(r, s) + " " + corner(r + 1, s + 1) + " " + corner(r + 1, s) + "\n";
    }
  return obj;
}

double angle_deg(Vec3 a, Vec3 b) {
  const double c = std::clamp(static_cast<double>(dot(normalize(a), normalize(b))), -1.0, 1.0);
  return std::acos(c) * 180.0 / std::numbers::pi;
}

/// Mean and largest angle between the shading normal at the closest hit and the sphere's
/// exact normal there, over rays from outside toward points spread over the sphere.
void normal_errors(const ExplicitHierarchy& h, double& mean, double& worst) {
  mean = 0, worst = 0;
  int n = 0;
  for (int i = 0; i < 400; ++i) {
    // A Fibonacci spiral of directions; rays come in from 3 units out along each.
    const double y = 1.0 - 2.0 * (i + 0.5) / 400, r = std::sqrt(1 - y * y);
    const double phi = i * std::numbers::pi * (3 - std::sqrt(5.0));
    const Vec3 d{static_cast<float>(r * std::cos(phi)), static_cast<float>(y),
                 static_cast<float>(r * std::sin(phi))};
    const Ray ray = Ray::make(d * 3.0f, -d);
    std::optional<SurfaceHit> best;
    PrimId best_id = 0;
    for (PrimId p = 0; p < h.prims.size(); ++p) {
      Ray limited = ray;
      if (best) limited.tmax = best->t;
      if (auto s = h.intersect(p, limited)) best = s, best_id = p;
    }
    ASSERT_TRUE(best.has_value()) << "ray " << i;
    const double e = angle_deg(h.shading_normal(best_id, *best), best->p);
    const double flipped = angle_deg(-h.shading_normal(best_id, *best), best->p);
    const double err = std::min(e, flipped);  // the side is the integrator's to choose
    mean += err, worst = std::max(worst, err), ++n;
  }
  mean /= n;
}

TEST(SmoothNormals, InterpolatedNormalsFollowTheAnalyticSphere) {
  Scratch s;
  std::ofstream(s.dir / "smooth.obj") << sphere_obj(12, 24, true);
  std::ofstream(s.dir / "flat.obj") << sphere_obj(12, 24, false);
  const ImportedMesh smooth = import_mesh((s.dir / "smooth.obj").string());
  const ImportedMesh flat = import_mesh((s.dir / "flat.obj").string());
  ASSERT_EQ(smooth.normals.size(), smooth.triangles.size());
  EXPECT_TRUE(flat.normals.empty());  // nothing changes for a file without normals
  const ExplicitHierarchy hs =
      build_explicit(smooth.triangles, smooth.materials, {}, {}, {}, smooth.normals);
  const ExplicitHierarchy hf = build_explicit(flat.triangles, flat.materials);
  double smooth_mean, smooth_worst, flat_mean, flat_worst;
  normal_errors(hs, smooth_mean, smooth_worst);
  normal_errors(hf, flat_mean, flat_worst);
  // Facets of 15 degrees: the geometric normal is off by up to about 10 degrees (5 on
  // average, measured). The vertex normals of a sphere about the origin are its vertices, so
  // the interpolated normal at a hit is the hit point itself, the exact normal: only rounding
  // is left (0.002 degrees on average, 0.03 at most, measured).
  EXPECT_GT(flat_mean, 2.0);
  EXPECT_LT(smooth_mean, 0.01) << "flat: " << flat_mean;
  EXPECT_LT(smooth_worst, 0.1) << "flat: " << flat_worst;
}

/// The normal output of a render of `path`, against the analytic normal of the unit sphere at
/// each pixel's centre ray: the mean angle over pixels whose centre ray meets the sphere well
/// inside its silhouette.
double render_normal_error(const std::string& path, bool generate) {
  SceneFileConfig config;
  config.smooth_normals = generate;
  const LoadedScene scene = load_scene(path, Params(path), config);
  RenderOptions o;
  o.width = o.height = 64, o.spp = 16, o.threads = 2;
  o.sampler = PixelSampler::kStratified;
  o.lod = FullDetail{};
  const RenderOutput out = render(scene, o);
  double sum = 0;
  int n = 0;
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      const Ray r = scene.env.camera.generate(x + 0.5f, y + 0.5f, o.width, o.height);
      // |o + t d| = 1: the exact hit of the centre ray on the unit sphere.
      const double b = dot(r.origin, r.dir), c = dot(r.origin, r.origin) - 1.0,
                   a = dot(r.dir, r.dir), disc = b * b - a * c;
      if (disc <= 0) continue;
      const double t = (-b - std::sqrt(disc)) / a;
      const Vec3 p = r.at(static_cast<float>(t));
      if (dot(p, -normalize(r.dir)) < 0.5f) continue;  // near the silhouette
      sum += angle_deg(out.normal[static_cast<std::size_t>(y * o.width + x)], p), ++n;
    }
  EXPECT_GT(n, 500);
  return sum / std::max(n, 1);
}

TEST(SmoothNormals, RenderedNormalsAndGeneratedOnes) {
  Scratch s;
  std::ofstream(s.dir / "smooth.obj") << sphere_obj(12, 24, true);
  std::ofstream(s.dir / "flat.obj") << sphere_obj(12, 24, false);
  const double with_file = render_normal_error((s.dir / "smooth.obj").string(), false);
  const double flat = render_normal_error((s.dir / "flat.obj").string(), false);
  const double generated = render_normal_error((s.dir / "flat.obj").string(), true);
  // Measured: 4.1 degrees faceted, 0.50 from the file's normals and 0.51 generated (what is
  // left is the pixel's area: the output is a mean over 16 samples, the reference the centre's).
  EXPECT_GT(flat, 2.0);
  EXPECT_LT(with_file, flat / 4) << "flat " << flat;
  EXPECT_LT(generated, flat / 4) << "flat " << flat;
  EXPECT_NEAR(generated, with_file, 0.1);
}

// A subdivided triangle is shaded as the coarse one was: its centre sub-triangle (ab, bc, ca)
// at its own centroid is the coarse centroid, and so is the interpolated normal there.
TEST(SmoothNormals, SubdivisionKeepsTheInterpolation) {
  VertexNormals v;
  v.n[0] = {0, 0, 1}, v.n[1] = {0.6f, 0, 0.8f}, v.n[2] = {0, -0.28f, 0.96f};
  const std::vector<VertexNormals> fine = subdivide(std::vector<VertexNormals>{v}, 1);
  ASSERT_EQ(fine.size(), 4u);
  const Vec3 coarse = interpolate(v, 1.0f / 3, 1.0f / 3);
  const Vec3 centre = interpolate(fine[3], 1.0f / 3, 1.0f / 3);
  EXPECT_LT(angle_deg(coarse, centre), 1e-3);
  // Corner a of the first sub-triangle is the coarse vertex a; its b is the midpoint of ab.
  EXPECT_EQ(fine[0].n[0], v.n[0]);
  EXPECT_LT(angle_deg(interpolate(fine[0], 1, 0), interpolate(v, 0.5f, 0)), 1e-3);
}

// Amalgams bake the normals the triangles are shaded with: a flat quad whose vertex normals all
// lean 45 degrees bakes that leaning normal into its root amalgam; without them, the plane's.
TEST(SmoothNormals, AmalgamsBakeTheInterpolatedNormals) {
  const std::vector<Primitive> quad = {Primitive::triangle({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, 0),
                                       Primitive::triangle({0, 0, 0}, {1, 1, 0}, {0, 1, 0}, 0)};
  VertexNormals lean;
  for (Vec3& n : lean.n) n = normalize(Vec3{1, 0, 1});
  BuildConfig cfg;
  cfg.bake.rays = 256;
  const ExplicitHierarchy smooth = build_explicit(quad, {Surface{}}, cfg, {}, {}, {lean, lean});
  const ExplicitHierarchy flat = build_explicit(quad, {Surface{}}, cfg);
  const Vec3 s = smooth.appearance(smooth.root()).normal, f = flat.appearance(flat.root()).normal;
  ASSERT_NE(s, Vec3{});
  ASSERT_NE(f, Vec3{});
  EXPECT_LT(std::min(angle_deg(s, lean.n[0]), angle_deg(-s, lean.n[0])), 1.0);
  EXPECT_LT(std::min(angle_deg(f, {0, 0, 1}), angle_deg(-f, {0, 0, 1})), 1.0);
}

/// The normal output of `scene`, rendered at full detail.
std::vector<Vec3> rendered_normals(const std::string& scene, bool instanced) {
  SceneFileConfig config;
  config.objects = instanced;                                         // every mesh an instance
  if (!instanced) config.instance_min_triangles = ~std::uint64_t{0};  // every one expanded
  const LoadedScene s = load_scene(scene, Params(scene), config);
  EXPECT_EQ(std::holds_alternative<InstancedHierarchy>(s.hierarchy), instanced);
  RenderOptions o;
  o.width = o.height = 48, o.spp = 4, o.threads = 2;
  o.lod = FullDetail{};
  return render(s, o).normal;
}

// A placed mesh's normals transform as normals (by M^-T, not M): a sphere stretched into an
// ellipsoid and turned, expanded into world triangles or kept as an instance, shows the same
// normals; the faceted sphere does not.
TEST(SmoothNormals, PlacedMeshesTransformTheirNormals) {
  Scratch s;
  std::ofstream(s.dir / "smooth.obj") << sphere_obj(12, 24, true);
  std::ofstream(s.dir / "flat.obj") << sphere_obj(12, 24, false);
  for (const char* name : {"smooth", "flat"})
    std::ofstream(s.dir / (std::string(name) + ".json"))
        << R"({"camera": {"position": [0, 1, 6], "look_at": [0, 0, 0], "vfov": 40},
  "lights": [{"type": "directional", "direction": [0.3, -1, -0.5], "intensity": [2, 2, 2]}],
  "meshes": [{"name": "s", "file": ")"
        << name << R"(.obj", "place": false}],
  "instances": [{"mesh": "s", "transforms": [{"scale": [2, 1, 0.5], "rotate_y_deg": 30}]}]})";
  const std::string smooth = (s.dir / "smooth.json").string();
  const std::vector<Vec3> expanded = rendered_normals(smooth, false);
  const std::vector<Vec3> instanced = rendered_normals(smooth, true);
  const std::vector<Vec3> flat = rendered_normals((s.dir / "flat.json").string(), false);
  double differ = 0, facets = 0;
  int n = 0;
  for (std::size_t i = 0; i < expanded.size(); ++i) {
    if (expanded[i] == Vec3{} || instanced[i] == Vec3{}) continue;  // background
    differ += angle_deg(expanded[i], instanced[i]);
    facets += angle_deg(expanded[i], flat[i]);
    ++n;
  }
  ASSERT_GT(n, 300);
  EXPECT_LT(differ / n, 0.05) << "faceted: " << facets / n;
  EXPECT_GT(facets / n, 1.0);
}

}  // namespace
}  // namespace amalgam

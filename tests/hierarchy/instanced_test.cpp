// The two-level instanced hierarchy against the same scene expanded into one explicit
// hierarchy, and the scene file producing it.

#include "amalgam/hierarchy/instanced.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/math/random.h"
#include "amalgam/render/render.h"
#include "amalgam/traverse/traverse.h"

namespace amalgam {
namespace {

/// A closed, bumpy blob of 2 * 8 * 12 triangles around the origin, radius about 1.
std::vector<Primitive> blob() {
  std::vector<Primitive> out;
  const int nu = 12, nv = 8;
  auto p = [&](int i, int j) {
    const float u = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / nu;
    const float v = std::numbers::pi_v<float> * static_cast<float>(j) / nv;
    const float r = 1.0f + 0.15f * std::sin(3.0f * u) * std::sin(2.0f * v);
    return Vec3{r * std::sin(v) * std::cos(u), r * std::cos(v), r * std::sin(v) * std::sin(u)};
  };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Vec3 a = p(i, j), b = p(i + 1, j), c = p(i + 1, j + 1), d = p(i, j + 1);
      const std::uint32_t m = static_cast<std::uint32_t>((i + j) % 2);
      if (j > 0) out.push_back(Primitive::triangle(a, b, c, m));
      if (j < nv - 1) out.push_back(Primitive::triangle(a, c, d, m));
    }
  return out;
}

Transform rot_y_scale_translate(float deg, float s, Vec3 t) {
  const float r = deg * std::numbers::pi_v<float> / 180.0f;
  Transform x;
  x.m[0][0] = s * std::cos(r), x.m[0][2] = s * std::sin(r);
  x.m[2][0] = -s * std::sin(r), x.m[2][2] = s * std::cos(r);
  x.m[1][1] = s;
  x.m[0][3] = t.x, x.m[1][3] = t.y, x.m[2][3] = t.z;
  return x;
}

struct Pair {
  LoadedScene expanded, instanced;
};

Pair make_pair_of_scenes(const std::vector<Transform>& where) {
  const std::vector<Surface> materials = {Surface{{0.9f, 0.3f, 0.2f}}, Surface{{0.2f, 0.8f, 0.3f}}};
  const std::vector<Primitive> mesh = blob();
  const Primitive ground = Primitive::box({-20, -1.5f, -20}, {20, -1.2f, 20}, 0);
  std::vector<Primitive> all;
  std::vector<Instance> instances;
  for (const Transform& t : where) {
    for (const Primitive& p : mesh)
      all.push_back(Primitive::triangle(t.point(p.a), t.point(p.b), t.point(p.c), p.material));
    instances.push_back({t, 0});
  }
  all.push_back(ground);
  std::vector<ExplicitHierarchy> meshes;
  meshes.push_back(build_explicit(mesh, materials));
  meshes.push_back(build_explicit({ground}, materials));
  instances.push_back({Transform{}, 1});
  Environment env;
  env.camera.position = {2, 4, 14};
  env.camera.look_at = {0, 0, 0};
  Light sun;
  sun.kind = LightKind::kDirectional;
  sun.direction = normalize(Vec3{0.4f, -1, -0.5f});
  sun.intensity = {2, 2, 2};
  env.lights = {sun};
  return {LoadedScene{"expanded", build_explicit(all, materials), env},
          LoadedScene{"instanced", build_instanced(std::move(meshes), instances), env}};
}

std::vector<Transform> translations() {
  std::vector<Transform> out;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k)
      out.push_back(Transform::translate({i * 2.5f - 4.0f, 0, k * 2.5f - 3.0f}));
  return out;
}

std::vector<Transform> rotated() {
  std::vector<Transform> out;
  Sampler s(11);
  for (int i = 0; i < 20; ++i)
    out.push_back(rot_y_scale_translate(360.0f * s.next(), 0.5f + s.next(),
                                        {s.next() * 12 - 6, s.next(), s.next() * 10 - 6}));
  return out;
}

RenderOptions traditional() {
  RenderOptions o;
  o.lod = FullDetail{};
  o.width = 64;
  o.height = 48;
  o.spp = 1;
  o.threads = 2;
  return o;
}

TEST(Instanced, IdentityInstanceIsBitIdenticalToExplicit) {
  Pair p = make_pair_of_scenes({Transform{}});
  const RenderOutput a = render(p.expanded, traditional()), b = render(p.instanced, traditional());
  ASSERT_EQ(a.image.size(), b.image.size());
  for (std::size_t i = 0; i < a.image.size(); ++i)
    ASSERT_EQ(a.image[i], b.image[i]) << "pixel " << i;
}

/// Same hits, ray by ray (traditional traversal), and images within float tolerance: the
/// instanced form intersects in object space, so t and the hit point differ in the last bits.
void expect_same_hits(const std::vector<Transform>& where) {
  Pair p = make_pair_of_scenes(where);
  const auto& e = std::get<ExplicitHierarchy>(p.expanded.hierarchy);
  const auto& in = std::get<InstancedHierarchy>(p.instanced.hierarchy);
  EXPECT_EQ(e.info().primitives, in.info().primitives);
  Counters ce, ci;
  Traversal<ExplicitHierarchy, TraditionalLod, StochasticOpacity, SortedOrder> te(e, {}, ce);
  Traversal<InstancedHierarchy, TraditionalLod, StochasticOpacity, SortedOrder> ti(in, {}, ci);
  int hits = 0, same_prim = 0, n = 0;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x, ++n) {
      const Ray r = p.expanded.env.camera.generate(x + 0.5f, y + 0.5f, 80, 60);
      const TraceHit a = te.intersect(r, 1), b = ti.intersect(r, 1);
      ASSERT_EQ(a.kind, b.kind) << "ray " << x << "," << y;
      if (a.kind == TraceHit::Kind::kNone) continue;
      ++hits;
      EXPECT_NEAR(a.t, b.t, 1e-4f * a.t);
      EXPECT_NEAR(dot(a.surf.normal, b.surf.normal), 1.0f, 1e-3f);
      const Primitive pa = e.prims[a.id], pb = in.primitive(b.id);
      if (length(pa.a - pb.a) < 1e-4f && length(pa.b - pb.b) < 1e-4f) ++same_prim;
    }
  EXPECT_GT(hits, n / 3);
  EXPECT_GE(same_prim, hits - hits / 200);  // edge rays may pick the neighbour
  const RenderOutput a = render(p.expanded, traditional()), b = render(p.instanced, traditional());
  double diff = 0;
  for (std::size_t i = 0; i < a.image.size(); ++i) diff += length(a.image[i] - b.image[i]);
  EXPECT_LT(diff / static_cast<double>(a.image.size()), 2e-3);
}

TEST(Instanced, TranslatedInstancesHitLikeExpanded) {
  expect_same_hits(translations());
}
TEST(Instanced, RotatedScaledInstancesHitLikeExpanded) {
  expect_same_hits(rotated());
}

TEST(Instanced, CountsAddUpAndLevelsRunThroughInstances) {
  Pair p = make_pair_of_scenes(rotated());
  const auto& in = std::get<InstancedHierarchy>(p.instanced.hierarchy);
  // Structure: instance boxes inside their top leaf, children inside parents in world space.
  for (std::size_t i = 0; i < in.top_nodes.size(); ++i) {
    const ExplicitNode& t = in.top_nodes[i];
    in.for_each_child(i, [&](Child c) {
      const Bbox b = in.bounds(c.id);
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(b.lo[a], t.bounds.lo[a]) << "top node " << i << ", axis " << a;
        EXPECT_LE(b.hi[a], t.bounds.hi[a]) << "top node " << i << ", axis " << a;
      }
      return true;
    });
  }
  for (const RenderOptions& base : {traditional(), RenderOptions{}}) {
    RenderOptions o = base;
    o.width = 48, o.height = 32, o.spp = 2;
    for (float k : {1.0f, 8.0f}) {
      if (!std::holds_alternative<FullDetail>(base.lod)) o.lod = ByFootprint{k};
      const RenderOutput r = render(p.instanced, o);
      const Counters& c = r.counters;
      std::uint64_t by_level = 0;
      for (auto v : c.by_level) by_level += v;
      EXPECT_EQ(c.tests_of(RayKind::kPrimary) + c.tests_of(RayKind::kShadow), c.total());
      EXPECT_EQ(c.tests_of(ObjectKind::kPrimitive) + c.tests_of(ObjectKind::kBoundingVolume) +
                    c.tests_of(ObjectKind::kAmalgam),
                c.total());
      EXPECT_EQ(by_level, c.total());
      EXPECT_EQ(c.by_level[static_cast<std::size_t>(in.levels)], 0u);  // nothing below l_max
    }
  }
  // Top-level amalgams are baked from the instances: opaque-ish, coloured like the blobs (the
  // root's colour is a weighted mean of the instance roots' colours, so it lies within their
  // range on every channel).
  const Appearance root = in.appearance(in.root());
  EXPECT_GT(root.opacity, 0.05f);
  EXPECT_LE(root.opacity, 1.0f);
  Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  for (std::size_t k = 0; k < in.instances.size(); ++k) {
    const Vec3 c = in.appearance(InstancedHierarchy::id(k + 1, 0)).surface.colour;
    lo = min(lo, c), hi = max(hi, c);
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_GE(root.surface.colour[a], lo[a] - 1e-5f) << "channel " << a;
    EXPECT_LE(root.surface.colour[a], hi[a] + 1e-5f) << "channel " << a;
  }
  EXPECT_GT(luminance(root.surface.colour), 0.0f);
}

TEST(Instanced, SceneFileKeepsLargeMeshesInstanced) {
  namespace fs = std::filesystem;
  // Named by the process: another suite (another worktree's) may run this test at once.
  const fs::path d =
      fs::temp_directory_path() / ("amalgam_instanced_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  {
    std::ofstream obj(d / "grid.obj");  // 8 x 8 quads: 128 triangles
    for (int j = 0; j <= 8; ++j)
      for (int i = 0; i <= 8; ++i)
        obj << "v " << i * 0.1 << " " << 0.05 * ((i + j) % 2) << " " << j * 0.1 << "\n";
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) {
        const int a = j * 9 + i + 1;
        obj << "f " << a << " " << a + 1 << " " << a + 10 << "\nf " << a << " " << a + 10 << " "
            << a + 9 << "\n";
      }
  }
  const std::string text = R"({
    "meshes": [{"name": "g", "file": "grid.obj", "place": false}],
    "instances": [{"mesh": "g", "grid": {"nx": 30, "nz": 20, "spacing": 1}},
                  {"mesh": "g", "scatter": {"count": 50, "radius": 3}, "material": {"colour": [1, 0, 0]}}],
    "spheres": [{"centre": [0, 2, 0], "radius": 0.5}]})";
  SceneFileConfig small;
  small.expand_limit = 1000;
  SceneDescription s = parse_scene_json(text, (d / "s.json").string(), small);
  EXPECT_EQ(s.instances.size(), 650u);
  EXPECT_EQ(s.meshes.size(), 2u);  // one per (mesh, material override)
  EXPECT_EQ(s.prims.size(), 1u);   // the sphere
  const AnyHierarchy h = build_hierarchy(std::move(s));
  ASSERT_TRUE(std::holds_alternative<InstancedHierarchy>(h));
  EXPECT_EQ(std::get<InstancedHierarchy>(h).info().primitives, 650 * 128 + 1);
  // Under the default limit the same scene is expanded into one explicit hierarchy.
  SceneDescription e = parse_scene_json(text, (d / "s.json").string());
  EXPECT_TRUE(e.instances.empty());
  EXPECT_EQ(e.prims.size(), 650u * 128u + 1u);
  fs::remove_all(d);
}

}  // namespace
}  // namespace amalgam

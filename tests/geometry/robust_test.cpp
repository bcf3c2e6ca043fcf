// Robust geometry (issue 6): rays aimed exactly at shared edges and vertices of closed meshes
// never slip through; NaN/Inf, degenerate, huge and tiny input is rejected with a clear
// message or rendered, never a crash or a hang; shadow rays do not hit the surface they
// leave (origins offset by the error bound, no fixed epsilon).

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "../sanitized.h"
#include "amalgam/hierarchy/build/build.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

namespace amalgam {
namespace {

// The ASan/UBSan preset runs this file too, about 10x slower: fewer rays there.
constexpr int kRayScale = kSanitized ? 10 : 1;

// -------------------------------------------------------------------------------------------
// Indexed meshes with exactly shared vertices.

struct Mesh {
  std::vector<Vec3> v;
  std::vector<std::array<std::uint32_t, 3>> f;

  /// Unit normal; edges normalised first so that 1e-15 and 1e15 scales neither underflow nor
  /// overflow.
  Vec3 normal(std::size_t face) const {
    const auto& t = f[face];
    return normalize(cross(normalize(v[t[1]] - v[t[0]]), normalize(v[t[2]] - v[t[0]])));
  }
  std::vector<Primitive> primitives() const {
    std::vector<Primitive> out;
    for (const auto& t : f) out.push_back(Primitive::triangle(v[t[0]], v[t[1]], v[t[2]]));
    return out;
  }
  Mesh transformed(float scale, Vec3 offset) const {
    Mesh m = *this;
    for (Vec3& p : m.v) p = p * scale + offset;
    return m;
  }
};

/// Cube [-1, 1]^3 as 12 outward-facing triangles.
Mesh cube() {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.v.push_back({(i & 1) ? 1.0f : -1.0f, (i & 2) ? 1.0f : -1.0f, (i & 4) ? 1.0f : -1.0f});
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.f.push_back({q[0], q[1], q[2]});
    m.f.push_back({q[0], q[2], q[3]});
  }
  return m;
}

/// Icosahedron subdivided `levels` times, vertices projected onto the unit sphere (shared
/// exactly: each edge midpoint is computed once).
Mesh icosphere(int levels) {
  Mesh m;
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  const Vec3 base[12] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (const Vec3& p : base) m.v.push_back(normalize(p));
  m.f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.v.push_back(normalize((m.v[a] + m.v[b]) * 0.5f));
      return mid[key] = static_cast<std::uint32_t>(m.v.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& [a, b, c] : m.f) {
      const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.f = std::move(next);
  }
  return m;
}

/// Re-indexes imported triangles by exact vertex position.
Mesh indexed(const std::vector<Primitive>& tris) {
  Mesh m;
  std::map<std::tuple<float, float, float>, std::uint32_t> index;
  auto id = [&](Vec3 p) {
    auto [it, fresh] =
        index.emplace(std::tuple{p.x, p.y, p.z}, static_cast<std::uint32_t>(m.v.size()));
    if (fresh) m.v.push_back(p);
    return it->second;
  };
  for (const Primitive& t : tris) m.f.push_back({id(t.a), id(t.b), id(t.c)});
  return m;
}

/// Shared edges with a consistent orientation (a->b in one face, b->a in the other) and
/// vertices whose whole 1-ring consists of such edges: where "closed" holds locally.
struct Topology {
  struct Edge {
    std::uint32_t a, b;
    std::array<std::uint32_t, 2> faces;
  };
  std::vector<Edge> edges;
  std::vector<std::uint32_t> vertices;
  std::vector<std::vector<std::uint32_t>> vertex_faces;
  std::size_t open_or_inconsistent_edges = 0;
};

Topology topology(const Mesh& m) {
  Topology t;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> directed;
  t.vertex_faces.resize(m.v.size());
  for (std::uint32_t i = 0; i < m.f.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      directed[{m.f[i][k], m.f[i][(k + 1) % 3]}].push_back(i);
      t.vertex_faces[m.f[i][k]].push_back(i);
    }
  std::vector<bool> vertex_ok(m.v.size(), true);
  for (const auto& [e, faces] : directed) {
    auto back = directed.find({e.second, e.first});
    const bool good = faces.size() == 1 && back != directed.end() && back->second.size() == 1;
    if (!good) {
      vertex_ok[e.first] = vertex_ok[e.second] = false;
      ++t.open_or_inconsistent_edges;
    } else if (e.first < e.second) {
      t.edges.push_back({e.first, e.second, {faces[0], back->second[0]}});
    }
  }
  for (std::uint32_t i = 0; i < m.v.size(); ++i)
    if (vertex_ok[i] && !t.vertex_faces[i].empty()) t.vertices.push_back(i);
  return t;
}

/// A random unit direction strictly on the front side of every face in `faces` (cosine above
/// `margin`), or nothing when 64 tries find none (a saddle without such a cone).
std::optional<Vec3> front_direction(const Mesh& m, const std::vector<std::uint32_t>& faces,
                                    std::mt19937& rng, float margin = 0.1f) {
  std::normal_distribution<float> g;
  Vec3 mean{};
  for (std::uint32_t f : faces) mean += m.normal(f);
  for (int attempt = 0; attempt < 64; ++attempt) {
    Vec3 u = normalize(Vec3{g(rng), g(rng), g(rng)} + (attempt < 32 ? normalize(mean) : Vec3{}));
    bool ok = true;
    for (std::uint32_t f : faces) ok = ok && dot(u, m.normal(f)) > margin;
    if (ok) return u;
  }
  return std::nullopt;
}

struct Aim {
  std::size_t rays = 0, missed = 0, skipped_targets = 0;
  std::string first_miss;
};

/// Shoots `rays` rays from outside at exact points of shared edges (p = lerp(a, b, s)) and at
/// shared vertices, each tested against every triangle around the target; counts the rays
/// that hit none.
Aim aim_at_edges_and_vertices(const Mesh& m, std::size_t rays, std::uint32_t seed) {
  const Topology topo = topology(m);
  Aim r;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Bbox box;
  for (const Vec3& p : m.v) box.extend(p);
  const float size = box.diagonal();
  const std::size_t targets = topo.edges.size() + topo.vertices.size();
  const std::size_t per_target = std::max<std::size_t>(1, rays / std::max<std::size_t>(targets, 1));
  for (std::size_t target = 0; target < targets; ++target) {
    std::vector<std::uint32_t> faces;
    Vec3 a, b;
    const bool is_edge = target < topo.edges.size();
    if (is_edge) {
      const auto& e = topo.edges[target];
      a = m.v[e.a], b = m.v[e.b];
      faces = {e.faces[0], e.faces[1]};
    } else {
      a = b = m.v[topo.vertices[target - topo.edges.size()]];
      faces = topo.vertex_faces[topo.vertices[target - topo.edges.size()]];
    }
    // Candidates: the target's faces and their neighbours around a and b.
    std::vector<std::uint32_t> candidates = faces;
    for (std::uint32_t f : faces)
      for (std::uint32_t k : m.f[f])
        candidates.insert(candidates.end(), topo.vertex_faces[k].begin(),
                          topo.vertex_faces[k].end());
    for (std::size_t i = 0; i < per_target; ++i) {
      const auto u = front_direction(m, faces, rng);
      if (!u) {
        ++r.skipped_targets;
        break;
      }
      // Edge points: the midpoint, then parameters k / 1024 in [1/16, 15/16]. Far from the
      // origin, lerp rounds p to the float grid; it must stay well inside the edge, since a
      // ray through a vertex that is front-facing for only two of its faces may touch the
      // mesh in that single point and rightly miss.
      const float s = i == 0 ? 0.5f : std::ldexp(64.0f + std::floor(unit(rng) * 897.0f), -10);
      const Vec3 p = is_edge ? lerp(a, b, s) : a;
      if (is_edge && (p == a || p == b)) continue;
      const Vec3 o = p + *u * (size * (0.05f + 3.0f * unit(rng)));
      const Ray ray = Ray::make(o, p - o);
      bool hit = false;
      for (std::uint32_t f : candidates) {
        const auto& t = m.f[f];
        if (intersect_triangle(ray, m.v[t[0]], m.v[t[1]], m.v[t[2]])) {
          hit = true;
          break;
        }
      }
      ++r.rays;
      if (!hit && r.missed++ == 0) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "%s target (%.9g %.9g %.9g) from (%.9g %.9g %.9g)",
                      is_edge ? "edge" : "vertex", p.x, p.y, p.z, o.x, o.y, o.z);
        r.first_miss = buf;
      }
    }
  }
  return r;
}

void expect_watertight(const Mesh& m, std::size_t rays, std::uint32_t seed,
                       const std::string& what) {
  const Topology topo = topology(m);
  ASSERT_GT(topo.edges.size(), 0u) << what;
  const Aim r = aim_at_edges_and_vertices(m, rays, seed);
  EXPECT_EQ(r.missed, 0u) << what << ": " << r.missed << " of " << r.rays
                          << " rays slipped through; first: " << r.first_miss;
  EXPECT_GE(r.rays, rays / 2) << what;
}

// -------------------------------------------------------------------------------------------

TEST(Watertight, CubeEdgesAndVertices) {
  const Mesh m = cube();
  ASSERT_EQ(topology(m).open_or_inconsistent_edges, 0u);
  expect_watertight(m, 1'000'000 / kRayScale, 1, "cube");
}

TEST(Watertight, CubeFarFromTheOriginAndAtExtremeScales) {
  const Mesh m = cube();
  expect_watertight(m.transformed(1.0f, {1e5f, -3e4f, 7e3f}), 200'000 / kRayScale, 2,
                    "cube at 1e5");
  expect_watertight(m.transformed(0.37f, {-2.5e3f, 1.25e2f, 9.0f}), 200'000 / kRayScale, 3,
                    "small cube at 2.5e3");
  expect_watertight(m.transformed(1e-15f, {}), 100'000 / kRayScale, 4, "cube of size 1e-15");
  expect_watertight(m.transformed(1e15f, {}), 100'000 / kRayScale, 5, "cube of size 1e15");
}

TEST(Watertight, TessellatedSphereEdgesAndVertices) {
  const Mesh m = icosphere(4);  // 5120 triangles, 7680 edges, 2562 vertices
  ASSERT_EQ(topology(m).open_or_inconsistent_edges, 0u);
  expect_watertight(m, 2'000'000 / kRayScale, 6, "icosphere");
  expect_watertight(m.transformed(3.0f, {-1e4f, 2e4f, 5e3f}), 300'000 / kRayScale, 7,
                    "icosphere at 2e4");
}

constexpr const char* kWuson = "/usr/share/assimp/models/PLY/Wuson.ply";

TEST(Watertight, WusonEdgesAndVertices) {
  ASSERT_TRUE(std::filesystem::exists(kWuson))
      << kWuson << " missing (assimp-testmodels, scripts/deps.sh)";
  const ImportedMesh imported = import_mesh(kWuson);
  const Mesh m = indexed(imported.triangles);
  const Topology topo = topology(m);
  // Wuson is closed except where the modeller left seams: test the shared edges.
  ASSERT_GT(topo.edges.size(), 3 * imported.triangles.size() / 2 * 9 / 10)
      << "Wuson.ply should be mostly closed";
  expect_watertight(m, 1'000'000 / kRayScale, 8, "Wuson");
}

/// The same rays through the whole pipeline (hierarchy traversal with the robust slab test,
/// then the triangles): a primary ray aimed at an edge or vertex of a closed mesh hits it.
TEST(Watertight, ThroughTheHierarchy) {
  const Mesh m = icosphere(3).transformed(2.0f, {1e3f, -5e2f, 2.5e2f});
  LoadedScene s{"icosphere", build_explicit(m.primitives(), {Surface{}}), Environment{}};
  RenderOptions o;
  o.lod = FullDetail{};
  const Topology topo = topology(m);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::size_t rays = 0, missed = 0;
  const std::size_t per_target = 40 / static_cast<std::size_t>(kRayScale) + 1;
  for (const auto& e : topo.edges)
    for (std::size_t i = 0; i < per_target; ++i) {
      const auto u = front_direction(m, {e.faces[0], e.faces[1]}, rng);
      ASSERT_TRUE(u);
      const Vec3 p =
          lerp(m.v[e.a], m.v[e.b], std::ldexp(16.0f + std::floor(unit(rng) * 225.0f), -8));
      const Vec3 o_ = p + *u * (1.0f + 20.0f * unit(rng));
      const TraceOutput t = trace(s, o, Ray::make(o_, normalize(p - o_)));
      ++rays;
      missed += t.hit.kind != TraceHit::Kind::kPrimitive;
    }
  EXPECT_EQ(missed, 0u) << missed << " of " << rays << " rays through the hierarchy missed";
}

// -------------------------------------------------------------------------------------------
// Degenerate and extreme input: rejected with a clear message, or rendered, never a crash
// or a hang.

/// Builds `prims` and renders an 8 x 6 image of them seen from `camera` with every renderer
/// and opacity model; returns the four renders.
std::vector<RenderOutput> render_prims(std::vector<Primitive> prims, const Camera& camera) {
  Environment env;
  env.camera = camera;
  Light sun;
  sun.kind = LightKind::kDirectional;
  sun.direction = normalize(Vec3{0.3f, -1.0f, -0.4f});
  env.lights = {sun};
  LoadedScene s{"prims", build_explicit(std::move(prims), {Surface{}}), env};
  RenderOptions o;
  o.width = 8, o.height = 6, o.spp = 2, o.threads = 1;
  std::vector<RenderOutput> out;
  for (RendererKind r : {RendererKind::kTraditional, RendererKind::kScaleSensitive})
    for (OpacityKind op : {OpacityKind::kStochastic, OpacityKind::kDeterministic}) {
      o.lod = r == RendererKind::kTraditional ? LevelOfDetail{FullDetail{}} : LevelOfDetail{};
      o.opacity = op;
      out.push_back(render(s, o));
    }
  return out;
}

/// Every render is finite everywhere and shows the proper geometry: at least `lit` pixels
/// (of 48) brighter than the background (all renderers see the same scene at this size).
void expect_finite_image(const std::vector<RenderOutput>& outs, const std::string& what,
                         int lit = 1) {
  ASSERT_EQ(outs.size(), 4u);
  for (std::size_t k = 0; k < outs.size(); ++k) {
    const RenderOutput& out = outs[k];
    int bright = 0;
    for (std::size_t i = 0; i < out.image.size(); ++i) {
      ASSERT_TRUE(is_finite(out.image[i]))
          << what << ", render " << k << ": pixel " << i << " is not finite";
      bright += luminance(out.image[i]) > luminance(Environment{}.background) + 0.02f;
    }
    EXPECT_GE(bright, lit) << what << ", render " << k << ": the geometry does not show";
  }
}

TEST(Degenerate, ZeroAreaAndCollinearTrianglesRender) {
  std::vector<Primitive> prims = {
      Primitive::triangle({0, 0, 0}, {0, 0, 0}, {0, 0, 0}),     // a point
      Primitive::triangle({0, 0, 0}, {1, 1, 0}, {2, 2, 0}),     // collinear
      Primitive::triangle({-1, 0, 0}, {1, 0, 0}, {-1, 0, 0}),   // repeated vertex
      Primitive::triangle({-1, -1, 0}, {1, -1, 0}, {0, 1, 0}),  // a proper one
      Primitive::sphere({2, 0, 0}, 0.0f),                       // zero radius
      Primitive::box({0, 0, 1}, {0, 0, 1}),                     // empty box
      Primitive::box({-3, -3, -1}, {-2, -2, -1}),               // flat box
  };
  Camera c;
  c.position = {0, 0, 5};
  const std::vector<RenderOutput> out = render_prims(prims, c);
  expect_finite_image(out, "degenerate primitives");
  // Degenerate triangles alone, aimed at directly: no hit, no NaN.
  const Ray r = Ray::make({0.5f, 0.5f, 1}, {0, 0, -1});
  EXPECT_FALSE(intersect_triangle(r, {0, 0, 0}, {1, 1, 0}, {2, 2, 0}));
  EXPECT_FALSE(intersect_triangle(r, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}));
  const Ray along = Ray::make({-1, -1, 0}, {1, 1, 0});  // in the plane of the collinear one
  EXPECT_FALSE(intersect_triangle(along, {0, 0, 0}, {1, 1, 0}, {2, 2, 0}));
}

TEST(Degenerate, NanAndInfiniteVerticesDoNotCrashTheRenderer) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<Primitive> prims = {
      Primitive::triangle({-1, -1, 0}, {1, -1, 0}, {0, 1, 0}),
      Primitive::triangle({nan, 0, 0}, {1, 0, 0}, {0, 1, 0}),
      Primitive::triangle({0, 0, 0}, {inf, 0, 0}, {0, 1, 0}),
      Primitive::triangle({-inf, -inf, -inf}, {inf, inf, inf}, {0, nan, 0}),
      Primitive::sphere({0, 0, 0}, nan),
      Primitive::sphere({nan, nan, nan}, 1.0f),
      Primitive::sphere({0, 0, -2}, inf),
  };
  Camera c;
  c.position = {0, 0, 5};
  // The contract: no crash, no hang, and the proper triangle renders as it would alone.
  expect_finite_image(render_prims(prims, c), "NaN and infinite vertices");
  // And the kernels themselves: no hit from a NaN triangle.
  const Ray r = Ray::make({0.2f, 0.2f, 1}, {0, 0, -1});
  EXPECT_FALSE(intersect_triangle(r, {nan, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  EXPECT_FALSE(intersect_triangle(r, {0, 0, 0}, {1, 0, 0}, {0, nan, 0}));
}

TEST(Degenerate, HugeAndTinyCoordinatesRender) {
  // Within the range the float kernels resolve (extents relative to the camera of 1e-10 ..
  // 1e12: the watertight test's t is a sum of products of three coordinates), a correct
  // render: finite, and the cube, sphere and box show. Beyond it (1e-20, 1e20, tiny next to
  // huge), the contract is a finite image, never a crash or a hang; scene files and meshes
  // reject such coordinates with a message (Degenerate.SceneJsonRejectsOrRendersExtremeInput).
  for (const float scale : {1e-20f, 1e-10f, 1e10f, 1e12f, 1e20f}) {
    std::vector<Primitive> prims;
    for (const auto& t : cube().transformed(scale, {}).primitives()) prims.push_back(t);
    prims.push_back(Primitive::sphere({2 * scale, 0, 0}, 0.5f * scale));
    prims.push_back(Primitive::box(Vec3{-3, -3, -3} * scale, Vec3{-2, -2, -2} * scale));
    Camera c;
    c.position = Vec3{1.5f, 2.0f, 6.0f} * scale;
    c.look_at = {0, 0, 0};
    const bool resolved = scale >= 1e-10f && scale <= 1e12f;
    char name[32];
    std::snprintf(name, sizeof name, "scale %g", static_cast<double>(scale));
    expect_finite_image(render_prims(prims, c), name, resolved ? 6 : 0);
  }
  // Mixed: a tiny triangle next to a huge one.
  std::vector<Primitive> mixed = {
      Primitive::triangle({0, 0, 0}, {1e-20f, 0, 0}, {0, 1e-20f, 0}),
      Primitive::triangle({-1e20f, -1e20f, -1}, {1e20f, -1e20f, -1}, {0, 1e20f, -1}),
  };
  Camera c;
  c.position = {0, 0, 5};
  expect_finite_image(render_prims(mixed, c), "tiny next to huge", 0);
}

std::string scene_with(const std::string& geometry) {
  return R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
             "lights": [{"type": "directional", "direction": [0, -1, -1], "intensity": [1, 1, 1]}],
             )" +
         geometry + "}";
}

/// Parses and renders `text`; returns "" when it rendered, else the InputError's message.
std::string parse_and_render(const std::string& text) {
  try {
    SceneDescription d = parse_scene_json(text, "robust.json");
    Environment env = std::move(d.env);
    LoadedScene s{"robust", build_hierarchy(std::move(d)), std::move(env)};
    RenderOptions o;
    o.width = 6, o.height = 4, o.spp = 1, o.threads = 1;
    const RenderOutput out = render(s, o);
    for (const Vec3& p : out.image)
      if (!is_finite(p)) return "non-finite pixel";
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

TEST(Degenerate, SceneJsonRejectsOrRendersExtremeInput) {
  struct Case {
    const char* geometry;
    const char* message;  ///< expected part of the error; nullptr: must render
  };
  const Case cases[] = {
      {R"("triangles": [{"vertices": [[0, 0, 0], [1, 1, 1], [2, 2, 2]]}])", "zero area"},
      {R"("triangles": [{"vertices": [[0, 0, 0], [0, 0, 0], [0, 0, 0]]}])", "zero area"},
      {R"("triangles": [{"vertices": [[0, 0, 0], [1e400, 0, 0], [0, 1, 0]]}])", "line 3, column"},
      {R"("triangles": [{"vertices": [[0, 0, 0], [NaN, 0, 0], [0, 1, 0]]}])", "invalid JSON"},
      {R"("triangles": [{"vertices": [[0, 0, 0], [Infinity, 0, 0], [0, 1, 0]]}])", "invalid JSON"},
      {R"("triangles": [{"vertices": [[0, 0, 0], [1e31, 0, 0], [0, 1, 0]]}])",
       "/triangles/0/vertices/1"},
      {R"("spheres": [{"centre": [0, 0, 0], "radius": 0}])", "/spheres/0/radius"},
      {R"("spheres": [{"centre": [0, 0, 0], "radius": -1}])", "/spheres/0/radius"},
      {R"("boxes": [{"min": [1, 0, 0], "max": [0, 1, 1]}])", "/boxes/0/max"},
      {R"("triangles": [{"vertices": [[-1e20, -1e20, 0], [1e20, -1e20, 0], [0, 1e20, 0]]}])",
       "/triangles/0/vertices/0"},
      {R"("triangles": [{"vertices": [[-1e12, -1e12, 0], [1e12, -1e12, 0], [0, 1e12, 0]]}])",
       nullptr},
      {R"("triangles": [{"vertices": [[-1e13, -1e13, 0], [1e13, -1e13, 0], [0, 1e13, 0]]}])",
       "/triangles/0/vertices/0"},
      {R"("spheres": [{"centre": [0, 0, 0], "radius": 1e12}])", nullptr},
      {R"("spheres": [{"centre": [0, 0, 0], "radius": 1e13}])", "expected a number <= 1e12"},
      {R"("meshes": [{"file": "/usr/share/assimp/models/OBJ/box.obj",
                      "transform": {"scale": 1e11, "translate": [1e12, 0, 0]}}])",
       "beyond the supported range"},
      {R"("triangles": [{"vertices": [[0, 0, 0], [1e-20, 0, 0], [0, 1e-20, 0]]}])", nullptr},
      {R"("triangles": [{"vertices": [[0, 0, 0], [1e-18, 0, 0], [0, 1e-18, 0]]}])", nullptr},
      {R"("triangles": [{"vertices": [[0, 0, 0], [1e-30, 0, 0], [0, 1e-30, 0]]}])", nullptr},
      {R"("triangles": [{"vertices": [[1, 1, 1], [1, 1, 1], [1, 1, 1.0000001]]}])", "zero area"},
      {R"("spheres": [{"centre": [0, 0, 0], "radius": 1e-20}])", nullptr},
      {R"("spheres": [{"centre": [1e12, 1e12, 1e12], "radius": 1e-20}])", nullptr},
      {R"("spheres": [{"centre": [1e20, 0, 0], "radius": 1}])", "/spheres/0/centre"},
      {R"("boxes": [{"min": [-1e12, -1e12, -1e12], "max": [1e12, 1e12, -1]}])", nullptr},
      {R"("boxes": [{"min": [0, 0, 0], "max": [1e-20, 1e-20, 1e-20]}])", nullptr},
  };
  for (const Case& c : cases) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string got = parse_and_render(scene_with(c.geometry));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(seconds, 10.0) << c.geometry << ": took " << seconds << " s";
    if (c.message == nullptr) {
      EXPECT_EQ(got, "") << c.geometry;
    } else {
      EXPECT_NE(got.find(c.message), std::string::npos)
          << c.geometry << "\n  expected an error containing '" << c.message << "', got '" << got
          << "'";
      EXPECT_EQ(got.rfind("robust.json: ", 0), 0u) << "the error names the file: " << got;
    }
  }
}

// -------------------------------------------------------------------------------------------
// Shadow-ray self-intersection.

/// One directional light; trace() the given primary rays and return, per ray, whether the
/// hit is lit (colour > 0) and the cosine at the hit.
struct LitCheck {
  std::size_t hits = 0, dark = 0;
  std::string first_dark;
};

LitCheck check_lit(const LoadedScene& s, Vec3 light_dir, const std::vector<Ray>& rays,
                   float min_cos, const std::function<bool(Vec3)>& unoccluded) {
  LitCheck r;
  RenderOptions o;
  o.lod = FullDetail{};
  for (const Ray& ray : rays) {
    const TraceOutput t = trace(s, o, ray);
    if (t.hit.kind != TraceHit::Kind::kPrimitive) continue;
    if (dot(t.hit.surf.normal, -light_dir) < min_cos || !unoccluded(t.hit.surf.p)) continue;
    ++r.hits;
    if (!(luminance(t.colour) > 0.0f) && r.dark++ == 0) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "at (%.9g %.9g %.9g)", t.hit.surf.p.x, t.hit.surf.p.y,
                    t.hit.surf.p.z);
      r.first_dark = buf;
    }
  }
  return r;
}

Environment sun_only(Vec3 dir, const Camera& camera) {
  Environment env;
  Light sun;
  sun.kind = LightKind::kDirectional;
  sun.direction = normalize(dir);
  env.lights = {sun};
  env.camera = camera;
  env.background = {0, 0, 0};
  return env;
}

TEST(ShadowAcne, ClosedMeshLitFromOutsideHasNoSelfShadowing) {
  // A convex closed mesh: every face turned toward the light is unoccluded.
  for (const auto& [scale, offset] : {std::pair{1.0f, Vec3{}}, std::pair{50.0f, Vec3{1e5f, 0, 0}},
                                      std::pair{1e-3f, Vec3{3.0f, -2.0f, 1.0f}}}) {
    const Mesh m = icosphere(3).transformed(scale, offset);
    const Vec3 light = normalize(Vec3{0.3f, -1.0f, -0.45f});
    Camera cam;
    cam.position = offset + Vec3{0.4f, 0.8f, 3.0f} * scale;
    cam.look_at = offset;
    LoadedScene s{"sphere", build_explicit(m.primitives(), {Surface{}}), sun_only(light, cam)};
    std::vector<Ray> rays;
    const int n = 200 / (kRayScale == 1 ? 1 : 4);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) rays.push_back(cam.generate(x + 0.5f, y + 0.5f, n, n));
    const LitCheck r = check_lit(s, light, rays, 1e-3f, [](Vec3) { return true; });
    EXPECT_GT(r.hits, rays.size() / 20) << "scale " << scale;
    EXPECT_EQ(r.dark, 0u) << "scale " << scale << ": " << r.dark << " of " << r.hits
                          << " lit points shadowed by their own surface, first " << r.first_dark;
  }
}

TEST(ShadowAcne, InstancedMeshFarFromTheOriginHasNoSelfShadowing) {
  // A convex closed mesh of 1 cm triangles as a rotated instance 100 m from the world origin,
  // as the Wusons of scenes/demo-field-fine.json: a shadow ray leaves its hit point by the
  // point's world error bound, but re-enters object space through the instance's inverse
  // transform, whose rounding (of the distance from the world origin, and turned into another
  // axis by the rotation) put it behind its own triangle.
  const Mesh m = icosphere(5).transformed(0.5f, {});
  std::vector<ExplicitHierarchy> meshes;
  meshes.push_back(build_explicit(m.primitives(), {Surface{}}));
  const Vec3 where{97.3f, 0.21f, 0.37f};
  const Transform place = AffineD::translate(where).as<float>() * Transform::rotate(1, 57.0);
  const Vec3 light = normalize(Vec3{0.45f, -1.0f, -0.6f});
  Camera cam;
  cam.position = where + Vec3{0.0f, 0.4f, 2.5f};
  cam.look_at = where;
  LoadedScene s{"instanced sphere", build_instanced(std::move(meshes), {Instance{place, 0}}),
                sun_only(light, cam)};
  std::vector<Ray> rays;
  const int n = 200 / (kRayScale == 1 ? 1 : 4);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) rays.push_back(cam.generate(x + 0.5f, y + 0.5f, n, n));
  const LitCheck r = check_lit(s, light, rays, 1e-3f, [](Vec3) { return true; });
  EXPECT_GT(r.hits, rays.size() / 20);
  EXPECT_EQ(r.dark, 0u) << r.dark << " of " << r.hits
                        << " lit points shadowed by their own surface, first " << r.first_dark;
}

TEST(ShadowAcne, FarPlaneAtGrazingLightIsFullyLitWhereUnoccluded) {
  // A tilted quad 1e5 units from the origin, a closed sphere mesh resting above it, the light
  // 3 degrees above the plane. Every point of the quad outside the sphere's shadow is lit.
  const Vec3 centre{1e5f, 2e4f, -7e4f};
  const Vec3 n = normalize(Vec3{0.1f, 1.0f, 0.05f});
  const Vec3 t1 = normalize(cross(n, Vec3{0, 0, 1})), t2 = cross(n, t1);
  const float half = 50.0f;
  std::vector<Primitive> prims = {
      Primitive::triangle(centre - t1 * half - t2 * half, centre + t1 * half - t2 * half,
                          centre + t1 * half + t2 * half),
      Primitive::triangle(centre - t1 * half - t2 * half, centre + t1 * half + t2 * half,
                          centre - t1 * half + t2 * half)};
  const float r = 5.0f;
  const Vec3 ball = centre + n * (r * 1.5f);
  for (const auto& t : icosphere(2).transformed(r, ball).primitives()) prims.push_back(t);
  const float grazing = 3.0f * std::numbers::pi_v<float> / 180.0f;
  const Vec3 light = -(n * std::sin(grazing) + t1 * std::cos(grazing));  // travels along -t1
  Camera cam;
  cam.position = centre + n * 120.0f + t2 * 10.0f;
  cam.look_at = centre;
  cam.vfov_deg = 50.0f;
  LoadedScene s{"plane", build_explicit(std::move(prims), {Surface{}}), sun_only(light, cam)};
  std::vector<Ray> rays;
  const int w = 240 / (kRayScale == 1 ? 1 : 4);
  for (int y = 0; y < w; ++y)
    for (int x = 0; x < w; ++x) rays.push_back(cam.generate(x + 0.5f, y + 0.5f, w, w));
  // Unoccluded: the shadow ray toward the light clears the sphere's circumscribed ball by a
  // margin (the tessellation lies inside it), and the point is on the plane, not the ball.
  const auto unoccluded = [&](Vec3 p) {
    if (length(p - ball) < r * 1.01f) return false;
    const Vec3 to_light = -light, f = ball - p;
    const float along = dot(f, to_light);
    return along < 0.0f || length(f - to_light * along) > r * 1.05f;
  };
  const LitCheck lit = check_lit(s, light, rays, 0.0f, unoccluded);
  EXPECT_GT(lit.hits, rays.size() / 4);
  EXPECT_EQ(lit.dark, 0u) << lit.dark << " of " << lit.hits
                          << " unoccluded points of the far plane are dark (shadow acne), first "
                          << lit.first_dark;
}

}  // namespace
}  // namespace amalgam

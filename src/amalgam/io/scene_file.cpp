#include "amalgam/io/scene_file.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>

#include "amalgam/io/mesh_import.h"
#include "amalgam/math/random.h"
#include "amalgam/math/transform.h"

namespace amalgam {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string fmt(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

/// Coordinates beyond this are rejected: a few times 1e19 squared overflows float, and the
/// renderer (camera, distances, spheres) would silently produce a black image (issue 6,
/// tests/geometry/robust_test.cpp: Degenerate.SceneJsonRejectsOrRendersExtremeInput).
constexpr double kMaxCoordinate = 1e18;

/// Fails when `b` reaches beyond +-kMaxCoordinate.
void check_extent(const Bbox& b, const std::string& where) {
  const double m = std::max(max_component(abs(b.lo)), max_component(abs(b.hi)));
  if (!(m <= kMaxCoordinate))
    throw InputError(where + ": the geometry reaches a coordinate of " + fmt(m) +
                     ", beyond the supported range [-1e18, 1e18]");
}

// ---------------------------------------------------------------------------------------------
using Affine = AffineD;  // composed in double, rounded once per instance

// ---------------------------------------------------------------------------------------------
// Checked access to the JSON document: every error names the JSON pointer of the value.

/// A value of the document with its JSON pointer.
struct Val {
  const json& j;
  std::string ptr;
};

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& ptr, const std::string& what) const {
    throw InputError(file_ + ": " + (ptr.empty() ? std::string("top level") : ptr) + ": " + what);
  }

  static std::string escape(const std::string& key) {
    std::string out;
    for (char c : key) {
      if (c == '~')
        out += "~0";
      else if (c == '/')
        out += "~1";
      else
        out += c;
    }
    return out;
  }

  static Val child(const Val& v, const std::string& key) {
    return {v.j.at(key), v.ptr + "/" + escape(key)};
  }
  static Val element(const Val& v, std::size_t i) {
    return {v.j.at(i), v.ptr + "/" + std::to_string(i)};
  }

  /// Checks that `v` is an object whose keys are all in `allowed` ("comment" is always
  /// allowed). Aliases ({"centre", "center"}) may not both be present.
  void object(const Val& v, std::initializer_list<const char*> allowed) const {
    if (!v.j.is_object()) fail(v.ptr, "expected an object, found " + type(v.j));
    for (const auto& [key, value] : v.j.items()) {
      if (key == "comment") continue;
      bool ok = false;
      for (const char* a : allowed) ok = ok || key == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(v.ptr + "/" + escape(key), "unknown key (expected one of: " + list + ")");
      }
    }
  }

  /// The child `key`, or `alias` (an alternative spelling); nullopt when neither is there.
  std::optional<Val> find(const Val& v, const std::string& key,
                          const std::string& alias = "") const {
    const bool has_key = v.j.contains(key), has_alias = !alias.empty() && v.j.contains(alias);
    if (has_key && has_alias)
      fail(v.ptr, "both '" + key + "' and '" + alias + "' given (they mean the same)");
    if (has_key) return child(v, key);
    if (has_alias) return child(v, alias);
    return std::nullopt;
  }
  Val require(const Val& v, const std::string& key, const std::string& alias = "") const {
    if (auto c = find(v, key, alias)) return *c;
    fail(v.ptr, "missing key '" + key + "'");
  }

  static std::string type(const json& j) {
    if (j.is_number()) return "a number";
    if (j.is_string()) return "a string";
    if (j.is_boolean()) return "a boolean";
    if (j.is_null()) return "null";
    if (j.is_array()) return "an array";
    return "an object";
  }

  double number(const Val& v, double lo = -kMaxCoordinate, double hi = kMaxCoordinate,
                const char* range = nullptr) const {
    if (!v.j.is_number()) fail(v.ptr, "expected a number, found " + type(v.j));
    const double x = v.j.get<double>();
    if (!std::isfinite(x) || x < lo || x > hi)
      fail(v.ptr, std::string("expected a number ") +
                      (range ? range : "in [" + fmt(lo) + ", " + fmt(hi) + "]") + ", found " +
                      fmt(x));
    return x;
  }
  double positive(const Val& v) const {
    const bool huge = v.j.is_number() && v.j.get<double>() > kMaxCoordinate;
    return number(v, 1e-30, kMaxCoordinate, huge ? "<= 1e18" : "> 0");
  }
  std::int64_t integer(const Val& v, std::int64_t lo, std::int64_t hi) const {
    const std::string expected =
        "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (!v.j.is_number_integer()) {
      if (v.j.is_number_float()) {
        const double x = v.j.get<double>();
        if (x == std::floor(x) && x >= static_cast<double>(lo) && x <= static_cast<double>(hi))
          return static_cast<std::int64_t>(x);
      }
      fail(v.ptr, expected + ", found " + (v.j.is_number() ? v.j.dump() : type(v.j)));
    }
    const bool neg = v.j.is_number_unsigned() ? false : v.j.get<std::int64_t>() < 0;
    if (!neg && v.j.is_number_unsigned() &&
        v.j.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX))
      fail(v.ptr, expected + ", found " + v.j.dump());
    const std::int64_t x = v.j.get<std::int64_t>();
    if (x < lo || x > hi) fail(v.ptr, expected + ", found " + v.j.dump());
    return x;
  }
  bool boolean(const Val& v) const {
    if (!v.j.is_boolean()) fail(v.ptr, "expected true or false, found " + type(v.j));
    return v.j.get<bool>();
  }
  std::string string(const Val& v) const {
    if (!v.j.is_string()) fail(v.ptr, "expected a string, found " + type(v.j));
    return v.j.get<std::string>();
  }
  void array(const Val& v) const {
    if (!v.j.is_array()) fail(v.ptr, "expected an array, found " + type(v.j));
  }
  Vec3 vec3(const Val& v) const {
    if (!v.j.is_array() || v.j.size() != 3)
      fail(v.ptr, "expected an array of 3 numbers, found " +
                      (v.j.is_array() ? "an array of " + std::to_string(v.j.size()) : type(v.j)));
    Vec3 r;
    for (int i = 0; i < 3; ++i) {
      const Val e = element(v, static_cast<std::size_t>(i));
      if (!e.j.is_number()) fail(v.ptr, "expected an array of 3 numbers, found " + v.j.dump());
      r[i] = static_cast<float>(number(e));
    }
    return r;
  }
  Vec3 colour(const Val& v) const {
    const Vec3 c = vec3(v);
    if (c.x < 0 || c.y < 0 || c.z < 0) fail(v.ptr, "expected non-negative colour components");
    return c;
  }
  Vec3 direction(const Val& v) const {
    const Vec3 d = vec3(v);
    if (!(length(d) > 0.0f)) fail(v.ptr, "expected a non-zero direction");
    return d;
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// ---------------------------------------------------------------------------------------------
// The scene file proper.

/// Splits every triangle into 4 at its edge midpoints, `levels` times (a flat tessellation:
/// the same surface with 4^levels times the triangles).
ImportedMesh subdivide(const ImportedMesh& in, int levels) {
  ImportedMesh out = in;
  for (int l = 0; l < levels; ++l) {
    std::vector<Primitive> next;
    next.reserve(out.triangles.size() * 4);
    for (const Primitive& t : out.triangles) {
      const Vec3 ab = (t.a + t.b) * 0.5f, bc = (t.b + t.c) * 0.5f, ca = (t.c + t.a) * 0.5f;
      next.push_back(Primitive::triangle(t.a, ab, ca, t.material));
      next.push_back(Primitive::triangle(ab, t.b, bc, t.material));
      next.push_back(Primitive::triangle(ca, bc, t.c, t.material));
      next.push_back(Primitive::triangle(ab, bc, ca, t.material));
    }
    out.triangles = std::move(next);
  }
  return out;
}

struct MeshEntry {
  std::string name;
  std::shared_ptr<const ImportedMesh> mesh;
  Affine model;                           ///< fit, then the mesh's transform
  std::optional<std::uint32_t> material;  ///< override
  std::string ptr;
};

class SceneParser {
 public:
  SceneParser(const std::string& path, const SceneFileConfig& config)
      : r_(path), dir_(fs::path(path).parent_path()), config_(config) {}

  SceneDescription parse(const json& doc) {
    const Val root{doc, ""};
    r_.object(root, {"camera", "lights", "background", "materials", "meshes", "spheres", "boxes",
                     "triangles", "instances"});
    out_.materials.push_back(Surface{});  // 0: the default material
    if (auto m = r_.find(root, "materials")) read_materials(*m);
    if (auto b = r_.find(root, "background")) out_.env.background = r_.colour(*b);

    // First count, then expand: an oversized scene fails before anything is allocated.
    std::vector<Val> spheres, boxes, triangles;
    if (auto v = r_.find(root, "spheres")) spheres = items(*v);
    if (auto v = r_.find(root, "boxes")) boxes = items(*v);
    if (auto v = r_.find(root, "triangles")) triangles = items(*v);
    if (auto v = r_.find(root, "meshes")) read_meshes(*v);
    std::vector<Placement> placements;
    if (auto v = r_.find(root, "instances")) placements = read_instances(*v);
    // Expand everything when the expanded scene is small; else keep large meshes instanced.
    double everything = static_cast<double>(spheres.size() + boxes.size() + triangles.size());
    for (const MeshEntry& m : meshes_)
      if (placed_.count(m.name)) everything += static_cast<double>(m.mesh->triangles.size());
    for (const Placement& p : placements)
      everything +=
          static_cast<double>(p.mesh->mesh->triangles.size()) * static_cast<double>(p.where.size());
    const bool expand_all =
        everything <= static_cast<double>(std::min(config_.expand_limit, config_.max_triangles));
    std::uint64_t total = spheres.size() + boxes.size() + triangles.size();
    std::uint64_t kept = 0;
    for (const MeshEntry& m : meshes_)
      if (placed_.count(m.name)) add_count(total, m.mesh->triangles.size(), m.ptr);
    for (Placement& p : placements) {
      p.expand = expand_all || p.mesh->mesh->triangles.size() < config_.instance_min_triangles;
      if (p.expand) {
        add_count(total, static_cast<double>(p.mesh->mesh->triangles.size()) * p.where.size(),
                  p.ptr);
      } else {
        kept += p.where.size();
        if (kept > config_.max_instances)
          r_.fail(p.ptr, "the scene would hold " + fmt(static_cast<double>(kept)) +
                             " instances, more than the limit of " +
                             fmt(static_cast<double>(config_.max_instances)));
      }
    }
    out_.prims.reserve(total);
    out_.instances.reserve(kept);

    for (const Val& s : spheres) read_sphere(s);
    for (const Val& b : boxes) read_box(b);
    for (const Val& t : triangles) read_triangle(t);
    for (const MeshEntry& m : meshes_)
      if (placed_.count(m.name)) place(m, Affine{}, m.material);
    Bbox bounds;
    for (const Placement& p : placements) {
      const auto material = p.material ? p.material : p.mesh->material;
      if (p.expand) {
        for (const Affine& a : p.where) place(*p.mesh, a, material);
      } else {
        const std::uint32_t mesh = instanced_mesh(*p.mesh, material);
        const Bbox object = object_bounds_[mesh];
        for (const Affine& a : p.where) {
          Instance in;
          for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 4; ++k) in.to_world.m[i][k] = static_cast<float>(a.m[i][k]);
          in.mesh = mesh;
          out_.instances.push_back(in);
          for (int c = 0; c < 8; ++c)
            bounds.extend(
                a.point({c & 1 ? object.hi.x : object.lo.x, c & 2 ? object.hi.y : object.lo.y,
                         c & 4 ? object.hi.z : object.lo.z}));
        }
      }
    }
    if (out_.prims.empty() && out_.instances.empty())
      r_.fail("",
              "the scene has no geometry (give meshes, spheres, boxes, triangles or "
              "instances)");

    for (const Primitive& p : out_.prims) bounds.extend(amalgam::bounds(p));
    check_extent(bounds, r_.file());  // transforms can scale valid input beyond the range
    if (auto c = r_.find(root, "camera"))
      out_.env.camera = read_camera(*c);
    else
      out_.env.camera = frame_camera(bounds);
    if (auto l = r_.find(root, "lights"))
      read_lights(*l);
    else
      out_.env.lights = default_lights(bounds, out_.env.camera);
    return std::move(out_);
  }

 private:
  struct Placement {
    const MeshEntry* mesh;
    std::vector<Affine> where;
    std::optional<std::uint32_t> material;
    std::string ptr;
    bool expand = true;  ///< into triangles, or kept as instances
  };

  /// The object-space mesh of `m` with `material` (or its own materials), made once.
  std::uint32_t instanced_mesh(const MeshEntry& m, std::optional<std::uint32_t> material) {
    const auto key = std::make_pair(&m, material ? static_cast<std::int64_t>(*material) : -1);
    auto it = instanced_.find(key);
    if (it != instanced_.end()) return it->second;
    const auto index = static_cast<std::uint32_t>(out_.meshes.size());
    const std::size_t before = out_.prims.size();
    place(m, Affine{}, material);  // appends world = object-space triangles to out_.prims
    std::vector<Primitive> tris(out_.prims.begin() + static_cast<std::ptrdiff_t>(before),
                                out_.prims.end());
    out_.prims.resize(before);
    Bbox b;
    for (const Primitive& t : tris) b.extend(amalgam::bounds(t));
    object_bounds_.push_back(b);
    out_.meshes.push_back(std::move(tris));
    instanced_.emplace(key, index);
    return index;
  }

  std::vector<Val> items(const Val& v) const {
    r_.array(v);
    std::vector<Val> out;
    for (std::size_t i = 0; i < v.j.size(); ++i) out.push_back(Reader::element(v, i));
    return out;
  }

  void add_count(std::uint64_t& total, double more, const std::string& ptr) const {
    if (static_cast<double>(total) + more > static_cast<double>(config_.max_triangles))
      r_.fail(ptr, "the scene would hold " + fmt(static_cast<double>(total) + more) +
                       " primitives, more than the limit of " +
                       fmt(static_cast<double>(config_.max_triangles)) +
                       " (instances of meshes with fewer than " +
                       fmt(static_cast<double>(config_.instance_min_triangles)) +
                       " triangles are expanded into triangles)");
    total += static_cast<std::uint64_t>(more);
  }

  // -- materials ------------------------------------------------------------------------------

  Surface read_surface(const Val& v) const {
    r_.object(v, {"colour", "color", "reflectance", "shininess"});
    Surface s;
    if (auto c = r_.find(v, "colour", "color")) s.colour = r_.colour(*c);
    if (auto c = r_.find(v, "reflectance")) s.reflectance = static_cast<float>(r_.number(*c, 0, 1));
    if (auto c = r_.find(v, "shininess"))
      s.shininess = static_cast<float>(r_.number(*c, 1e-3, 1e6));
    return s;
  }

  void read_materials(const Val& v) {
    if (!v.j.is_object()) r_.fail(v.ptr, "expected an object mapping names to materials");
    for (const auto& [name, value] : v.j.items()) {
      material_index_[name] = static_cast<std::uint32_t>(out_.materials.size());
      out_.materials.push_back(read_surface(Reader::child(v, name)));
    }
  }

  /// A "material" value: the name of a material, or a material object.
  std::uint32_t material_ref(const Val& v) {
    if (v.j.is_string()) {
      const std::string name = v.j.get<std::string>();
      auto it = material_index_.find(name);
      if (it == material_index_.end()) {
        std::string list;
        for (const auto& [n, i] : material_index_) list += (list.empty() ? "" : ", ") + n;
        r_.fail(v.ptr, "unknown material '" + name + "' (" +
                           (list.empty() ? "no materials are defined" : "defined: " + list) + ")");
      }
      return it->second;
    }
    if (!v.j.is_object())
      r_.fail(v.ptr, "expected a material name or a material object, found " + Reader::type(v.j));
    out_.materials.push_back(read_surface(v));
    return static_cast<std::uint32_t>(out_.materials.size() - 1);
  }
  std::uint32_t optional_material(const Val& v) {
    if (auto m = r_.find(v, "material")) return material_ref(*m);
    return 0;
  }

  // -- camera and lights ----------------------------------------------------------------------

  Camera read_camera(const Val& v) const {
    r_.object(v, {"position", "look_at", "up", "vfov"});
    Camera c;
    c.position = r_.vec3(r_.require(v, "position"));
    c.look_at = r_.vec3(r_.require(v, "look_at"));
    if (auto u = r_.find(v, "up")) c.up = r_.direction(*u);
    if (auto f = r_.find(v, "vfov"))
      c.vfov_deg = static_cast<float>(r_.number(*f, 0.01, 179.0, "in (0, 180) degrees"));
    const Vec3 d = c.look_at - c.position;
    if (!(length(d) > 0.0f)) r_.fail(v.ptr + "/look_at", "must differ from the position");
    if (!(length(cross(normalize(d), normalize(c.up))) > 1e-6f))
      r_.fail(v.ptr + "/up", "must not be parallel to the viewing direction");
    return c;
  }

  void read_lights(const Val& v) {
    for (const Val& l : items(v)) {
      const std::string type = r_.string(r_.require(l, "type"));
      Light light;
      if (type == "point") {
        r_.object(l, {"type", "position", "intensity"});
        light.kind = LightKind::kPoint;
        light.position = r_.vec3(r_.require(l, "position"));
      } else if (type == "directional") {
        r_.object(l, {"type", "direction", "intensity"});
        light.kind = LightKind::kDirectional;
        light.direction = normalize(r_.direction(r_.require(l, "direction")));
      } else {
        r_.fail(l.ptr + "/type", "expected \"point\" or \"directional\", found \"" + type + "\"");
      }
      light.intensity = r_.colour(r_.require(l, "intensity"));
      out_.env.lights.push_back(light);
    }
  }

  // -- primitives -----------------------------------------------------------------------------

  void read_sphere(const Val& v) {
    r_.object(v, {"centre", "center", "radius", "material"});
    const Vec3 c = r_.vec3(r_.require(v, "centre", "center"));
    const auto radius = static_cast<float>(r_.positive(r_.require(v, "radius")));
    out_.prims.push_back(Primitive::sphere(c, radius, optional_material(v)));
  }

  void read_box(const Val& v) {
    r_.object(v, {"min", "max", "material"});
    const Vec3 lo = r_.vec3(r_.require(v, "min")), hi = r_.vec3(r_.require(v, "max"));
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z)
      r_.fail(v.ptr + "/max", "expected max >= min in every coordinate");
    out_.prims.push_back(Primitive::box(lo, hi, optional_material(v)));
  }

  void read_triangle(const Val& v) {
    r_.object(v, {"vertices", "material"});
    const Val vs = r_.require(v, "vertices");
    if (!vs.j.is_array() || vs.j.size() != 3)
      r_.fail(vs.ptr, "expected an array of 3 vertices (each an array of 3 numbers)");
    Vec3 p[3];
    for (std::size_t i = 0; i < 3; ++i) p[i] = r_.vec3(Reader::element(vs, i));
    // Zero area, in double as the mesh importer does: in float, the cross product of a proper
    // triangle with 1e-18 legs underflows (tests/geometry/robust_test.cpp).
    double u[3], w[3];
    for (int k = 0; k < 3; ++k) u[k] = double(p[1][k]) - p[0][k], w[k] = double(p[2][k]) - p[0][k];
    const double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2],
                 cz = u[0] * w[1] - u[1] * w[0];
    if (!(cx * cx + cy * cy + cz * cz > 0.0)) r_.fail(vs.ptr, "the triangle has zero area");
    out_.prims.push_back(Primitive::triangle(p[0], p[1], p[2], optional_material(v)));
  }

  // -- transforms -----------------------------------------------------------------------------

  Affine read_transform(const Val& v) const {
    r_.object(v, {"matrix", "translate", "scale", "rotate_x_deg", "rotate_y_deg", "rotate_z_deg"});
    Affine a;
    if (auto m = r_.find(v, "matrix")) {
      if (v.j.size() != (v.j.contains("comment") ? 2u : 1u))
        r_.fail(v.ptr, "'matrix' cannot be combined with translate, scale or rotate");
      a = read_matrix(*m);
    } else {
      if (auto s = r_.find(v, "scale")) {
        Vec3 k;
        if (s->j.is_number()) {
          const auto f = static_cast<float>(r_.number(*s));
          k = {f, f, f};
        } else {
          k = r_.vec3(*s);
        }
        if (k.x == 0 || k.y == 0 || k.z == 0) r_.fail(s->ptr, "scale factors must not be zero");
        a = Affine::scale(k);
      }
      const char* rot[] = {"rotate_x_deg", "rotate_y_deg", "rotate_z_deg"};
      for (int axis = 0; axis < 3; ++axis)
        if (auto r = r_.find(v, rot[axis])) a = Affine::rotate(axis, r_.number(*r)) * a;
      if (auto t = r_.find(v, "translate")) a = Affine::translate(r_.vec3(*t)) * a;
    }
    return a;
  }

  Affine read_matrix(const Val& v) const {
    const char* expected = "expected a 4x4 matrix: 4 rows of 4 numbers, or 16 numbers, row-major";
    std::vector<double> m;
    if (!v.j.is_array()) r_.fail(v.ptr, expected);
    if (v.j.size() == 16) {
      for (std::size_t i = 0; i < 16; ++i) m.push_back(r_.number(Reader::element(v, i)));
    } else if (v.j.size() == 4) {
      for (std::size_t i = 0; i < 4; ++i) {
        const Val row = Reader::element(v, i);
        if (!row.j.is_array() || row.j.size() != 4) r_.fail(row.ptr, "expected a row of 4 numbers");
        for (std::size_t k = 0; k < 4; ++k) m.push_back(r_.number(Reader::element(row, k)));
      }
    } else {
      r_.fail(v.ptr, expected);
    }
    if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1)
      r_.fail(v.ptr, "expected an affine matrix (last row 0 0 0 1)");
    Affine a;
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 4; ++k) a.m[i][k] = m[static_cast<std::size_t>(i * 4 + k)];
    if (!(std::fabs(a.det()) > 0)) r_.fail(v.ptr, "the matrix is singular");
    return a;
  }

  // -- meshes and instances -------------------------------------------------------------------

  void read_meshes(const Val& v) {
    for (const Val& m : items(v)) {
      r_.object(m, {"file", "name", "transform", "material", "fit", "place", "subdivide"});
      const Val file = r_.require(m, "file");
      const fs::path rel = r_.string(file);
      const fs::path full = rel.is_absolute() || dir_.empty() ? rel : dir_ / rel;
      MeshEntry e;
      e.ptr = m.ptr;
      e.name = m.j.contains("name") ? r_.string(Reader::child(m, "name")) : m.ptr;
      for (const MeshEntry& other : meshes_)
        if (other.name == e.name)
          r_.fail(m.ptr + "/name", "a mesh named '" + e.name + "' already exists");
      auto cached = imported_.find(full.string());
      if (cached == imported_.end()) {
        try {
          ImportConfig ic;
          ic.max_triangles = config_.max_triangles;
          cached =
              imported_
                  .emplace(full.string(),
                           std::make_shared<const ImportedMesh>(import_mesh(full.string(), ic)))
                  .first;
        } catch (const InputError& err) {
          r_.fail(file.ptr, err.what());
        }
      }
      e.mesh = cached->second;
      if (auto sub = r_.find(m, "subdivide")) {
        const auto levels = static_cast<int>(r_.integer(*sub, 0, 8));
        const double tris = static_cast<double>(e.mesh->triangles.size()) * std::pow(4.0, levels);
        if (tris > static_cast<double>(config_.max_triangles))
          r_.fail(sub->ptr, "subdividing " + fmt(static_cast<double>(e.mesh->triangles.size())) +
                                " triangles " + std::to_string(levels) + " times gives " +
                                fmt(tris) + ", more than the limit of " +
                                fmt(static_cast<double>(config_.max_triangles)));
        if (levels > 0) e.mesh = std::make_shared<const ImportedMesh>(subdivide(*e.mesh, levels));
      }
      if (auto f = r_.find(m, "fit")) {
        // Uniform scale to the given largest extent, centred in x and z, resting on y = 0.
        const Bbox b = e.mesh->bounds;
        const double s = r_.positive(*f) / std::max(max_component(b.extent()), 1e-30f);
        e.model =
            Affine::scale({static_cast<float>(s), static_cast<float>(s), static_cast<float>(s)}) *
            Affine::translate({-b.center().x, -b.lo.y, -b.center().z});
      }
      if (auto t = r_.find(m, "transform")) e.model = read_transform(*t) * e.model;
      if (auto mat = r_.find(m, "material")) e.material = material_ref(*mat);
      const bool show = m.j.contains("place") ? r_.boolean(Reader::child(m, "place")) : true;
      meshes_.push_back(std::move(e));
      if (show) placed_.insert(meshes_.back().name);
    }
    for (const MeshEntry& e : meshes_) by_name_[e.name] = &e;
  }

  std::vector<Placement> read_instances(const Val& v) {
    std::vector<Placement> out;
    for (const Val& in : items(v)) {
      r_.object(in, {"mesh", "transform", "material", "transforms", "grid", "scatter"});
      const Val name = r_.require(in, "mesh");
      const std::string n = r_.string(name);
      auto it = by_name_.find(n);
      if (it == by_name_.end()) {
        std::string list;
        for (const auto& [k, e] : by_name_) list += (list.empty() ? "" : ", ") + k;
        r_.fail(name.ptr,
                "no mesh named '" + n + "' (" +
                    (list.empty() ? std::string("no meshes are defined") : "meshes: " + list) +
                    ")");
      }
      Placement p{it->second, {}, std::nullopt, in.ptr};
      const Affine local =
          in.j.contains("transform") ? read_transform(Reader::child(in, "transform")) : Affine{};
      if (auto mat = r_.find(in, "material")) p.material = material_ref(*mat);
      const int kinds =
          in.j.contains("transforms") + in.j.contains("grid") + in.j.contains("scatter");
      if (kinds != 1) r_.fail(in.ptr, "expected exactly one of 'transforms', 'grid' or 'scatter'");
      std::vector<Affine> where;
      if (auto t = r_.find(in, "transforms")) {
        for (const Val& e : items(*t)) where.push_back(read_transform(e));
      } else if (auto g = r_.find(in, "grid")) {
        where = read_grid(*g, it->second->mesh->triangles.size());
      } else {
        where = read_scatter(r_.require(in, "scatter"), it->second->mesh->triangles.size());
      }
      for (Affine& a : where) a = a * local;
      p.where = std::move(where);
      out.push_back(std::move(p));
    }
    return out;
  }

  static constexpr std::int64_t kMaxInstances = 100'000'000;

  std::vector<Affine> read_grid(const Val& v, std::size_t triangles) const {
    r_.object(v, {"nx", "nz", "spacing", "origin"});
    const std::int64_t nx = r_.integer(r_.require(v, "nx"), 1, 1'000'000);
    const std::int64_t nz = r_.integer(r_.require(v, "nz"), 1, 1'000'000);
    const double spacing = r_.positive(r_.require(v, "spacing"));
    const Vec3 origin = v.j.contains("origin") ? r_.vec3(Reader::child(v, "origin")) : Vec3{};
    if (nx * nz > kMaxInstances)
      r_.fail(v.ptr, "nx * nz = " + std::to_string(nx * nz) + " instances, more than " +
                         std::to_string(kMaxInstances));
    add_instances_check(static_cast<double>(nx * nz), triangles, v.ptr);
    std::vector<Affine> out;
    out.reserve(static_cast<std::size_t>(nx * nz));
    for (std::int64_t j = 0; j < nz; ++j)
      for (std::int64_t i = 0; i < nx; ++i)
        out.push_back(Affine::translate(
            {origin.x + static_cast<float>((static_cast<double>(i) - 0.5 * (nx - 1)) * spacing),
             origin.y,
             origin.z + static_cast<float>((static_cast<double>(j) - 0.5 * (nz - 1)) * spacing)}));
    return out;
  }

  std::vector<Affine> read_scatter(const Val& v, std::size_t triangles) const {
    r_.object(v, {"count", "radius", "seed", "centre", "center", "rotate"});
    const std::int64_t count = r_.integer(r_.require(v, "count"), 1, kMaxInstances);
    const double radius = r_.positive(r_.require(v, "radius"));
    const auto seed = static_cast<std::uint64_t>(
        v.j.contains("seed") ? r_.integer(Reader::child(v, "seed"), 0, INT64_MAX) : 0);
    const Vec3 centre = [&] {
      auto c = r_.find(v, "centre", "center");
      return c ? r_.vec3(*c) : Vec3{};
    }();
    const bool rotate = v.j.contains("rotate") ? r_.boolean(Reader::child(v, "rotate")) : true;
    add_instances_check(static_cast<double>(count), triangles, v.ptr);
    std::vector<Affine> out;
    out.reserve(static_cast<std::size_t>(count));
    for (std::int64_t i = 0; i < count; ++i) {
      // Uniform on the disc of `radius` in the plane y = centre.y.
      Sampler s(hash_combine(seed, static_cast<std::uint64_t>(i)));
      const double r = radius * std::sqrt(static_cast<double>(s.next()));
      const double phi = 2.0 * std::numbers::pi * s.next();
      const double angle = rotate ? 360.0 * s.next() : 0.0;
      out.push_back(Affine::translate({centre.x + static_cast<float>(r * std::cos(phi)), centre.y,
                                       centre.z + static_cast<float>(r * std::sin(phi))}) *
                    Affine::rotate(1, angle));
    }
    return out;
  }

  /// Fails before the generator allocates its transforms when its instances alone would hold
  /// too many triangles (the scene-wide count is checked again once all are read).
  void add_instances_check(double count, std::size_t triangles, const std::string& ptr) const {
    const double total = count * static_cast<double>(triangles);
    if (count > static_cast<double>(config_.max_instances))
      r_.fail(ptr, fmt(count) + " instances, more than the limit of " +
                       fmt(static_cast<double>(config_.max_instances)));
    // Only meshes too small to instance are sure to be expanded at this point.
    if (triangles < config_.instance_min_triangles &&
        total > static_cast<double>(config_.max_triangles))
      r_.fail(ptr, fmt(count) + " instances of " + fmt(static_cast<double>(triangles)) +
                       " triangles would hold " + fmt(total) +
                       " triangles, more than the limit of " +
                       fmt(static_cast<double>(config_.max_triangles)) +
                       " (instances of meshes with fewer than " +
                       fmt(static_cast<double>(config_.instance_min_triangles)) +
                       " triangles are expanded into triangles)");
  }

  void place(const MeshEntry& m, const Affine& where, std::optional<std::uint32_t> material) {
    const Affine a = where * m.model;
    const auto base = static_cast<std::uint32_t>(out_.materials.size());
    const bool own = !material.has_value();
    if (own) {
      // The mesh's own materials, appended once per mesh entry.
      auto it = material_base_.find(&m);
      if (it == material_base_.end()) {
        out_.materials.insert(out_.materials.end(), m.mesh->materials.begin(),
                              m.mesh->materials.end());
        it = material_base_.emplace(&m, base).first;
      }
      for (const Primitive& t : m.mesh->triangles)
        out_.prims.push_back(
            Primitive::triangle(a.point(t.a), a.point(t.b), a.point(t.c), it->second + t.material));
    } else {
      for (const Primitive& t : m.mesh->triangles)
        out_.prims.push_back(
            Primitive::triangle(a.point(t.a), a.point(t.b), a.point(t.c), *material));
    }
  }

  Reader r_;
  fs::path dir_;
  SceneFileConfig config_;
  SceneDescription out_;
  std::map<std::string, std::uint32_t> material_index_;
  std::map<std::string, std::shared_ptr<const ImportedMesh>> imported_;
  std::vector<MeshEntry> meshes_;
  std::set<std::string> placed_;
  std::map<std::string, const MeshEntry*> by_name_;
  std::map<const MeshEntry*, std::uint32_t> material_base_;
  std::map<std::pair<const MeshEntry*, std::int64_t>, std::uint32_t> instanced_;
  std::vector<Bbox> object_bounds_;  ///< per instanced mesh
};

/// Turns nlohmann's parse error into "line L, column C: what".
std::string describe_parse_error(const json::parse_error& e, const std::string& text) {
  const std::size_t byte = std::min<std::size_t>(e.byte == 0 ? 0 : e.byte - 1, text.size());
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < byte; ++i) {
    if (text[i] == '\n')
      ++line, column = 1;
    else
      ++column;
  }
  std::string what = e.what();
  // "[json.exception.parse_error.101] parse error at line 1, column 2: syntax error ..."
  const auto col = what.find("column ");
  const auto colon = what.find(": ", col == std::string::npos ? 0 : col);
  if (colon != std::string::npos) what = what.substr(colon + 2);
  for (char& c : what)
    if (c == '\n' || c == '\r') c = ' ';
  return "line " + std::to_string(line) + ", column " + std::to_string(column) +
         ": invalid JSON: " + what;
}

/// Turns nlohmann's "number overflow parsing '1e400'" into "line L, column C: ..." by finding
/// the quoted token in the text (found by the fuzzer, see tests/fuzz_regressions_test.cpp).
std::string describe_overflow(const json::out_of_range& e, const std::string& text) {
  const std::string what = e.what();
  const auto open = what.find('\''), close = what.rfind('\'');
  const std::string token =
      open != std::string::npos && close > open ? what.substr(open + 1, close - open - 1) : "";
  const std::size_t at = token.empty() ? std::string::npos : text.find(token);
  std::string where;
  if (at != std::string::npos) {
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < at; ++i) {
      if (text[i] == '\n')
        ++line, column = 1;
      else
        ++column;
    }
    where = "line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
  }
  return where + "invalid JSON: number " + (token.empty() ? "" : token + " ") +
         "is out of the range of a double";
}

}  // namespace

SceneDescription parse_scene_json(const std::string& text, const std::string& path,
                                  const SceneFileConfig& config) {
  json doc;
  try {
    doc = json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    throw InputError(path + ": " + describe_parse_error(e, text));
  } catch (const json::out_of_range& e) {
    // A number beyond double's range ("1e400"): the exception names the token, not its place.
    throw InputError(path + ": " + describe_overflow(e, text));
  }
  return SceneParser(path, config).parse(doc);
}

SceneDescription read_scene_json(const std::string& path, const SceneFileConfig& config) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path + ": no such file");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  if (!in || !(text << in.rdbuf())) throw InputError(path + ": cannot read the file");
  return parse_scene_json(text.str(), path, config);
}

Camera frame_camera(const Bbox& bounds, float vfov_deg) {
  Camera c;
  c.vfov_deg = vfov_deg;
  const Vec3 centre = bounds.center();
  const float radius = std::max(0.5f * bounds.diagonal(), 1e-6f);
  // Azimuth 35 degrees right of +z, elevation 25 degrees.
  const float az = 35.0f * std::numbers::pi_v<float> / 180.0f;
  const float el = 25.0f * std::numbers::pi_v<float> / 180.0f;
  const Vec3 dir{std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
  const float half = 0.5f * vfov_deg * std::numbers::pi_v<float> / 180.0f;
  c.position = centre + dir * (radius / std::sin(half));
  c.look_at = centre;
  c.up = {0, 1, 0};
  return c;
}

std::vector<Light> default_lights(const Bbox& bounds, const Camera& camera) {
  Light key;
  key.kind = LightKind::kDirectional;
  key.direction = normalize(Vec3{0.45f, -1.0f, -0.6f});
  key.intensity = {2.2f, 2.1f, 2.0f};
  Light fill;
  fill.kind = LightKind::kPoint;
  fill.position = camera.position;
  const float d = length(camera.position - bounds.center());
  const float e = 0.9f * d * d;  // irradiance 0.9 at the centre of the bounds
  fill.intensity = {e, e, e};
  return {key, fill};
}

SceneDescription mesh_scene(const std::string& path, const SceneFileConfig& config) {
  ImportConfig ic;
  ic.max_triangles = config.max_triangles;
  ImportedMesh m = import_mesh(path, ic);
  check_extent(m.bounds, path);
  SceneDescription d;
  d.prims = std::move(m.triangles);
  d.materials = std::move(m.materials);
  d.env.camera = frame_camera(m.bounds);
  d.env.lights = default_lights(m.bounds, d.env.camera);
  return d;
}

}  // namespace amalgam

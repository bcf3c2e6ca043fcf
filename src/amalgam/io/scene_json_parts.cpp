#include "amalgam/io/scene_json_parts.h"

#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "amalgam/io/image.h"
#include "amalgam/io/scene_json.h"

namespace amalgam::scene_json {

Surface read_surface(const JsonReader& r, const JsonValue& v) {
  r.object(v, {"colour", "color", "reflectance", "shininess"});
  Surface s;
  if (auto c = r.find(v, "colour", "color")) s.colour = r.colour(*c);
  if (auto c = r.find(v, "reflectance")) s.reflectance = static_cast<float>(r.number(*c, 0, 1));
  if (auto c = r.find(v, "shininess")) s.shininess = static_cast<float>(r.number(*c, 1e-3, 1e6));
  return s;
}

Camera read_camera(const JsonReader& r, const JsonValue& v) {
  r.object(v, {"position", "look_at", "up", "vfov"});
  Camera c;
  c.position = r.vec3(r.require(v, "position"));
  c.look_at = r.vec3(r.require(v, "look_at"));
  if (auto u = r.find(v, "up")) c.up = r.direction(*u);
  if (auto f = r.find(v, "vfov"))
    c.vfov_deg = static_cast<float>(r.number(*f, 0.01, 179.0, "in (0, 180) degrees"));
  const Vec3 d = c.look_at - c.position;
  if (!(length(d) > 0.0f)) r.fail(v.ptr + "/look_at", "must differ from the position");
  if (!(length(cross(normalize(d), normalize(c.up))) > 1e-6f))
    r.fail(v.ptr + "/up", "must not be parallel to the viewing direction");
  return c;
}

namespace {

Light read_sky(const JsonReader& r, const JsonValue& l, SkyInput& sky) {
  r.object(l, {"type", "radiance", "map", "rotate_y_deg", "samples"});
  if (sky.seen) r.fail(l.ptr + "/type", "a scene has at most one sky");
  sky.seen = true;
  Light light;
  light.kind = LightKind::kSky;
  light.samples = 16;
  if (auto x = r.find(l, "radiance")) light.intensity = r.colour(*x);
  if (auto x = r.find(l, "samples")) light.samples = static_cast<int>(r.integer(*x, 1, 4096));
  float rotate = 0.0f;
  if (auto x = r.find(l, "rotate_y_deg")) rotate = static_cast<float>(r.number(*x, -360, 360));
  if (auto m = r.find(l, "map")) {
    const std::filesystem::path path = sky.dir / r.string(*m);
    int w = 0, h = 0;
    std::vector<Vec3> px;
    try {
      px = read_image(path.string(), w, h);
    } catch (const std::exception& e) {
      r.fail(m->ptr, e.what());
    }
    try {
      *sky.map = std::make_shared<const SkyMap>(w, h, std::move(px), Vec3{1, 1, 1}, rotate);
    } catch (const InputError& e) {
      r.fail(m->ptr, path.string() + ": " + e.what());
    }
    sky.inputs->push_back(path.string());
  }
  return light;
}

}  // namespace

Light read_light(const JsonReader& r, const JsonValue& l, SkyInput& sky) {
  const std::string type = r.string(r.require(l, "type"));
  Light light;
  if (type == "sky") return read_sky(r, l, sky);
  if (type == "point") {
    r.object(l, {"type", "position", "intensity", "radius", "samples"});
    light.kind = LightKind::kPoint;
    light.position = r.vec3(r.require(l, "position"));
    if (auto x = r.find(l, "radius")) light.radius = static_cast<float>(r.positive(*x));
  } else if (type == "directional") {
    r.object(l, {"type", "direction", "intensity", "angle", "samples"});
    light.kind = LightKind::kDirectional;
    light.direction = normalize(r.direction(r.require(l, "direction")));
    if (auto x = r.find(l, "angle"))
      light.angle = static_cast<float>(r.number(*x, 1e-4, 90.0, "in degrees, (0, 90]") *
                                       std::numbers::pi / 180.0);
  } else if (type == "spot") {
    r.object(l, {"type", "position", "direction", "intensity", "inner_deg", "outer_deg"});
    light.kind = LightKind::kSpot;
    light.position = r.vec3(r.require(l, "position"));
    light.direction = normalize(r.direction(r.require(l, "direction")));
    double outer = 45.0, inner = 0.0;
    if (auto x = r.find(l, "outer_deg")) outer = r.number(*x, 1e-3, 90.0, "in degrees, (0, 90]");
    if (auto x = r.find(l, "inner_deg"))
      inner = r.number(*x, 0.0, outer, "in degrees, [0, outer_deg]");
    light.cos_inner = static_cast<float>(std::cos(inner * std::numbers::pi / 180.0));
    light.cos_outer = static_cast<float>(std::cos(outer * std::numbers::pi / 180.0));
  } else {
    r.fail(l.ptr + "/type",
           "expected \"point\", \"directional\", \"spot\" or \"sky\", found \"" + type + "\"");
  }
  light.intensity = r.colour(r.require(l, "intensity"));
  if (auto x = r.find(l, "samples")) {
    if (!light.sized())
      r.fail(x->ptr, type == "point" ? "samples needs a radius (a sized light)"
                                     : "samples needs an angle (a sized light)");
    light.samples = static_cast<int>(r.integer(*x, 1, 4096));
  }
  return light;
}

Primitive read_sphere(const JsonReader& r, const JsonValue& v) {
  r.object(v, {"centre", "center", "radius", "material"});
  const Vec3 c = r.vec3(r.require(v, "centre", "center"));
  const auto radius = static_cast<float>(r.positive(r.require(v, "radius")));
  return Primitive::sphere(c, radius);
}

Primitive read_box(const JsonReader& r, const JsonValue& v) {
  r.object(v, {"min", "max", "material"});
  const Vec3 lo = r.vec3(r.require(v, "min")), hi = r.vec3(r.require(v, "max"));
  if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z)
    r.fail(v.ptr + "/max", "expected max >= min in every coordinate");
  return Primitive::box(lo, hi);
}

Primitive read_triangle(const JsonReader& r, const JsonValue& v) {
  r.object(v, {"vertices", "material"});
  const JsonValue vs = r.require(v, "vertices");
  if (!vs.j.is_array() || vs.j.size() != 3)
    r.fail(vs.ptr, "expected an array of 3 vertices (each an array of 3 numbers)");
  Vec3 p[3];
  for (std::size_t i = 0; i < 3; ++i) p[i] = r.vec3(JsonReader::element(vs, i));
  // Zero area, in double as the mesh importer does: in float, the cross product of a proper
  // triangle with 1e-18 legs underflows (tests/geometry/robust_test.cpp).
  double u[3], w[3];
  for (int k = 0; k < 3; ++k) u[k] = double(p[1][k]) - p[0][k], w[k] = double(p[2][k]) - p[0][k];
  const double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2],
               cz = u[0] * w[1] - u[1] * w[0];
  if (!(cx * cx + cy * cy + cz * cz > 0.0)) r.fail(vs.ptr, "the triangle has zero area");
  return Primitive::triangle(p[0], p[1], p[2]);
}

AffineD read_transform(const JsonReader& r, const JsonValue& v) {
  r.object(v, {"matrix", "translate", "scale", "rotate_x_deg", "rotate_y_deg", "rotate_z_deg"});
  AffineD a;
  if (auto m = r.find(v, "matrix")) {
    if (v.j.size() != (v.j.contains("comment") ? 2u : 1u))
      r.fail(v.ptr, "'matrix' cannot be combined with translate, scale or rotate");
    a = read_matrix(r, *m);
  } else {
    if (auto s = r.find(v, "scale")) {
      Vec3 k;
      if (s->j.is_number()) {
        const auto f = static_cast<float>(r.number(*s));
        k = {f, f, f};
      } else {
        k = r.vec3(*s);
      }
      if (k.x == 0 || k.y == 0 || k.z == 0) r.fail(s->ptr, "scale factors must not be zero");
      a = AffineD::scale(k);
    }
    const char* rot[] = {"rotate_x_deg", "rotate_y_deg", "rotate_z_deg"};
    for (int axis = 0; axis < 3; ++axis)
      if (auto rd = r.find(v, rot[axis])) a = AffineD::rotate(axis, r.number(*rd)) * a;
    if (auto t = r.find(v, "translate")) a = AffineD::translate(r.vec3(*t)) * a;
  }
  return a;
}

AffineD read_matrix(const JsonReader& r, const JsonValue& v) {
  const char* expected = "expected a 4x4 matrix: 4 rows of 4 numbers, or 16 numbers, row-major";
  std::vector<double> m;
  if (!v.j.is_array()) r.fail(v.ptr, expected);
  if (v.j.size() == 16) {
    for (std::size_t i = 0; i < 16; ++i) m.push_back(r.number(JsonReader::element(v, i)));
  } else if (v.j.size() == 4) {
    for (std::size_t i = 0; i < 4; ++i) {
      const JsonValue row = JsonReader::element(v, i);
      if (!row.j.is_array() || row.j.size() != 4) r.fail(row.ptr, "expected a row of 4 numbers");
      for (std::size_t k = 0; k < 4; ++k) m.push_back(r.number(JsonReader::element(row, k)));
    }
  } else {
    r.fail(v.ptr, expected);
  }
  if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1)
    r.fail(v.ptr, "expected an affine matrix (last row 0 0 0 1)");
  AffineD a;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 4; ++k) a.m[i][k] = m[static_cast<std::size_t>(i * 4 + k)];
  if (!(std::fabs(a.det()) > 0)) r.fail(v.ptr, "the matrix is singular");
  return a;
}

void append_mesh(SceneDescription& out, const ImportedMesh& mesh, const AffineD& a,
                 std::optional<std::uint32_t> material, std::uint32_t base) {
  const bool textured = !material && !mesh.uvs.empty();
  if (textured || !out.uvs.empty()) out.uvs.resize(out.prims.size());
  const bool smooth = !mesh.normals.empty();  // geometry: kept under a replaced material too
  if (smooth || !out.normals.empty()) out.normals.resize(out.prims.size());
  Vec3 rows[3];  // M^-T, for the normals (only a mesh with normals needs the inverse)
  if (smooth) {
    const AffineD inv = a.inverse();
    for (int i = 0; i < 3; ++i)
      rows[i] = Vec3{static_cast<float>(inv.m[0][i]), static_cast<float>(inv.m[1][i]),
                     static_cast<float>(inv.m[2][i])};
  }
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const Primitive& t = mesh.triangles[i];
    out.prims.push_back(Primitive::triangle(a.point(t.a), a.point(t.b), a.point(t.c),
                                            material ? *material : base + t.material));
    if (textured) out.uvs.push_back(mesh.uvs[i]);
    if (smooth) out.normals.push_back(transform(mesh.normals[i], rows));
  }
  if (!out.uvs.empty()) out.uvs.resize(out.prims.size());
  if (!out.normals.empty()) out.normals.resize(out.prims.size());
}

std::uint32_t append_materials(SceneDescription& out, const ImportedMesh& mesh) {
  const auto base = static_cast<std::uint32_t>(out.materials.size());
  const auto shift = static_cast<std::int32_t>(out.textures.size());
  for (Surface s : mesh.materials) {
    if (s.texture >= 0) s.texture += shift;
    out.materials.push_back(s);
  }
  out.textures.insert(out.textures.end(), mesh.textures.begin(), mesh.textures.end());
  return base;
}

namespace {
constexpr std::int64_t kMaxInstances = 100'000'000;
}  // namespace

GridPattern read_grid(const JsonReader& r, const JsonValue& v) {
  r.object(v, {"nx", "nz", "spacing", "origin"});
  const std::int64_t nx = r.integer(r.require(v, "nx"), 1, 1'000'000);
  const std::int64_t nz = r.integer(r.require(v, "nz"), 1, 1'000'000);
  const double spacing = r.positive(r.require(v, "spacing"));
  const Vec3 origin = v.j.contains("origin") ? r.vec3(JsonReader::child(v, "origin")) : Vec3{};
  if (nx * nz > kMaxInstances)
    r.fail(v.ptr, "nx * nz = " + std::to_string(nx * nz) + " instances, more than " +
                      std::to_string(kMaxInstances));
  return {nx, nz, spacing, origin};
}

ScatterPattern read_scatter(const JsonReader& r, const JsonValue& v) {
  r.object(v, {"count", "radius", "seed", "centre", "center", "rotate"});
  const std::int64_t count = r.integer(r.require(v, "count"), 1, kMaxInstances);
  const double radius = r.positive(r.require(v, "radius"));
  const auto seed = static_cast<std::uint64_t>(
      v.j.contains("seed") ? r.integer(JsonReader::child(v, "seed"), 0, INT64_MAX) : 0);
  auto c = r.find(v, "centre", "center");
  const Vec3 centre = c ? r.vec3(*c) : Vec3{};
  const bool rotate = v.j.contains("rotate") ? r.boolean(JsonReader::child(v, "rotate")) : true;
  return {count, radius, seed, centre, rotate};
}

std::string beyond_limit(double bytes, const SceneFileConfig& config) {
  if (config.max_bytes == 0 || bytes <= static_cast<double>(config.max_bytes)) return {};
  return format_bytes(bytes) + ", more than " + config.limit_name;
}

/// The offset of the first byte that is not part of well-formed UTF-8 (or a NUL), or npos.
std::size_t first_invalid_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    int n = c < 0x80 ? 0 : (c >> 5) == 0x6 ? 1 : (c >> 4) == 0xe ? 2 : (c >> 3) == 0x1e ? 3 : -1;
    if (c == 0 || n < 0 || i + static_cast<std::size_t>(n) >= s.size()) return i;
    for (int k = 1; k <= n; ++k)
      if ((static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]) >> 6) != 0x2) return i;
    i += static_cast<std::size_t>(n) + 1;
  }
  return std::string::npos;
}

}  // namespace amalgam::scene_json

namespace amalgam {

ImportConfig import_config(const SceneFileConfig& config) {
  ImportConfig ic;
  ic.max_triangles = config.max_triangles;
  ic.max_bytes = config.import_max_bytes;
  ic.limit_name = config.import_limit_name;
  ic.smooth_normals = config.smooth_normals;
  return ic;
}

std::string format_bytes(double b) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  int u = 0;
  while (b >= 1024 && u < 4) b /= 1024, ++u;
  std::ostringstream s;
  s << std::fixed << std::setprecision(u ? 1 : 0) << b << " " << units[u];
  return s.str();
}

void check_memory(const std::string& where, std::uint64_t need, const SceneFileConfig& config) {
  if (config.max_bytes == 0 || need <= config.max_bytes) return;
  throw InputError(where + ": the scene needs about " + format_bytes(static_cast<double>(need)) +
                   " (estimated before building, within about 25 %), more than " +
                   config.limit_name);
}

}  // namespace amalgam

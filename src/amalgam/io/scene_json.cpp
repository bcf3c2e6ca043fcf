#include "amalgam/io/scene_json.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/io/json_reader.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/io/scene_json_parts.h"
#include "amalgam/math/transform.h"
#include "amalgam/scene/coordinate_limit.h"
#include "amalgam/scene/framing.h"
#include "amalgam/scene/instance_patterns.h"
#include "amalgam/scene/subdivide.h"

namespace amalgam {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;
using Affine = AffineD;  // composed in double, rounded once per instance

std::string fmt(double v) {
  return JsonReader::format(v);
}

// ---------------------------------------------------------------------------------------------
// The scene file proper: its structure (materials by name, meshes, instances, the limits on
// what it may expand to). The parts that stand alone are read by scene_json_parts.h.

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
    const JsonValue root{doc, ""};
    r_.object(root, {"camera", "lights", "background", "materials", "meshes", "spheres", "boxes",
                     "triangles", "instances"});
    out_.materials.push_back(Surface{});  // 0: the default material
    if (auto m = r_.find(root, "materials")) read_materials(*m);
    if (auto b = r_.find(root, "background")) out_.env.background = r_.colour(*b);

    // First count, then expand: an oversized scene fails before anything is allocated.
    std::vector<JsonValue> spheres, boxes, triangles;
    if (auto v = r_.find(root, "spheres")) spheres = r_.items(*v);
    if (auto v = r_.find(root, "boxes")) boxes = r_.items(*v);
    if (auto v = r_.find(root, "triangles")) triangles = r_.items(*v);
    if (auto v = r_.find(root, "meshes")) read_meshes(*v);
    std::vector<Placement> placements;
    if (auto v = r_.find(root, "instances")) placements = read_instances(*v);
    // Expand everything when the expanded scene is small; else keep large meshes instanced.
    double everything = static_cast<double>(spheres.size() + boxes.size() + triangles.size());
    for (const MeshEntry& m : meshes_)
      if (placed_.count(m.name)) everything += static_cast<double>(m.mesh->triangles.size());
    for (const Placement& p : placements)
      everything +=
          static_cast<double>(p.mesh->mesh->triangles.size()) * static_cast<double>(p.count);
    // With config_.objects every mesh placed stays an object of its own (an instance).
    const bool objects = config_.objects;
    const bool expand_all =
        !objects &&
        everything <= static_cast<double>(std::min(config_.expand_limit, config_.max_triangles));
    std::uint64_t total = spheres.size() + boxes.size() + triangles.size();
    std::uint64_t kept = 0;
    for (const MeshEntry& m : meshes_)
      if (placed_.count(m.name)) {
        if (objects)
          ++kept;
        else
          add_count(total, m.mesh->triangles.size(), m.ptr);
      }
    for (Placement& p : placements) {
      p.expand = !objects &&
                 (expand_all || p.mesh->mesh->triangles.size() < config_.instance_min_triangles);
      if (p.expand) {
        add_count(total, static_cast<double>(p.mesh->mesh->triangles.size()) * p.count, p.ptr);
      } else {
        kept += p.count;
        if (kept > config_.max_instances)
          r_.fail(p.ptr, "the scene would hold " + fmt(static_cast<double>(kept)) +
                             " instances, more than the limit of " +
                             fmt(static_cast<double>(config_.max_instances)));
      }
    }
    if (config_.max_bytes) {  // before any triangle is expanded or built
      std::uint64_t instanced = 0;
      std::set<const MeshEntry*> seen;
      for (const Placement& p : placements)
        if (!p.expand && seen.insert(p.mesh).second) instanced += p.mesh->mesh->triangles.size();
      if (objects)
        for (const MeshEntry& m : meshes_)
          if (placed_.count(m.name) && seen.insert(&m).second)
            instanced += m.mesh->triangles.size();
      std::uint64_t textures = 0;  // texels once per file; coordinates as read and as built
      bool smooth = false;         // vertex normals: as the coordinates
      for (const auto& [file, mesh] : imported_) {
        for (const Texture& t : mesh->textures) textures += t.texels.size();
        smooth = smooth || !mesh->normals.empty();
      }
      if (textures) textures += 2 * sizeof(TexCoords) * (total + instanced);
      if (smooth) textures += 2 * sizeof(VertexNormals) * (total + instanced);
      check_memory(r_.file(), MemoryModel::scene(total, instanced, kept) + textures, config_);
    }
    out_.prims.reserve(total);
    out_.instances.reserve(kept);

    for (const JsonValue& s : spheres) read_sphere(s);
    for (const JsonValue& b : boxes) read_box(b);
    for (const JsonValue& t : triangles) read_triangle(t);
    Bbox bounds;
    for (const MeshEntry& m : meshes_) {
      if (!placed_.count(m.name)) continue;
      if (!objects) {
        place(m, Affine{}, m.material);
        continue;
      }
      Instance in;  // identity: the mesh's own transform is in its object space
      in.mesh = instanced_mesh(m, m.material);
      out_.instances.push_back(in);
      bounds.extend(object_bounds_[in.mesh]);
    }
    for (const Placement& p : placements) {
      const auto material = p.material ? p.material : p.mesh->material;
      if (p.expand) {
        for (const Affine& a : p.where()) place(*p.mesh, a, material);
      } else {
        const std::uint32_t mesh = instanced_mesh(*p.mesh, material);
        const Bbox object = object_bounds_[mesh];
        for (const Affine& a : p.where()) {
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
    // A camera given with a wrong type is reported before "no geometry": the first problem of
    // the file in the order a reader meets it.
    if (auto c = r_.find(root, "camera")) (void)scene_json::read_camera(r_, *c);
    if (out_.prims.empty() && out_.instances.empty())
      r_.fail("",
              "the scene has no geometry (give meshes, spheres, boxes, triangles or "
              "instances)");

    for (const Primitive& p : out_.prims) bounds.extend(amalgam::bounds(p));
    check_extent(bounds, r_.file());  // transforms can scale valid input beyond the range
    if (auto c = r_.find(root, "camera"))
      out_.env.camera = scene_json::read_camera(r_, *c);
    else
      out_.env.camera = frame_camera(bounds), out_.framed_camera = true;
    if (auto l = r_.find(root, "lights"))
      read_lights(*l);
    else
      out_.env.lights = default_lights(bounds, out_.env.camera), out_.default_lights = true;
    return std::move(out_);
  }

 private:
  struct Placement {
    const MeshEntry* mesh;
    /// Generates the transforms once the whole scene's counts are checked against the limits.
    std::function<std::vector<Affine>()> where;
    std::size_t count = 0;  ///< of where()
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
    out_.mesh_uvs.push_back(
        scene_json::take_tail(out_.uvs, before, !material && !m.mesh->uvs.empty()));
    out_.mesh_normals.push_back(
        scene_json::take_tail(out_.normals, before, !m.mesh->normals.empty()));
    Bbox b;
    for (const Primitive& t : tris) b.extend(amalgam::bounds(t));
    object_bounds_.push_back(b);
    out_.meshes.push_back(std::move(tris));
    instanced_.emplace(key, index);
    return index;
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

  void read_materials(const JsonValue& v) {
    if (!v.j.is_object()) r_.fail(v.ptr, "expected an object mapping names to materials");
    for (const auto& [name, value] : v.j.items()) {
      material_index_[name] = static_cast<std::uint32_t>(out_.materials.size());
      out_.materials.push_back(scene_json::read_surface(r_, JsonReader::child(v, name)));
    }
  }

  /// A "material" value: the name of a material, or a material object.
  std::uint32_t material_ref(const JsonValue& v) {
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
      r_.fail(v.ptr,
              "expected a material name or a material object, found " + JsonReader::type(v.j));
    out_.materials.push_back(scene_json::read_surface(r_, v));
    return static_cast<std::uint32_t>(out_.materials.size() - 1);
  }
  std::uint32_t optional_material(const JsonValue& v) {
    if (auto m = r_.find(v, "material")) return material_ref(*m);
    return 0;
  }

  // -- camera and lights ----------------------------------------------------------------------

  void read_lights(const JsonValue& v) {
    scene_json::SkyInput sky{dir_, &out_.env.sky_map, &out_.inputs};
    for (const JsonValue& l : r_.items(v))
      out_.env.lights.push_back(scene_json::read_light(r_, l, sky));
  }

  // -- primitives -----------------------------------------------------------------------------

  void read_sphere(const JsonValue& v) {
    Primitive p = scene_json::read_sphere(r_, v);
    p.material = optional_material(v);
    out_.prims.push_back(p);
  }

  void read_box(const JsonValue& v) {
    Primitive p = scene_json::read_box(r_, v);
    p.material = optional_material(v);
    out_.prims.push_back(p);
  }

  void read_triangle(const JsonValue& v) {
    Primitive p = scene_json::read_triangle(r_, v);
    p.material = optional_material(v);
    out_.prims.push_back(p);
  }

  // -- meshes and instances -------------------------------------------------------------------

  void read_meshes(const JsonValue& v) {
    for (const JsonValue& m : r_.items(v)) {
      r_.object(m, {"file", "name", "transform", "material", "fit", "place", "subdivide"});
      const JsonValue file = r_.require(m, "file");
      const fs::path rel = r_.string(file);
      const fs::path full = rel.is_absolute() || dir_.empty() ? rel : dir_ / rel;
      MeshEntry e;
      e.ptr = m.ptr;
      e.name = m.j.contains("name") ? r_.string(JsonReader::child(m, "name")) : m.ptr;
      for (const MeshEntry& other : meshes_)
        if (other.name == e.name)
          r_.fail(m.ptr + "/name", "a mesh named '" + e.name + "' already exists");
      auto cached = imported_.find(full.string());
      if (cached == imported_.end()) {
        try {
          const ImportConfig ic = import_config(config_);
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
      if (warned_.insert(full.string()).second) {  // once per mesh file
        out_.inputs.push_back(full.string());
        out_.inputs.insert(out_.inputs.end(), e.mesh->files_read.begin(), e.mesh->files_read.end());
        out_.warnings.insert(out_.warnings.end(), e.mesh->dropped.begin(), e.mesh->dropped.end());
        if (!e.mesh->cameras.empty() || !e.mesh->lights.empty())
          out_.warnings.push_back(full.string() +
                                  ": its cameras and lights are not used (a scene file's are)");
      }
      if (auto sub = r_.find(m, "subdivide")) {
        const auto levels = static_cast<int>(r_.integer(*sub, 0, 8));
        const double tris = static_cast<double>(e.mesh->triangles.size()) * std::pow(4.0, levels);
        if (tris > static_cast<double>(config_.max_triangles))
          r_.fail(sub->ptr, "subdividing " + fmt(static_cast<double>(e.mesh->triangles.size())) +
                                " triangles " + std::to_string(levels) + " times gives " +
                                fmt(tris) + ", more than the limit of " +
                                fmt(static_cast<double>(config_.max_triangles)));
        // Before subdividing: the finer triangles alone must fit the memory limit (the whole
        // scene is estimated once every mesh is read).
        const double bytes = tris * static_cast<double>(sizeof(Primitive));
        if (config_.max_bytes != 0 && bytes > static_cast<double>(config_.max_bytes))
          r_.fail(sub->ptr, "subdividing " + std::to_string(levels) + " times gives " + fmt(tris) +
                                " triangles, which alone take " + format_bytes(bytes) +
                                ", more than " + config_.limit_name);
        held_ += levels > 0 ? bytes : 0.0;  // a finer copy per entry, all held at once
        if (const std::string why = scene_json::beyond_limit(held_, config_); !why.empty())
          r_.fail(sub->ptr, "the meshes so far, subdivided, need at least " + why);
        if (levels > 0) {
          ImportedMesh fine = *e.mesh;
          fine.triangles = subdivide(e.mesh->triangles, levels);
          fine.uvs = subdivide(e.mesh->uvs, levels);
          fine.normals = subdivide(e.mesh->normals, levels);
          e.mesh = std::make_shared<const ImportedMesh>(std::move(fine));
        }
      }
      if (auto f = r_.find(m, "fit")) {
        // Uniform scale to the given largest extent, centred in x and z, resting on y = 0.
        const Bbox b = e.mesh->bounds;
        const double s = r_.positive(*f) / std::max(max_component(b.extent()), 1e-30f);
        e.model =
            Affine::scale({static_cast<float>(s), static_cast<float>(s), static_cast<float>(s)}) *
            Affine::translate({-b.center().x, -b.lo.y, -b.center().z});
      }
      if (auto t = r_.find(m, "transform")) e.model = scene_json::read_transform(r_, *t) * e.model;
      if (auto mat = r_.find(m, "material")) e.material = material_ref(*mat);
      const bool show = m.j.contains("place") ? r_.boolean(JsonReader::child(m, "place")) : true;
      meshes_.push_back(std::move(e));
      if (show) placed_.insert(meshes_.back().name);
    }
    for (const MeshEntry& e : meshes_) by_name_[e.name] = &e;
  }

  std::vector<Placement> read_instances(const JsonValue& v) {
    std::vector<Placement> out;
    for (const JsonValue& in : r_.items(v)) {
      r_.object(in, {"mesh", "transform", "material", "transforms", "grid", "scatter"});
      const JsonValue name = r_.require(in, "mesh");
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
      Placement p{it->second, {}, 0, std::nullopt, in.ptr};
      const Affine local = in.j.contains("transform")
                               ? scene_json::read_transform(r_, JsonReader::child(in, "transform"))
                               : Affine{};
      if (auto mat = r_.find(in, "material")) p.material = material_ref(*mat);
      const int kinds =
          in.j.contains("transforms") + in.j.contains("grid") + in.j.contains("scatter");
      if (kinds != 1) r_.fail(in.ptr, "expected exactly one of 'transforms', 'grid' or 'scatter'");
      const std::size_t triangles = it->second->mesh->triangles.size();
      if (auto t = r_.find(in, "transforms")) {
        std::vector<Affine> where;
        for (const JsonValue& e : r_.items(*t)) where.push_back(scene_json::read_transform(r_, e));
        p.count = where.size();
        p.where = [where, local] { return placed(where, local); };
      } else if (auto g = r_.find(in, "grid")) {
        const GridPattern grid = scene_json::read_grid(r_, *g);
        p.count = static_cast<std::size_t>(grid.nx * grid.nz);
        add_instances_check(static_cast<double>(p.count), triangles, g->ptr);
        p.where = [grid, local] { return placed(grid_placements(grid), local); };
      } else {
        const JsonValue sc = r_.require(in, "scatter");
        const ScatterPattern scatter = scene_json::read_scatter(r_, sc);
        p.count = static_cast<std::size_t>(scatter.count);
        add_instances_check(static_cast<double>(p.count), triangles, sc.ptr);
        p.where = [scatter, local] { return placed(scatter_placements(scatter), local); };
      }
      out.push_back(std::move(p));
    }
    return out;
  }

  static std::vector<Affine> placed(std::vector<Affine> where, const Affine& local) {
    for (Affine& a : where) a = a * local;
    return where;
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
    std::uint32_t base = 0;
    if (!material) {  // the mesh's own materials (and textures), appended once per mesh entry
      auto it = material_base_.find(&m);
      if (it == material_base_.end())
        it = material_base_.emplace(&m, scene_json::append_materials(out_, *m.mesh)).first;
      base = it->second;
    }
    scene_json::append_mesh(out_, *m.mesh, where * m.model, material, base);
  }

  JsonReader r_;
  fs::path dir_;
  SceneFileConfig config_;
  SceneDescription out_;
  std::map<std::string, std::uint32_t> material_index_;
  std::map<std::string, std::shared_ptr<const ImportedMesh>> imported_;
  std::vector<MeshEntry> meshes_;
  std::set<std::string> placed_;
  std::map<std::string, const MeshEntry*> by_name_;
  std::map<const MeshEntry*, std::uint32_t> material_base_;
  std::set<std::string> warned_;  ///< mesh files whose warnings are passed on
  std::map<std::pair<const MeshEntry*, std::int64_t>, std::uint32_t> instanced_;
  std::vector<Bbox> object_bounds_;  ///< per instanced mesh
  double held_ = 0;                  ///< bytes of the subdivided meshes' copies
};

}  // namespace

SceneDescription parse_scene_json(const std::string& text, const std::string& path,
                                  const SceneFileConfig& config) {
  const json doc = parse_json(text, path, {config.max_bytes, config.limit_name});
  return SceneParser(path, config).parse(doc);
}

SceneDescription read_scene_json(const std::string& path, const SceneFileConfig& config) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path + ": no such file");
  // Read, the text is held twice (the stream's buffer and its copy): refused before that.
  if (const std::string why = scene_json::beyond_limit(2.0 * fs::file_size(path, ec), config);
      !ec && !why.empty())
    throw InputError(path + ": reading the file needs " + why);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  in.peek();
  if (in && in.eof()) throw InputError(path + ": empty file (a scene file is a JSON object)");
  if (!in || !(text << in.rdbuf())) throw InputError(path + ": cannot read the file");
  const std::string bytes = text.str();
  if (const std::size_t bad = scene_json::first_invalid_utf8(bytes); bad != std::string::npos)
    throw InputError(path + ": not UTF-8 text (byte " + std::to_string(bad) +
                     "): a scene file is JSON");
  return parse_scene_json(bytes, path, config);
}

}  // namespace amalgam

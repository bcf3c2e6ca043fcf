#pragma once
/// \file The parts of a scene file that stand alone (io/scene_json.h reads the rest): a
/// material, the camera, a light, a sphere, box or triangle, a transform. Each checks its
/// value and throws InputError naming the JSON pointer of what is wrong (JsonReader).

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "amalgam/io/json_reader.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/math/transform.h"
#include "amalgam/scene/description.h"
#include "amalgam/scene/instance_patterns.h"

namespace amalgam {
struct SceneFileConfig;
}  // namespace amalgam

namespace amalgam::scene_json {

/// An instance grid, {"nx", "nz", "spacing", "origin"?}: at most 10^8 instances.
GridPattern read_grid(const JsonReader& r, const JsonValue& v);
/// An instance scatter, {"count", "radius", "seed"?, "centre"? (or "center"), "rotate"?}.
ScatterPattern read_scatter(const JsonReader& r, const JsonValue& v);

/// {"colour" (or "color"), "reflectance", "shininess"}, each optional.
Surface read_surface(const JsonReader& r, const JsonValue& v);

/// {"position", "look_at", "up", "vfov"}: up must not be parallel to the view direction.
Camera read_camera(const JsonReader& r, const JsonValue& v);

/// {"type": "point", "position", "intensity"} or {"type": "directional", "direction",
/// "intensity"} (the direction normalised), {"type": "spot", "position", "direction",
/// "intensity", "inner_deg"?, "outer_deg"?} (half-angles of glTF's falloff, default 0 and 45),
/// or {"type": "sky", "radiance"?, "map"?, "rotate_y_deg"?, "samples"?}: at most one sky; its
/// equirectangular map (.exr, .pfm or .png, scene/sky.h) is read relative to `sky.dir` into
/// `sky.map`, its path added to `sky.inputs`.
struct SkyInput {
  std::filesystem::path dir;
  std::shared_ptr<const SkyMap>* map = nullptr;
  std::vector<std::string>* inputs = nullptr;
  bool seen = false;
};
Light read_light(const JsonReader& r, const JsonValue& v, SkyInput& sky);

/// The geometry of {"centre" (or "center"), "radius", "material"}, {"min", "max", "material"}
/// or {"vertices", "material"} (a triangle of non-zero area); the material is left 0 for the
/// caller, which resolves it after these checks.
Primitive read_sphere(const JsonReader& r, const JsonValue& v);
Primitive read_box(const JsonReader& r, const JsonValue& v);
Primitive read_triangle(const JsonReader& r, const JsonValue& v);

/// {"matrix"} alone, or "scale" (a number or 3), then "rotate_x_deg", "rotate_y_deg",
/// "rotate_z_deg", then "translate", applied in that order.
AffineD read_transform(const JsonReader& r, const JsonValue& v);

/// A non-singular affine 4x4 matrix: 4 rows of 4 numbers or 16 numbers, row-major, last row
/// 0 0 0 1.
AffineD read_matrix(const JsonReader& r, const JsonValue& v);

/// Appends the triangles of `mesh`, mapped by `a`, to `out.prims`: with `material` for all,
/// or (none) with the mesh's own materials, which start at `out.materials[base]`. Keeps
/// `out.uvs` parallel to `out.prims` once any textured material is placed (zeros for
/// primitives without texture), and `out.normals` once any mesh with vertex normals is (mapped
/// by the inverse transpose of `a`).
void append_mesh(SceneDescription& out, const ImportedMesh& mesh, const AffineD& a,
                 std::optional<std::uint32_t> material, std::uint32_t base);

/// Cuts the side table `v` (texture coordinates, vertex normals) back to its first `before`
/// entries and returns the rest when `keep` (else nothing): the entries of the mesh just
/// appended, taken away for a mesh of its own.
template <class T>
std::vector<T> take_tail(std::vector<T>& v, std::size_t before, bool keep) {
  std::vector<T> tail;
  if (v.size() <= before) return tail;
  if (keep) tail.assign(v.begin() + static_cast<std::ptrdiff_t>(before), v.end());
  v.resize(before);
  return tail;
}

/// Appends the materials of `mesh` to `out.materials`, and its textures to `out.textures`
/// (the materials' texture indices shifted to match). Returns the index of the first.
std::uint32_t append_materials(SceneDescription& out, const ImportedMesh& mesh);

/// "<bytes>, more than <limit>" when `bytes` pass config.max_bytes, else "" (a limit of 0 is
/// none).
std::string beyond_limit(double bytes, const SceneFileConfig& config);

/// The offset of the first byte of `s` that is not part of well-formed UTF-8 (or a NUL), or
/// npos.
std::size_t first_invalid_utf8(const std::string& s);

}  // namespace amalgam::scene_json

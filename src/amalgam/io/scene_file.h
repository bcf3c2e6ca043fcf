#pragma once
/// \file Scene paths: scene files (`.json`, schema in the README) and bare meshes, which get a
/// default camera and lights.

#include <cstdint>
#include <string>
#include <vector>

#include "amalgam/scene/scene.h"
#include "amalgam/util/error.h"

namespace amalgam {

/// Settings for reading scene paths.
///
/// Instancing: a scene whose primitives, with every instance expanded, number at most
/// min(expand_limit, max_triangles) is expanded into one explicit hierarchy (one SAH over
/// everything traces fastest). A larger one keeps each `instances` entry whose mesh has at
/// least `instance_min_triangles` triangles as instances of a shared mesh hierarchy (the
/// two-level InstancedHierarchy); meshes smaller than that are always expanded.
struct SceneFileConfig {
  /// Expanded primitives (loose ones plus expanded instances) beyond this are an InputError.
  std::uint64_t max_triangles = 50'000'000;
  std::uint64_t expand_limit = 2'000'000;
  std::uint64_t instance_min_triangles = 64;
  /// Instances kept as instances beyond this are an InputError (about 250 bytes each).
  std::uint64_t max_instances = 20'000'000;
};

/// A scene as described, before any hierarchy is built.
struct SceneDescription {
  std::vector<Primitive> prims;    ///< world space, including expanded instances
  std::vector<Surface> materials;  ///< indexed by Primitive::material; never empty
  Environment env;
  /// Instanced meshes in object space (materials index `materials`), and their placements.
  /// Empty unless the scene is large enough to keep instances (see SceneFileConfig).
  std::vector<std::vector<Primitive>> meshes;
  std::vector<Instance> instances;
};

/// Reads a scene file. Relative mesh paths resolve against the file's folder. Throws
/// InputError naming the file and, for JSON syntax errors, the line and column, otherwise the
/// JSON pointer of the offending value ("scene.json: /lights/0/intensity: expected an array
/// of 3 numbers"): wrong types, missing keys, unknown keys and values out of range.
SceneDescription read_scene_json(const std::string& path, const SceneFileConfig& config = {});

/// Parses scene-file text; `path` names it in errors and anchors relative mesh paths.
SceneDescription parse_scene_json(const std::string& text, const std::string& path,
                                  const SceneFileConfig& config = {});

/// A bare mesh (see `import_mesh`) with `frame_camera` and `default_lights`.
SceneDescription mesh_scene(const std::string& path, const SceneFileConfig& config = {});

/// A camera that sees all of `bounds` from a 3/4 view (front-right, above; y is up).
Camera frame_camera(const Bbox& bounds, float vfov_deg = 40.0f);

/// A directional key light from above-left and a weaker point light at the camera (so that
/// no visible surface is black).
std::vector<Light> default_lights(const Bbox& bounds, const Camera& camera);

}  // namespace amalgam

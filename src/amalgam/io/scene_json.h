#pragma once
/// \file Scene files (`.json`, schema in docs/scene-format.md): the reader. What it produces is
/// a SceneDescription (scene/description.h); bare meshes are loaded by load/load_scene.h.

#include <cstdint>
#include <functional>
#include <string>

#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/scene/description.h"
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
  /// Keep every mesh placed (in `meshes` or by `instances`) as an instance, never expanded:
  /// each is then an object the volumetric renderer can render as cells (load/load_scene.h).
  bool objects = false;
  /// The cells baked for each object when `objects` is set (load/load_scene.h).
  VolumeConfig volume{};
  /// Bake the box amalgams' appearances (BakeConfig::appearances): only the scale-sensitive
  /// renderer renders them; false builds the hierarchy without (LoadedScene::amalgams).
  bool amalgams = true;
  /// Bytes the built scene may take (0: no limit), checked before any triangle is expanded or
  /// built, with MemoryModel (hierarchy/build/build.h); `limit_name` names the limit in the
  /// message (e.g. "--max-memory 100 MiB less the film").
  std::uint64_t max_bytes = 0;
  std::string limit_name = "the memory limit";
  /// Bytes the mesh import helper may allocate (ImportConfig::max_bytes; 0: no limit): a
  /// separate process, done before the scene is built, so held to the whole memory limit;
  /// `import_limit_name` names it.
  std::uint64_t import_max_bytes = 0;
  std::string import_limit_name = "the memory limit";
  /// Meshes without vertex normals get smooth ones (ImportConfig::smooth_normals).
  bool smooth_normals = false;
  /// Called as loading enters each phase ("reading scene.json", "building and baking
  /// scene.json"), e.g. for a status line or an out-of-memory message. Optional.
  std::function<void(const std::string&)> on_phase;
};

/// The settings import_mesh gets for the meshes of a scene loaded with `config`.
ImportConfig import_config(const SceneFileConfig& config);

/// "12.3 MiB": a byte count for messages.
std::string format_bytes(double bytes);

/// Throws InputError "<where>: the scene needs about X (estimated before building: ...), more
/// than <limit>" when `need` exceeds config.max_bytes (a limit of 0 is none).
void check_memory(const std::string& where, std::uint64_t need, const SceneFileConfig& config);

/// Reads a scene file. Relative mesh paths resolve against the file's folder. Throws
/// InputError naming the file and, for JSON syntax errors, the line and column, otherwise the
/// JSON pointer of the offending value ("scene.json: /lights/0/intensity: expected an array
/// of 3 numbers"): wrong types, missing keys, unknown keys and values out of range.
SceneDescription read_scene_json(const std::string& path, const SceneFileConfig& config = {});

/// Parses scene-file text; `path` names it in errors and anchors relative mesh paths.
SceneDescription parse_scene_json(const std::string& text, const std::string& path,
                                  const SceneFileConfig& config = {});

}  // namespace amalgam

#include "amalgam/load/load_scene.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>

#include "amalgam/io/mesh_import.h"
#include "amalgam/scene/coordinate_limit.h"
#include "amalgam/scene/framing.h"

namespace amalgam {

AnyHierarchy build_hierarchy(SceneDescription d, const BuildConfig& config) {
  if (d.instances.empty())
    return build_explicit(std::move(d.prims), std::move(d.materials), config);
  std::vector<ExplicitHierarchy> meshes;
  meshes.reserve(d.meshes.size() + 1);
  for (std::vector<Primitive>& m : d.meshes)
    meshes.push_back(build_explicit(std::move(m), d.materials, config));
  if (!d.prims.empty()) {
    Instance loose;  // identity: traced bit-exactly as in an explicit hierarchy
    loose.mesh = static_cast<std::uint32_t>(meshes.size());
    meshes.push_back(build_explicit(std::move(d.prims), d.materials, config));
    d.instances.push_back(loose);
  }
  return build_instanced(std::move(meshes), std::move(d.instances), config);
}

SceneDescription mesh_scene(const std::string& path, const SceneFileConfig& config) {
  ImportConfig ic;
  ic.max_triangles = config.max_triangles;
  ImportedMesh m = import_mesh(path, ic);
  check_extent(m.bounds, path);
  check_memory(path, MemoryModel::scene(m.triangles.size(), 0, 0), config);
  SceneDescription d;
  d.prims = std::move(m.triangles);
  d.materials = std::move(m.materials);
  d.env.camera = frame_camera(m.bounds);
  d.env.lights = default_lights(m.bounds, d.env.camera);
  return d;
}

LoadedScene load_scene_path(const std::string& path, const SceneFileConfig& config) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  if (config.on_phase) config.on_phase("reading " + path);
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  SceneDescription d = ext == ".json" ? read_scene_json(path, config) : mesh_scene(path, config);
  const auto t1 = Clock::now();
  Environment env = std::move(d.env);
  if (config.on_phase) config.on_phase("building and baking " + path);
  double bake_seconds = 0.0;
  BuildConfig build;
  build.bake_seconds = &bake_seconds;
  AnyHierarchy h = build_hierarchy(std::move(d), build);
  const auto t2 = Clock::now();
  LoadedScene s{path, std::move(h), std::move(env)};
  s.load_seconds = std::chrono::duration<double>(t1 - t0).count();
  s.bake_seconds = bake_seconds;
  s.build_seconds = std::max(0.0, std::chrono::duration<double>(t2 - t1).count() - bake_seconds);
  return s;
}

LoadedScene load_scene(const std::string& spec, const Params& params,
                       const SceneFileConfig& config) {
  if (spec.rfind("builtin:", 0) == 0) return load_builtin(spec, params);
  std::error_code ec;
  const bool exists = std::filesystem::exists(spec, ec);
  if (ec) throw InputError(spec + ": " + ec.message());  // e.g. a symbolic link loop
  if (!exists) throw InputError(spec + ": no such file");
  params.check_all_used();               // --set configures builtin scenes only
  return load_scene_path(spec, config);  // .json or mesh; times its own load and build
}

}  // namespace amalgam

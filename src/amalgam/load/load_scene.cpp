#include "amalgam/load/load_scene.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>

#include "amalgam/io/json_reader.h"
#include "amalgam/io/mesh_import.h"
#include "amalgam/render/option_rules.h"
#include "amalgam/scene/coordinate_limit.h"
#include "amalgam/scene/framing.h"
#include "amalgam/traverse/lit_ratio.h"
#include "amalgam/util/file_kind.h"
#include "amalgam/util/probe.h"

namespace amalgam {

AnyHierarchy build_hierarchy(SceneDescription d, const BuildConfig& config) {
  std::shared_ptr<const std::vector<Texture>> textures;
  if (!d.textures.empty())
    textures = std::make_shared<const std::vector<Texture>>(std::move(d.textures));
  if (d.instances.empty())
    return build_explicit(std::move(d.prims), std::move(d.materials), config, std::move(d.uvs),
                          std::move(textures), std::move(d.normals));
  std::vector<ExplicitHierarchy> meshes;
  meshes.reserve(d.meshes.size() + 1);
  for (std::size_t i = 0; i < d.meshes.size(); ++i)
    meshes.push_back(build_explicit(
        std::move(d.meshes[i]), d.materials, config,
        i < d.mesh_uvs.size() ? std::move(d.mesh_uvs[i]) : std::vector<TexCoords>{}, textures,
        i < d.mesh_normals.size() ? std::move(d.mesh_normals[i]) : std::vector<VertexNormals>{}));
  if (!d.prims.empty()) {
    Instance loose;  // identity: traced bit-exactly as in an explicit hierarchy
    loose.mesh = static_cast<std::uint32_t>(meshes.size());
    meshes.push_back(build_explicit(std::move(d.prims), d.materials, config, std::move(d.uvs),
                                    textures, std::move(d.normals)));
    d.instances.push_back(loose);
  }
  return build_instanced(std::move(meshes), std::move(d.instances), config);
}

SceneDescription mesh_scene(const std::string& path, const SceneFileConfig& config) {
  ImportedMesh m = import_mesh(path, import_config(config));
  check_extent(m.bounds, path);
  std::uint64_t texture_bytes = (m.uvs.size() * sizeof(TexCoords) +  // as read, and built
                                 m.normals.size() * sizeof(VertexNormals)) *
                                2;
  for (const Texture& t : m.textures) texture_bytes += t.texels.size();
  check_memory(path, MemoryModel::scene(m.triangles.size(), 0, 0) + texture_bytes, config);
  SceneDescription d;
  if (config.objects) {  // one object, placed once as it is
    d.meshes.push_back(std::move(m.triangles));
    d.mesh_uvs.push_back(std::move(m.uvs));
    d.mesh_normals.push_back(std::move(m.normals));
    d.instances.push_back(Instance{});
  } else {
    d.prims = std::move(m.triangles);
    d.uvs = std::move(m.uvs);
    d.normals = std::move(m.normals);
  }
  d.materials = std::move(m.materials);
  d.textures = std::move(m.textures);
  d.cameras = std::move(m.cameras);
  d.warnings = std::move(m.dropped);
  d.inputs = std::move(m.files_read);
  d.env.camera = d.cameras.empty() ? frame_camera(m.bounds) : d.cameras.front().camera;
  d.framed_camera = d.cameras.empty();
  d.default_lights = m.lights.empty();
  d.env.lights = d.default_lights ? default_lights(m.bounds, d.env.camera) : std::move(m.lights);
  return d;
}

double resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  double pages = 0.0, resident = 0.0;
  if (!(statm >> pages >> resident)) return 0.0;
  return resident * static_cast<double>(sysconf(_SC_PAGE_SIZE));
}

namespace {

/// Reads a scene with `read` and builds and bakes it: the work of load_scene_path, for a file
/// (`path` its name, and the first of the inputs) or for text (`path` names it in messages).
LoadedScene load_read(const std::string& path, bool is_file, const SceneFileConfig& config,
                      const std::function<SceneDescription()>& read) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  if (config.on_phase) config.on_phase("reading " + path);
  SceneDescription d = read();
  const auto t1 = Clock::now();
  Environment env = std::move(d.env);
  std::vector<NamedCamera> cameras = std::move(d.cameras);
  std::vector<std::string> warnings = std::move(d.warnings);
  std::vector<std::string> inputs;
  if (is_file) inputs.push_back(path);
  inputs.insert(inputs.end(), d.inputs.begin(), d.inputs.end());
  const bool defaults = d.default_lights, framed = d.framed_camera;
  if (config.on_phase) config.on_phase("building and baking " + path);
  double bake_seconds = 0.0;
  BuildConfig build;
  build.bake_seconds = &bake_seconds;
  build.bake.appearances = config.amalgams;
  const std::size_t objects = d.meshes.size();  // the loose primitives come after them
  AnyHierarchy h = build_hierarchy(std::move(d), build);
  const auto t2 = Clock::now();
  LoadedScene s{path, std::move(h), std::move(env)};
  if (config.objects) {
    if (config.on_phase) config.on_phase("baking the volumetric amalgams of " + path);
    const auto* ih = std::get_if<InstancedHierarchy>(&s.hierarchy);
    VolumeConfig volume = config.volume;
    if (light_probe().lines > 0) volume.lines = light_probe().lines;
    // Held to the limit as it goes: what the process holds now (the scene as built), plus
    // every block the bake is about to allocate, less what it has freed.
    struct Limit final : BakeBudget {
      const std::string& path;
      const SceneFileConfig& config;
      double used = resident_bytes();
      Limit(const std::string& p, const SceneFileConfig& c) : path(p), config(c) {}
      void charge(double bytes) override {
        used += bytes;
        if (bytes > 0.0 && used > static_cast<double>(config.max_bytes))
          throw InputError(path + ": baking its volumetric amalgams needs more than " +
                           config.limit_name + " (" + format_bytes(used) +
                           " with the scene as built, counted before allocating)");
      }
    } limit(path, config);
    if (config.max_bytes != 0) volume.budget = &limit;
    if (ih) {
      VolumeSet v = bake_volumes(*ih, objects, volume);
      // The seen-and-lit ratios serve the light probe's lit-share model alone.
      if (!light_probe().march_self)
        for (std::size_t m = 0; m < v.grids.size(); ++m)
          if (v.grids[m].cells() > 0 && !v.grids[m].oriented)
            bake_lit_ratio(ih->meshes[m], v.grids[m]);
      s.volumes = std::make_shared<const VolumeSet>(std::move(v));
    }
    s.volume_seconds = std::chrono::duration<double>(Clock::now() - t2).count();
  }
  s.cameras = std::move(cameras);
  s.warnings = std::move(warnings);
  s.inputs = std::move(inputs);
  s.default_lights = defaults;
  s.framed_camera = framed;
  s.load_seconds = std::chrono::duration<double>(t1 - t0).count();
  s.bake_seconds = bake_seconds;
  s.amalgams = config.amalgams;
  s.build_seconds = std::max(0.0, std::chrono::duration<double>(t2 - t1).count() - bake_seconds);
  return s;
}

}  // namespace

LoadedScene load_scene_path(const std::string& path, const SceneFileConfig& config) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return load_read(path, true, config, [&] {
    return ext == ".json" ? read_scene_json(path, config) : mesh_scene(path, config);
  });
}

LoadedScene load_scene_text(const std::string& text, const std::string& name,
                            const SceneFileConfig& config) {
  return load_read(name, false, config, [&] { return parse_scene_json(text, name, config); });
}

namespace {

Bbox scene_bounds(const LoadedScene& scene) {
  return std::visit([](const auto& h) { return h.bounds(h.root()); }, scene.hierarchy);
}

}  // namespace

Environment chosen_view(const LoadedScene& scene, const CameraChoice& choice) {
  const auto name = [&](std::string_view flag, const std::string& value = {}) {
    return option_text(flag, choice.spelling, value);
  };
  Camera c = scene.env.camera;
  if (!choice.camera.empty()) {
    const std::string& want = choice.camera;
    std::string list;
    const NamedCamera* found = nullptr;
    for (std::size_t i = 0; i < scene.cameras.size(); ++i) {
      if (scene.cameras[i].name == want && !found) found = &scene.cameras[i];
      list +=
          (i ? ", " : "") + std::to_string(i) + " '" + one_line(scene.cameras[i].name, 60) + "'";
    }
    if (!found && !want.empty() && want.size() < 10 &&
        want.find_first_not_of("0123456789") == std::string::npos &&
        std::stoul(want) < scene.cameras.size())
      found = &scene.cameras[std::stoul(want)];
    if (!found)
      throw InputError(name("--camera", one_line(want, 60)) + ": " +
                       (scene.cameras.empty()
                            ? scene.name + " defines no cameras (" + name("--eye") + ", " +
                                  name("--look-at") + ", " + name("--up") + " and " +
                                  name("--fov") + " set the view of any scene)"
                            : "no such camera in " + scene.name + " (cameras: " + list + ")"));
    c = found->camera;
  }
  if (choice.eye) c.position = *choice.eye;
  if (choice.look_at) c.look_at = *choice.look_at;
  if (choice.up) c.up = *choice.up;
  if (choice.fov_deg) {
    if (!(*choice.fov_deg > 0.0f && *choice.fov_deg < 180.0f))
      throw InputError(name("--fov", JsonReader::format(*choice.fov_deg)) +
                       ": expected a vertical field of view in degrees, > 0 and < 180");
    c.vfov_deg = *choice.fov_deg;
  }
  // A default view given only an up direction: the same 3/4 view about that up (a file whose
  // up axis is z, such as an STL, is framed upright by --up 0,0,1, not rolled on its side).
  if (scene.framed_camera && choice.camera.empty() && choice.up && !choice.eye && !choice.look_at &&
      length(*choice.up) > 0.0f)
    c = frame_camera(scene_bounds(scene), c.vfov_deg, *choice.up);
  const Vec3 dir = c.look_at - c.position;
  if (!(length(dir) > 0.0f))
    throw InputError(name("--eye") + "/" + name("--look-at") +
                     ": the eye is at the look-at point (no view direction)");
  if (!(length(cross(normalize(dir), c.up)) > 1e-6f * length(c.up)))
    throw InputError(name("--up") + ": the up vector is zero or along the view direction");
  const bool changed = c.position != scene.env.camera.position ||
                       c.look_at != scene.env.camera.look_at || c.up != scene.env.camera.up ||
                       c.vfov_deg != scene.env.camera.vfov_deg;
  Environment env = scene.env;
  if (choice.light_samples) {
    if (!(*choice.light_samples >= 1 && *choice.light_samples <= 4096))
      throw InputError(name("--light-samples", std::to_string(*choice.light_samples)) +
                       ": expected an integer in [1, 4096]");
    for (Light& l : env.lights)
      if (l.sized()) l.samples = *choice.light_samples;
  }
  if (!changed) return env;
  env.camera = c;
  if (scene.default_lights)  // (unsized: light_samples does not apply to them)
    env.lights = default_lights(scene_bounds(scene), c);
  return env;
}

void choose_camera(LoadedScene& scene, const CameraChoice& choice) {
  scene.env = chosen_view(scene, choice);
}

LoadedScene load_scene(const std::string& spec, const Params& params,
                       const SceneFileConfig& config) {
  if (spec.rfind("builtin:", 0) == 0) return load_builtin(spec, params);
  std::error_code ec;
  const bool exists = std::filesystem::exists(spec, ec);
  if (ec) throw InputError(spec + ": " + ec.message());  // e.g. a symbolic link loop
  if (!exists) throw InputError(spec + ": no such file");
  // Found with stat, before anything opens it: a FIFO would block the open, a device never end.
  if (const std::string why = not_a_regular_file(spec); !why.empty())
    throw InputError(spec + ": " + why + " (a scene is a .json or mesh file or builtin:NAME)");
  params.check_all_used();               // --set configures builtin scenes only
  return load_scene_path(spec, config);  // .json or mesh; times its own load and build
}

}  // namespace amalgam

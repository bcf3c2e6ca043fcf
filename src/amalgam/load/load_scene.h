#pragma once
/// \file The front end's scene loader: a SCENE argument (`builtin:NAME` + --set parameters, a
/// `.json` scene file, or a mesh path) -> a built, baked hierarchy with its environment. The
/// top layer of the library: it decides how a described scene is built (explicit or
/// instanced) and composes the readers of io/ with the builders of hierarchy/.

#include <optional>
#include <string>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/io/scene_json.h"
#include "amalgam/render/loaded_scene.h"
#include "amalgam/render/options.h"

namespace amalgam {

/// The hierarchy of a described scene: explicit when it has no instances, else instanced,
/// with the loose primitives as one more mesh placed once, untransformed.
AnyHierarchy build_hierarchy(SceneDescription d, const BuildConfig& config = {});

/// A bare mesh (see `import_mesh`, io/mesh_import.h) as a scene: its triangles and materials,
/// with `frame_camera` and `default_lights` (scene/framing.h). Only `config.max_triangles`
/// applies. Throws InputError naming the file.
SceneDescription mesh_scene(const std::string& path, const SceneFileConfig& config = {});

/// Loads a scene path: `.json` (any case) as a scene file, anything else as a mesh; builds
/// and bakes its hierarchy (build_hierarchy). Sets load_seconds (reading), build_seconds and
/// bake_seconds (the bake apart from the rest of the build).
LoadedScene load_scene_path(const std::string& path, const SceneFileConfig& config = {});

/// Loads scene-file text (the JSON of a `.json` scene; io/scene_json.h) as load_scene_path
/// loads a file: `name` names it in messages (e.g. "the dict"). Relative mesh paths resolve
/// against the current directory, unless `name` has a folder. Its inputs are the files it reads.
LoadedScene load_scene_text(const std::string& text, const std::string& name,
                            const SceneFileConfig& config = {});

/// The view asked for on the command line: one of the scene file's cameras (glTF) by name or
/// index, then any of its fields replaced; and the shadow rays per sized light.
struct CameraChoice {
  std::string camera;  ///< a name, else a 0-based index, of LoadedScene::cameras; empty: default
  std::optional<Vec3> eye, look_at, up;
  std::optional<float> fov_deg;        ///< vertical field of view
  std::optional<int> light_samples{};  ///< replaces Light::samples of every sized light
  /// How error messages name the view options: the CLI's flags (`--up`) or Python's keywords
  /// (`up=`).
  OptionSpelling spelling = OptionSpelling::kFlags;
};

/// Applies `choice` to `scene.env.camera`; default lights (LoadedScene::default_lights) follow
/// the camera. Call before content_hash is taken, so that a checkpoint records the view.
/// Throws InputError: `--camera X` naming no camera of the scene (the message lists those it
/// has), a field of view outside (0, 180) degrees, the eye at the look-at point, or an up
/// vector along the view direction.
void choose_camera(LoadedScene& scene, const CameraChoice& choice);

/// The environment `choose_camera` would give the scene, leaving the scene as it is: another
/// view of one built, baked scene (render's `env` overload, render/render.h). Same errors.
Environment chosen_view(const LoadedScene& scene, const CameraChoice& choice);

/// The bytes this process holds in memory now (its resident set, /proc/self/statm); 0 where
/// unknown. What the loader charges a scene's bake against.
double resident_bytes();

/// Loads `spec`. Throws InputError (one line naming the scene and the problem) on bad input,
/// including a scene file or mesh that would take more than `config.max_bytes` (checked before
/// building; the builtin scenes are implicit and take no memory to speak of).
LoadedScene load_scene(const std::string& spec, const Params& params,
                       const SceneFileConfig& config = {});

}  // namespace amalgam

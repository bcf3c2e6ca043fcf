#pragma once
/// \file What `render` and `trace` take: a built, baked hierarchy of any form with its
/// environment. Made by the front end's loader (load/load_scene.h) or, for the builtin scenes
/// alone, by `load_builtin`.

#include <cstdint>
#include <memory>
#include <string>
#include <variant>

#include "amalgam/builtin/catalog.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"
#include "amalgam/hierarchy/volume/volume_set.h"
#include "amalgam/scene/description.h"

namespace amalgam {

/// Every hierarchy a scene can load into; render.cpp's dispatch instantiates the traversal
/// for each alternative and every policy combination.
using AnyHierarchy =
    std::variant<ExplicitHierarchy, TubeHierarchy, PrismsHierarchy, InstancedHierarchy>;

struct LoadedScene {
  std::string name;
  AnyHierarchy hierarchy;
  Environment env;
  double load_seconds = 0.0;   ///< reading the scene (or making a builtin's)
  double build_seconds = 0.0;  ///< building the hierarchy, the bake not included
  double bake_seconds = 0.0;   ///< baking the amalgams' appearances
  /// Whether the amalgams have their appearances (false: loaded with SceneFileConfig::amalgams
  /// off, for a renderer that renders none; the scale-sensitive renderer refuses it).
  bool amalgams = true;
  /// The volumetric amalgams of the scene's objects (a scene loaded with
  /// SceneFileConfig::objects: instanced hierarchy, every mesh an instance), else null.
  std::shared_ptr<const VolumeSet> volumes{};
  double volume_seconds = 0.0;  ///< baking them
  /// For builtin scenes: the parameters as applied (Params::applied); part of content_hash.
  std::string params{};
  /// The cameras the scene file defines (glTF), env.camera being the chosen one.
  std::vector<NamedCamera> cameras{};
  /// env.lights are the default lights for env.camera (they follow a camera chosen later).
  bool default_lights = false;
  /// env.camera frames the scene by default (SceneDescription::framed_camera).
  bool framed_camera = false;
  /// What the scene file holds that is not rendered, one line each (the CLI prints them).
  std::vector<std::string> warnings{};
  /// The files read (the scene file, its meshes and their textures; none for a builtin): what
  /// an output must never replace.
  std::vector<std::string> inputs{};

  HierarchyInfo info() const {
    return std::visit([](const auto& h) { return h.info(); }, hierarchy);
  }
};

/// A 64-bit hash of everything the scene renders: its lights, camera and background, and its
/// geometry (for stored hierarchies every primitive, material and instance transform, field
/// by field; for the builtin scenes their name and parameters as applied, which determine
/// them; textures and texture coordinates when there are any). Two scenes with the same hash render
/// the same image (up to hash collisions): what a checkpoint is resumed against.
std::uint64_t content_hash(const LoadedScene& scene);

/// A builtin scene (builtin/catalog.h) ready to render; sets load_seconds.
LoadedScene load_builtin(const std::string& spec, const Params& params);

}  // namespace amalgam

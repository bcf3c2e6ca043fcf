#pragma once
/// \file A scene as described (by a scene file, a mesh, or code), before any hierarchy is built.

#include <vector>

#include "amalgam/scene/scene.h"

namespace amalgam {

/// A scene as described, before any hierarchy is built.
struct SceneDescription {
  std::vector<Primitive> prims;    ///< world space, including expanded instances
  std::vector<Surface> materials;  ///< indexed by Primitive::material; never empty
  Environment env;
  /// Instanced meshes in object space (materials index `materials`), and their placements.
  /// Empty unless the scene is large enough to keep instances (see SceneFileConfig,
  /// io/scene_json.h).
  std::vector<std::vector<Primitive>> meshes;
  std::vector<Instance> instances;
};

}  // namespace amalgam

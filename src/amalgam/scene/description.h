#pragma once
/// \file A scene as described (by a scene file, a mesh, or code), before any hierarchy is built.

#include <string>
#include <vector>

#include "amalgam/scene/scene.h"
#include "amalgam/scene/texture.h"
#include "amalgam/scene/vertex_normals.h"

namespace amalgam {

/// A camera a scene file names (glTF: the name of the camera's node).
struct NamedCamera {
  std::string name;
  Camera camera;
};

/// A scene as described, before any hierarchy is built.
struct SceneDescription {
  std::vector<Primitive> prims;    ///< world space, including expanded instances
  std::vector<Surface> materials;  ///< indexed by Primitive::material; never empty
  /// Texture coordinates per primitive of `prims` (same order) when a material has a texture,
  /// else empty; `Surface::texture` indexes `textures`.
  std::vector<TexCoords> uvs;
  /// Vertex normals per primitive of `prims` (same order) when a mesh placed has them, else
  /// empty (zero for primitives without).
  std::vector<VertexNormals> normals;
  std::vector<Texture> textures;
  /// The cameras the file defines (env.camera is the first, or a default view when empty).
  std::vector<NamedCamera> cameras;
  /// True when env.lights are default_lights (scene/framing.h) for env.camera: a camera chosen
  /// later moves them with it.
  bool default_lights = false;
  /// True when env.camera is frame_camera's (the file gives no camera): `--up` alone frames
  /// the scene again about that up direction.
  bool framed_camera = false;
  /// What the file holds that is not rendered, one line each, for the user to see.
  std::vector<std::string> warnings;
  /// The files read besides the scene file itself (meshes, their textures): inputs that an
  /// output must never replace.
  std::vector<std::string> inputs;
  Environment env;
  /// Instanced meshes in object space (materials index `materials`), and their placements.
  /// Empty unless the scene is large enough to keep instances (see SceneFileConfig,
  /// io/scene_json.h).
  std::vector<std::vector<Primitive>> meshes;
  std::vector<std::vector<TexCoords>> mesh_uvs;          ///< per mesh: as `uvs`, for its primitives
  std::vector<std::vector<VertexNormals>> mesh_normals;  ///< per mesh: as `normals`
  std::vector<Instance> instances;
};

}  // namespace amalgam

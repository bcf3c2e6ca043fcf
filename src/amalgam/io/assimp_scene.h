#pragma once
/// \file What the mesh import helper reads from an Assimp scene beyond its triangles:
/// materials with their decoded base-colour textures, glTF cameras, point and directional
/// lights, and one line for each kind of content that is not rendered (docs/import.md). Runs
/// only in the amalgam-import helper (io/assimp_import.h).

#include <string>
#include <vector>

#include "amalgam/io/mesh_import.h"

struct aiScene;

namespace amalgam::assimp_scene {

/// The cameras and lights of `scene` in world space, placed by their nodes. Call before the
/// node transforms are baked into the vertices (aiProcess_PreTransformVertices drops the
/// nodes). `gltf`: the file is glTF, whose importer stores its cameras in its own way. What
/// cannot be rendered is a line of `out.dropped`.
void read_cameras_lights(const aiScene& scene, const std::string& path, bool gltf,
                         ImportedMesh& out);

/// A line of `out.dropped` for each kind of content `scene` holds that amalgam does not
/// render: material features (emission, transmission, transparency, ...), textures other
/// than the base colour, vertex colours, skins, morph targets, animations.
void note_unrendered(const aiScene& scene, const std::string& path, ImportedMesh& out);

/// Sets `out.materials` (one per material of `scene`, never empty) and `out.textures`: each
/// material's base colour factor (glTF) or diffuse colour, and its base-colour (or diffuse)
/// texture decoded. Returns each material's texture-coordinate channel. A texture that cannot
/// be read is a line of `out.dropped`, and its material keeps its colour.
std::vector<unsigned> read_materials(const aiScene& scene, const std::string& path,
                                     ImportedMesh& out);

}  // namespace amalgam::assimp_scene

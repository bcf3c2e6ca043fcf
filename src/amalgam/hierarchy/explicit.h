#pragma once
/// \file The explicit amalgam hierarchy: flat arrays of nodes, appearances and primitives.
/// Node 0 is the root. A node's children are either a contiguous range of nodes or a
/// contiguous range of primitives.

#include <cstdint>
#include <memory>
#include <vector>

#include "amalgam/hierarchy/bake/normals.h"
#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/hierarchy/primitives.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/scene/texture.h"
#include "amalgam/scene/vertex_normals.h"

namespace amalgam {

struct ExplicitNode {
  Bbox bounds;
  std::uint32_t first = 0;  ///< index of the first child (node or primitive)
  std::uint16_t count = 0;  ///< number of children
  bool leaf = false;        ///< children are primitives
};

class ExplicitHierarchy {
 public:
  std::vector<ExplicitNode> nodes;
  std::vector<Appearance> appearances;  ///< one per node
  /// In leaf order; packed by `build_wide` (hierarchy/primitives.h).
  PrimitiveStore prims;
  std::vector<Surface> materials;  ///< indexed by Primitive::material
  /// Texture coordinates per primitive (same order as `prims`) when a material is textured,
  /// else empty: a side table, so untextured scenes pay nothing.
  std::vector<TexCoords> uvs;
  /// Vertex normals per primitive (same order as `prims`) when the mesh has any, else empty:
  /// a side table like `uvs`.
  std::vector<VertexNormals> vertex_normals;
  /// The textures `Surface::texture` indexes (shared by the meshes of an instanced scene).
  std::shared_ptr<const std::vector<Texture>> textures;
  int levels = 0;
  /// The normal tensor (trace 1) of the root's contents, from the bake: lets an instance
  /// level above compose normals across the instance boundary.
  NormalTensor root_normals;
  /// SoA child boxes for the SIMD traversal (wide.h); built by `build_wide` at the end of `bake`
  /// (hierarchy/bake/bake.h).
  WideNodes wide;

  NodeId root() const { return 0; }
  Bbox bounds(NodeId id) const { return nodes[id].bounds; }
  Appearance appearance(NodeId id) const { return appearances[id]; }
  template <class F>
  void for_each_child(NodeId id, F&& f) const {
    const ExplicitNode& n = nodes[id];
    for (std::uint32_t i = 0; i < n.count; ++i)
      if (!f(Child{n.first + i, n.leaf})) return;
  }
  std::optional<SurfaceHit> intersect(PrimId id, const Ray& ray) const {
    return amalgam::intersect(prims[id], ray);
  }
  Surface surface(PrimId id) const { return materials[prims.material(id)]; }
  /// The surface at hit `s` on primitive `id`: its texture, if any, sampled at the
  /// coordinates interpolated with the hit's barycentrics, times the material's colour.
  Surface surface_at(PrimId id, const SurfaceHit& s) const {
    Surface m = materials[prims.material(id)];
    if (m.texture >= 0) {
      if (!uvs.empty() && textures && static_cast<std::size_t>(m.texture) < textures->size()) {
        float u, v;
        interpolate(uvs[id], s.b1, s.b2, u, v);
        m.colour = m.colour * sample((*textures)[static_cast<std::size_t>(m.texture)], u, v);
      }
      m.texture = -1;
    }
    return m;
  }
  /// The normal to shade hit `s` on primitive `id` with: its vertex normals interpolated with
  /// the hit's barycentrics where it has them, else the geometric normal `s.normal`. Either
  /// way unit length; its side is the caller's to choose.
  Vec3 shading_normal(PrimId id, const SurfaceHit& s) const {
    if (vertex_normals.empty()) return s.normal;
    const Vec3 n = interpolate(vertex_normals[id], s.b1, s.b2);
    return n == Vec3{} ? s.normal : n;
  }
  /// The colour an amalgam bakes for primitive `id`: its material's colour, times, when
  /// textured, the texture's mean over the triangle's texture coordinates (or over all its
  /// texels when the primitive has no coordinates).
  Vec3 bake_colour(PrimId id) const {
    const Surface& m = materials[prims.material(id)];
    if (m.texture < 0 || !textures || static_cast<std::size_t>(m.texture) >= textures->size())
      return m.colour;
    const Texture& t = (*textures)[static_cast<std::size_t>(m.texture)];
    return m.colour * (uvs.empty() ? t.mean : mean_over_triangle(t, uvs[id]));
  }
  /// The SoA child boxes when they match `nodes` and the primitives are packed (else null: the
  /// traversal's generic source).
  const WideNodes* wide_nodes() const {
    return !nodes.empty() && wide.headers.size() == nodes.size() && prims.packed() ? &wide
                                                                                   : nullptr;
  }
  /// Whether the SIMD form is missing or stale: never built, or the nodes or primitives
  /// changed since `build_wide` (an edit unpacks the store). Not when `build_wide` left it out by
  /// design (too many records to address). A traversal refuses such a hierarchy (traverse.h)
  /// rather than walk it silently without its SIMD form.
  bool wide_stale() const {
    return !nodes.empty() && !wide_nodes() && wide.unaddressable_nodes != nodes.size();
  }
  HierarchyInfo info() const {
    return {static_cast<double>(prims.size()), static_cast<double>(nodes.size()), levels};
  }
};

}  // namespace amalgam

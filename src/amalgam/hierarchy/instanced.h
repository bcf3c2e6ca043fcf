#pragma once
/// \file The two-level instanced hierarchy: a top-level SAH tree over instances, each an
/// affine transform of a mesh that has its own explicit hierarchy (shared by all its
/// instances), so memory grows with the distinct meshes plus O(1) per instance.
///
/// Ids: the high 32 bits hold 0 for a top-level node, or instance index + 1; the low 32 bits
/// the node (or primitive) index within the top tree or the instance's mesh hierarchy.
/// Levels run on through the instance boundary: an instance's root sits one level below the
/// top-level leaf that holds it, so `Traversal` counts tests on the right levels unchanged.
///
/// Bounds of a node inside an instance are the world box of its transformed box. Primitive
/// tests transform the ray into object space without normalising the direction, so the hit
/// parameter t is the same in both spaces; each test is one intersection test, as for the
/// explicit form. Appearances inside an instance are the mesh's, with the opacity rescaled
/// from the transformed box to its world box (Cauchy: a line crossing the world box crosses
/// the transformed box with probability area ratio) and the normal transformed; top-level
/// amalgams are baked from the instance roots (`bake_from_children`).

#include <cstdint>
#include <vector>

#include "amalgam/hierarchy/explicit.h"

namespace amalgam {

class InstancedHierarchy {
 public:
  /// Precomputed per instance.
  struct InstanceData {
    Transform to_world, to_object;
    Vec3 normal_rows[3];  ///< rows of M^-T: world normal = (rows . n), then normalised
    Vec3 abs_rows[3];     ///< rows of |M|, for world boxes
    float face_area[3];   ///< |M e_y x M e_z|, |M e_z x M e_x|, |M e_x x M e_y|
    Bbox world_bounds;    ///< of the mesh root
    std::uint32_t mesh = 0;
    bool identity = false;  ///< then rays and boxes are used untransformed (bit-exact)
  };

  std::vector<ExplicitNode> top_nodes;  ///< leaves' children: top_items[first .. +count)
  std::vector<Appearance> top_appearances;
  std::vector<std::uint32_t> top_items;  ///< instance indices
  std::vector<ExplicitHierarchy> meshes;
  std::vector<InstanceData> instances;
  int levels = 0;

  static constexpr std::uint64_t id(std::uint64_t instance_plus_one, std::uint32_t local) {
    return (instance_plus_one << 32) | local;
  }
  static constexpr std::uint32_t local(std::uint64_t id) {
    return static_cast<std::uint32_t>(id & 0xffffffffu);
  }
  static constexpr std::uint64_t slot(std::uint64_t id) { return id >> 32; }  ///< 0: top

  NodeId root() const { return 0; }
  Bbox bounds(NodeId n) const {
    const std::uint64_t s = slot(n);
    if (s == 0) return top_nodes[n].bounds;
    const InstanceData& in = instances[s - 1];
    return world_box(in, meshes[in.mesh].nodes[local(n)].bounds);
  }
  Appearance appearance(NodeId n) const;
  template <class F>
  void for_each_child(NodeId n, F&& f) const {
    const std::uint64_t s = slot(n);
    if (s == 0) {
      const ExplicitNode& t = top_nodes[n];
      for (std::uint32_t i = 0; i < t.count; ++i) {
        const std::uint64_t c = t.leaf ? id(top_items[t.first + i] + 1ull, 0) : t.first + i;
        if (!f(Child{c, false})) return;
      }
      return;
    }
    const ExplicitNode& e = meshes[instances[s - 1].mesh].nodes[local(n)];
    for (std::uint32_t i = 0; i < e.count; ++i)
      if (!f(Child{id(s, e.first + i), e.leaf})) return;
  }
  std::optional<SurfaceHit> intersect(PrimId p, const Ray& ray) const;
  Surface surface(PrimId p) const {
    const InstanceData& in = instances[slot(p) - 1];
    return meshes[in.mesh].surface(local(p));
  }
  HierarchyInfo info() const;
  /// The primitive in world space (for flatten() and tests).
  Primitive primitive(PrimId p) const;

  /// The precomputed data of placement `inst` of `mesh` (built and baked).
  static InstanceData make_instance(const Instance& inst, const ExplicitHierarchy& mesh);

  /// The world box of the transformed box `b` of instance `in` (conservative by a few ulps).
  static Bbox world_box(const InstanceData& in, const Bbox& b);
};

}  // namespace amalgam

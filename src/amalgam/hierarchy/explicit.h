#pragma once
/// \file The explicit amalgam hierarchy: flat arrays of nodes, appearances and primitives.
/// Node 0 is the root. A node's children are either a contiguous range of nodes or a
/// contiguous range of primitives.

#include <cstdint>
#include <vector>

#include "amalgam/hierarchy/hierarchy.h"

namespace amalgam {

struct ExplicitNode {
  Bbox bounds;
  std::uint32_t first = 0;   ///< index of the first child (node or primitive)
  std::uint16_t count = 0;   ///< number of children
  bool leaf = false;         ///< children are primitives
};

class ExplicitHierarchy {
 public:
  std::vector<ExplicitNode> nodes;
  std::vector<Appearance> appearances;  ///< one per node
  std::vector<Primitive> prims;
  std::vector<Surface> materials;       ///< indexed by Primitive::material
  int levels = 0;

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
  Surface surface(PrimId id) const { return materials[prims[id].material]; }
  HierarchyInfo info() const {
    return {static_cast<double>(prims.size()), static_cast<double>(nodes.size()), levels};
  }
};

/// Build settings for `build_explicit`.
struct BuildConfig {
  int arity = 4;      ///< children per interior node (2..kMaxChildren)
  int leaf_size = 4;  ///< at most this many primitives in a leaf
};

/// Builds a hierarchy over `prims` by recursive median splits along the longest centroid
/// axis, then bakes every amalgam's appearance bottom-up (see `bake`). Empty input gives a
/// single empty leaf.
ExplicitHierarchy build_explicit(std::vector<Primitive> prims, std::vector<Surface> materials,
                                 const BuildConfig& config = {});

/// Bakes appearances bottom-up. Colour: children's colours weighted by their mean projected
/// area times opacity. Opacity: the chance that a ray crossing the node hits something,
/// estimated with independent occluders: 1 - prod_i (1 - a_i A_i / A_node), A the mean
/// projected area (surface area / 4 for a box).
void bake(ExplicitHierarchy& h);

/// Copies a hierarchy that can list its primitives (`src.primitive(PrimId)`) into explicit
/// form (breadth-first node order), keeping its appearances: the same scene, for
/// differential tests of the two forms. Only for small hierarchies.
template <Hierarchy H>
ExplicitHierarchy flatten(const H& src, int max_levels);

}  // namespace amalgam

#include "amalgam/hierarchy/flatten.inl"

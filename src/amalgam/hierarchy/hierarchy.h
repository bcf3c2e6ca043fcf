#pragma once
/// \file The amalgam hierarchy concept. Every interior node is an amalgam: bounds plus an
/// appearance. Children are nodes or primitives. Two forms satisfy the concept: the explicit
/// flat-array hierarchy (explicit.h) and the implicit generators of the builtin scenes
/// (builtin/*.h), whose children are computed on demand in constant memory.

#include <concepts>
#include <cstdint>
#include <optional>
#include <string>

#include "amalgam/geometry/bbox.h"
#include "amalgam/geometry/intersect.h"
#include "amalgam/hierarchy/appearance.h"

namespace amalgam {

/// Identifies a node or a primitive within one hierarchy. Ids are unique per kind and stable:
/// random decisions are keyed on them.
using NodeId = std::uint64_t;
using PrimId = std::uint64_t;

struct Child {
  std::uint64_t id;
  bool is_primitive;
};

/// Sizes reported in the stats JSON ("scene": {...}).
struct HierarchyInfo {
  double primitives = 0;  ///< may exceed 2^53 for implicit scenes; reported as a double
  double nodes = 0;       ///< interior nodes (amalgams)
  int levels = 0;         ///< l_max + 1
};

/// Upper bound on the number of levels of any hierarchy (root = level 0).
inline constexpr int kMaxLevels = 64;

/// Upper bound on the number of children of any node, for traversal's stack buffers.
inline constexpr int kMaxChildren = 64;

/// `for_each_child(node, f)` calls `f(Child)` for each child in stored order and stops early
/// when `f` returns false. The root is on level 0; a child is one level below its parent.
template <class H>
concept Hierarchy = requires(const H& h, NodeId n, PrimId p, const Ray& r) {
  { h.root() } -> std::same_as<NodeId>;
  { h.bounds(n) } -> std::same_as<Bbox>;
  { h.appearance(n) } -> std::same_as<Appearance>;
  {h.for_each_child(n, [](Child) { return true; })};
  { h.intersect(p, r) } -> std::same_as<std::optional<SurfaceHit>>;
  { h.surface(p) } -> std::same_as<Surface>;
  { h.info() } -> std::same_as<HierarchyInfo>;
};

}  // namespace amalgam

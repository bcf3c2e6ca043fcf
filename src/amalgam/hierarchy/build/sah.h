#pragma once
/// \file Binned SAH builder over boxes, collapsed to wide nodes. Shared by the explicit
/// hierarchy (boxes = primitive bounds) and the top level of the instanced hierarchy (boxes =
/// instance world bounds).
///
/// See Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies" (RT 2007) for
/// the binning, and Wald, Benthin, Boulos, "Getting Rid of Packets" (RT 2008) for collapsing a
/// binary tree to a wide one by repeatedly opening the child with the largest surface area.

#include <cstdint>
#include <span>
#include <vector>

#include "amalgam/geometry/bbox.h"

namespace amalgam {

/// Settings of `build_sah`.
struct SahConfig {
  int arity = 4;         ///< children per interior node, 2..kMaxChildren
  int leaf_size = 4;     ///< at most this many items in a leaf
  int bins = 16;         ///< SAH bins per axis over the centroid bounds, 2..256
  float c_trav = 1.0f;   ///< SAH cost of a bounding-volume test
  float c_int = 1.0f;    ///< SAH cost of an item test
  bool parallel = true;  ///< oneTBB: parallel subtrees and parallel binning of large ranges
};

/// A wide tree over items. Node 0 is the root; nodes are in breadth-first order, so a node's
/// children are contiguous and have larger indices, and levels never decrease with the index.
/// A leaf's items are order[first .. first + count).
struct SahTree {
  struct Node {
    Bbox bounds;
    std::uint32_t first = 0;
    std::uint16_t count = 0;
    bool leaf = false;
  };
  std::vector<Node> nodes;
  std::vector<std::uint32_t> order;  ///< item indices, leaf by leaf
  std::vector<std::uint8_t> level;   ///< per node, root = 0
  int depth = 0;                     ///< deepest node level
};

/// Builds the tree. Empty input gives a single empty leaf. Every item is in exactly one leaf;
/// every node's box is the union of its children's boxes.
SahTree build_sah(std::span<const Bbox> boxes, const SahConfig& config = {});
/// The same, taking the boxes over: they are freed once copied, before the tree's nodes are
/// allocated (a lower peak of memory).
SahTree build_sah(std::vector<Bbox>&& boxes, const SahConfig& config = {});

}  // namespace amalgam

#pragma once
/// \file The node data of an explicit hierarchy as the SIMD traversal reads it: per node a
/// 12-byte header and the SoA boxes of an interior node's children (geometry/wide.h); the
/// triangles of triangle-only leaves are SoA packs in the primitive store
/// (`ExplicitHierarchy::prims`, hierarchy/primitives.h).
///
/// `WideNodes` is derived data: `build_wide` fills it from `ExplicitHierarchy::nodes` and packs
/// `prims` (called at the end of `bake`, so `build_explicit` always has it). The traversal
/// uses it only when it has one header per node and the primitives are packed
/// (`ExplicitHierarchy::wide_nodes`); a hierarchy whose nodes or primitives are edited
/// afterwards must call `build_wide` again.

#include <cstdint>
#include <vector>

#include "amalgam/geometry/wide.h"
#include "amalgam/hierarchy/hierarchy.h"

namespace amalgam {

class ExplicitHierarchy;
class InstancedHierarchy;

/// WideHeader::leaf values.
enum : std::uint8_t {
  kWideInterior = 0,
  kWideLeaf = 1,          ///< primitives tested one by one (a leaf with non-triangles)
  kWideTriangleLeaf = 2,  ///< triangles only: ceil(count / 4) packs from `block`
};

/// A node as the fast traversal reads it (12 bytes instead of ExplicitNode's 32).
struct WideHeader {
  std::uint32_t first = 0;  ///< first child (node or primitive), as ExplicitNode::first
  /// Interior nodes: first of ceil(count / 4) blocks in `blocks`; triangle leaves: first of
  /// ceil(count / 4) packs in `ExplicitHierarchy::prims.packs()`.
  std::uint32_t block = 0;
  std::uint16_t count = 0;
  std::uint8_t leaf = kWideInterior;
  /// Interior nodes: the bit mask of the first min(count, 8) lanes, (1 << that) - 1, so that
  /// the traversal masks off a block's unused lanes with one load.
  std::uint8_t lanes = 0;
};

struct WideNodes {
  std::vector<WideHeader> headers;  ///< one per node
  /// Children's boxes of every interior node, and one spare block at the end (an 8-lane read
  /// of the last node's single block stays inside the vector).
  std::vector<WideBox4> blocks;
  std::size_t bytes() const {
    return headers.size() * sizeof(WideHeader) + blocks.size() * sizeof(WideBox4);
  }
};

/// (Re)builds `h.wide` from `h.nodes` and packs `h.prims` (unpacking them first if packed).
void build_wide(ExplicitHierarchy& h);

/// (Re)builds `h.top_wide` from `h.top_nodes`, and the `WideNodes` of every mesh that has none
/// (called at the end of `build_instanced`).
void build_wide(InstancedHierarchy& h);

}  // namespace amalgam

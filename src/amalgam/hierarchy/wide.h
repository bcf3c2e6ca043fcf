#pragma once
/// \file The node data of an explicit hierarchy as the SIMD traversal reads it: per node a
/// 12-byte header, the SoA boxes of an interior node's children, and SoA packs of the
/// triangles of a triangle-only leaf (geometry/wide.h).
///
/// `WideNodes` is derived data: `build_wide` fills it from `ExplicitHierarchy::nodes` and
/// `prims` (called at the end of `bake`, so `build_explicit` always has it). The traversal
/// uses it only when it has one header per node (`ExplicitHierarchy::wide_nodes`); a hierarchy
/// whose nodes or primitives are edited afterwards must call `build_wide` again.

#include <cstdint>
#include <vector>

#include "amalgam/geometry/wide.h"
#include "amalgam/hierarchy/hierarchy.h"

namespace amalgam {

class ExplicitHierarchy;

/// WideHeader::leaf values.
enum : std::uint8_t {
  kWideInterior = 0,
  kWideLeaf = 1,          ///< primitives tested one by one (a leaf with non-triangles)
  kWideTriangleLeaf = 2,  ///< triangles only: ceil(count / 4) packs in `tris` from `block`
};

/// A node as the fast traversal reads it (12 bytes instead of ExplicitNode's 32).
struct WideHeader {
  std::uint32_t first = 0;  ///< first child (node or primitive), as ExplicitNode::first
  /// Interior nodes: first of ceil(count / 4) blocks in `blocks`; triangle leaves: first of
  /// ceil(count / 4) packs in `tris`.
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
  std::vector<TrianglePack4> tris;  ///< triangles of every triangle-only leaf, leaf order
  std::size_t bytes() const {
    return headers.size() * sizeof(WideHeader) + blocks.size() * sizeof(WideBox4) +
           tris.size() * sizeof(TrianglePack4);
  }
};

/// The children of one node gathered for a SIMD test, as a hierarchy that is not stored in
/// `WideNodes` form hands them to the traversal (`gather_children`, e.g. the instanced form,
/// whose boxes inside an instance are computed per visit): their boxes in SoA blocks of four and
/// their ids; for a leaf, only the ids of its primitives (in stored order).
struct GatheredChildren {
  WideBox4 boxes[kMaxChildren / kWideLanes];
  NodeId ids[kMaxChildren];
  int count = 0;
  bool primitives = false;

  /// Stores `b` as child `i`'s box.
  void put_box(int i, const Bbox& b) {
    WideBox4& w = boxes[i / kWideLanes];
    const int l = i % kWideLanes;
    w.lo[0][l] = b.lo.x, w.lo[1][l] = b.lo.y, w.lo[2][l] = b.lo.z;
    w.hi[0][l] = b.hi.x, w.hi[1][l] = b.hi.y, w.hi[2][l] = b.hi.z;
  }
  /// Child `i`'s box.
  Bbox box(int i) const {
    const WideBox4& w = boxes[i / kWideLanes];
    const int l = i % kWideLanes;
    return {{w.lo[0][l], w.lo[1][l], w.lo[2][l]}, {w.hi[0][l], w.hi[1][l], w.hi[2][l]}};
  }
};

/// (Re)builds `h.wide` from `h.nodes`.
void build_wide(ExplicitHierarchy& h);

}  // namespace amalgam

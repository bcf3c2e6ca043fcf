#pragma once
/// \file The node data of a hierarchy as the SIMD traversal reads it: a record per interior
/// node, holding its children's boxes (SoA, geometry/wide.h) and beside them each child's
/// reference, so that entering a child needs nothing but the reference taken from its parent
/// (no header to read first). Leaves keep a 12-byte header per node; the triangles of
/// triangle-only leaves are SoA packs in the primitive store (`ExplicitHierarchy::prims`,
/// hierarchy/primitives.h).
///
/// `WideNodes` is derived data: `build_wide` fills it from `ExplicitHierarchy::nodes` and packs
/// `prims` (called at the end of `bake`, so `build_explicit` always has it). The traversal
/// uses it only when it has one header per node and the primitives are packed
/// (`ExplicitHierarchy::wide_nodes`); a hierarchy whose nodes or primitives are edited
/// afterwards must call `build_wide` again.

#include <cstdint>
#include <cstring>
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

/// What the traversal reads of a leaf (12 bytes; one per node, indexed by node id).
struct WideHeader {
  std::uint32_t first = 0;  ///< first child (node or primitive), as ExplicitNode::first
  /// Interior nodes: their record's index in `WideNodes::record_node`; triangle leaves: their
  /// first of ceil(count / 4) packs in `ExplicitHierarchy::prims.packs()`.
  std::uint32_t block = 0;
  std::uint16_t count = 0;
  std::uint8_t leaf = kWideInterior;
  std::uint8_t reserved = 0;  ///< zero: no padding byte left undefined (headers are compared)
};

/// An interior node's record (224 bytes): its children's boxes in 8-lane rows
/// (geometry/wide.h, `BoxRows`) and, after them, their references. A node of more than 8
/// children has ceil(count / 8) consecutive records; lanes beyond the count hold empty boxes
/// and reference 0; a node without children has one record of empty lanes. (Records of 4 lanes
/// for nodes of up to 4 children, at half the bytes, made every walk 5-10 % slower: the
/// variable row stride costs more per node than the smaller footprint saves.)
///
/// A reference to a node, as a parent's record holds it for each child and the traversal's
/// stack carries it (so that entering a child needs nothing but its reference):
/// - a triangle-only leaf of one pack (1 to 4 triangles: the default leaves): kWideRefLeaf |
///   kWideRefPack | (count - 1) << 28 | the index of its pack in the primitive store, so that
///   the walk tests the pack without reading the leaf's header first (on a 10^6-triangle scene
///   that read was a second dependent cache miss per leaf); `pack_node` gives its node;
/// - any other leaf: kWideRefLeaf | its node id (its header says what it holds);
/// - an interior node: half the byte offset of its record in `WideNodes::pool` (records are
///   32-byte aligned, so the low 4 bits are free) | a lane code there: its child count when at
///   most 8 (the lanes in use: (1 << code) - 1), else kWideRefMany (the count is in its
///   header).
/// In the top tree of an instanced hierarchy every node has a record; kWideRefLeaf marks a
/// top leaf's reference, whose record's lanes are instances (their instance indices).
using WideRef = std::uint32_t;
inline constexpr WideRef kWideRefLeaf = 1u << 31;
inline constexpr WideRef kWideRefPack = 1u << 30;  ///< with kWideRefLeaf: a one-pack leaf
inline constexpr WideRef kWideRefPackIndex = (1u << 28) - 1;
inline constexpr WideRef kWideRefMany = 15;
inline constexpr WideRef kWideRefOffset = ~kWideRefLeaf & ~15u;
/// Packs a one-pack leaf's reference can address.
inline constexpr std::uint64_t kWideMaxPackRefs = std::uint64_t{kWideRefPackIndex} + 1;

/// The reference of a one-pack leaf of `count` (1..4) triangles in pack `pack`.
inline constexpr WideRef wide_pack_ref(std::uint32_t pack, int count) {
  return kWideRefLeaf | kWideRefPack | static_cast<WideRef>(count - 1) << 28 | pack;
}
/// The pack and the number of triangles of a one-pack leaf's reference.
inline constexpr std::uint32_t wide_ref_pack(WideRef r) {
  return r & kWideRefPackIndex;
}
inline constexpr int wide_ref_pack_count(WideRef r) {
  return static_cast<int>((r >> 28) & 3u) + 1;
}
/// The bytes of a record.
inline constexpr std::uint32_t kWideRecordBytes = 7 * kBoxLanes * sizeof(float);
/// The largest node id (leaf) and pool size a reference can hold; larger hierarchies take the
/// generic traversal.
inline constexpr std::uint64_t kWideMaxNodes = kWideRefPack;
inline constexpr std::uint64_t kWideMaxPoolBytes = std::uint64_t{kWideRefLeaf} * 2;

inline constexpr WideRef wide_interior_ref(std::uint64_t offset, int count) {
  return static_cast<WideRef>(offset / 2) |
         static_cast<WideRef>(count > kBoxLanes ? kWideRefMany : count);
}

/// 32 bytes of the record pool (floats and references, read with SIMD loads and memcpy).
struct alignas(32) WideUnit {
  unsigned char bytes[32];
};

/// One record of the pool as the traversal reads it.
struct WideRecord {
  const unsigned char* base;
  /// The record of interior reference `r` in the pool at `pool`.
  [[gnu::always_inline]] static WideRecord at(const unsigned char* pool, WideRef r) {
    return {pool + std::size_t{r & kWideRefOffset} * 2};
  }
  BoxRows boxes() const { return {reinterpret_cast<const float*>(base), kBoxLanes}; }
  WideRef child(int lane) const {
    WideRef r;
    std::memcpy(&r, base + (6 * kBoxLanes + lane) * sizeof(float), sizeof r);
    return r;
  }
  /// The next record of a node of more than 8 children.
  WideRecord next() const { return {base + kWideRecordBytes}; }
};

struct WideNodes {
  std::vector<WideHeader> headers;         ///< one per node
  std::vector<WideUnit> pool;              ///< interior nodes' records, in node order
  std::vector<std::uint32_t> record_node;  ///< per record: its node (LOD policies read it)
  /// Per pack of the primitive store: the leaf it belongs to (one-pack leaves' references
  /// carry their pack, not their node; LOD policies and a hit's primitive id read it).
  std::vector<std::uint32_t> pack_node;
  WideRef root = 0;  ///< the reference of node 0
  /// `build_wide` found more records than references address: the hierarchy has no SIMD form
  /// by design (the traversal's generic source walks it), for `unaddressable_nodes` nodes.
  std::size_t unaddressable_nodes = 0;
  const unsigned char* pool_bytes() const {
    return reinterpret_cast<const unsigned char*>(pool.data());
  }
  /// The record of interior reference `r` (its first, for more than 8 children).
  WideRecord record(WideRef r) const { return WideRecord::at(pool_bytes(), r); }
  /// The node whose record is at interior reference `r`.
  std::uint32_t record_owner(WideRef r) const {
    return record_node[std::size_t{r & kWideRefOffset} * 2 / kWideRecordBytes];
  }
  /// The id of the node `r` refers to (in a hierarchy's own tree: there kWideRefLeaf marks a
  /// leaf).
  std::uint32_t node_of(WideRef r) const {
    if (!(r & kWideRefLeaf)) return record_owner(r);
    return r & kWideRefPack ? pack_node[wide_ref_pack(r)] : r & ~kWideRefLeaf;
  }
  /// The first primitive of the one-pack leaf `r`.
  std::uint32_t pack_first(WideRef r) const { return headers[pack_node[wide_ref_pack(r)]].first; }
  /// What the walks read of leaf `r` before testing it: a one-pack leaf's pack and count from
  /// the reference alone (`first` left 0: `leaf_first` reads it, on a hit), any other leaf's
  /// header.
  WideHeader leaf_header(WideRef r) const {
    if (r & kWideRefPack)
      return {0, wide_ref_pack(r), static_cast<std::uint16_t>(wide_ref_pack_count(r)),
              kWideTriangleLeaf, 0};
    return headers[r & ~kWideRefLeaf];
  }
  /// The first primitive of leaf `r`, whose `leaf_header` is `hd`.
  std::uint32_t leaf_first(WideRef r, const WideHeader& hd) const {
    return r & kWideRefPack ? pack_first(r) : hd.first;
  }
  /// The children of interior node `r`.
  int child_count(WideRef r) const {
    const int code = static_cast<int>(r & 15u);
    return code <= kBoxLanes ? code : headers[record_owner(r)].count;
  }
  std::size_t bytes() const {
    return headers.size() * sizeof(WideHeader) + pool.size() * sizeof(WideUnit) +
           (record_node.size() + pack_node.size()) * sizeof(std::uint32_t);
  }
};

/// (Re)builds `h.wide` from `h.nodes` and packs `h.prims` (unpacking them first if packed).
void build_wide(ExplicitHierarchy& h);

/// (Re)builds `h.top_wide` from `h.top_nodes`, and the `WideNodes` of every mesh whose form is
/// stale (called at the end of `build_instanced`). Leaves the top tree without SIMD form (the
/// traversal's generic source) when a mesh has none by design.
void build_wide(InstancedHierarchy& h);

}  // namespace amalgam

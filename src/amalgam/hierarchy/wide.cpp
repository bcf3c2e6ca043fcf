#include "amalgam/hierarchy/wide.h"

#include <algorithm>
#include <cstring>

#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"
#include "amalgam/util/parallel.h"

namespace amalgam {
namespace {

/// The records of a node of `count` children (hierarchy/wide.h).
std::size_t records_of(int count) {
  return std::max<std::size_t>(1, (static_cast<std::size_t>(count) + kBoxLanes - 1) / kBoxLanes);
}

/// Writes the records from record `first` of node `node` of `count` children: child c's box
/// `box(c)` and reference `ref(c)` in lane c % 8 of record first + c / 8.
template <class Box, class Ref>
void fill_records(WideNodes& w, std::uint32_t first, std::uint32_t node, int count, Box&& box,
                  Ref&& ref) {
  unsigned char* base =
      reinterpret_cast<unsigned char*>(w.pool.data()) + std::size_t{first} * kWideRecordBytes;
  for (std::size_t k = 0; k < records_of(count); ++k, base += kWideRecordBytes) {
    w.record_node[first + k] = node;
    for (int lane = 0; lane < kBoxLanes; ++lane) {
      const int c = static_cast<int>(k) * kBoxLanes + lane;
      const Bbox bb = c < count ? box(c) : Bbox{};
      const WideRef r = c < count ? ref(c) : 0;
      for (int a = 0; a < 3; ++a) {
        const float lo = bb.lo[a], hi = bb.hi[a];
        std::memcpy(base + (a * kBoxLanes + lane) * sizeof(float), &lo, sizeof lo);
        std::memcpy(base + ((3 + a) * kBoxLanes + lane) * sizeof(float), &hi, sizeof hi);
      }
      std::memcpy(base + (6 * kBoxLanes + lane) * sizeof(float), &r, sizeof r);
    }
  }
}

/// Where each interior node's records start (`is_interior(i)`), in node order: the headers'
/// `block`; returns the number of records, or 0 when a reference cannot address them all.
template <class Interior>
std::size_t assign_records(std::vector<WideHeader>& headers, Interior&& is_interior) {
  if (headers.size() >= kWideMaxNodes) return 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < headers.size(); ++i)
    if (is_interior(i)) {
      headers[i].block = static_cast<std::uint32_t>(n);
      n += records_of(headers[i].count);
      if (n * kWideRecordBytes >= kWideMaxPoolBytes) return 0;
    }
  return n;
}

/// The pool and its owners for `records` records.
void allocate(WideNodes& w, std::size_t records) {
  w.pool.assign(records * kWideRecordBytes / sizeof(WideUnit), WideUnit{});
  w.record_node.assign(records, 0);
}

/// The reference of an interior node of `count` children whose records start at `first`.
WideRef interior_ref(std::uint32_t first, int count) {
  return wide_interior_ref(std::uint64_t{first} * kWideRecordBytes, count);
}

}  // namespace

void build_wide(ExplicitHierarchy& h) {
  WideNodes& w = h.wide;
  const std::vector<Primitive>& prims = h.prims.edit();  // the whole form, to classify and pack
  const std::size_t n = h.nodes.size();
  w = WideNodes{};
  w.headers.assign(n, WideHeader{});
  // Each node's header but for where its records or packs start (in parallel: a leaf reads its
  // primitives), then where the records start in node order (a prefix sum), then the packs
  // (in node order), then the records (in parallel again): the layout of a serial pass over
  // the nodes, bit for bit.
  for_each_index(n, [&](std::size_t i) {
    const ExplicitNode& nd = h.nodes[i];
    WideHeader& hd = w.headers[i];
    hd.first = nd.first;
    hd.count = nd.count;
    hd.leaf = nd.leaf ? kWideLeaf : kWideInterior;
    if (!nd.leaf) return;
    bool triangles = nd.count > 0;
    for (int j = 0; j < nd.count; ++j)
      triangles = triangles && prims[nd.first + j].kind == PrimKind::kTriangle;
    if (triangles) hd.leaf = kWideTriangleLeaf;  // else spheres or boxes: the scalar loop
  });
  const std::size_t n_records =
      assign_records(w.headers, [&](std::size_t i) { return !h.nodes[i].leaf; });
  std::vector<PrimRange> leaves;
  for (const WideHeader& hd : w.headers)
    if (hd.leaf == kWideTriangleLeaf) leaves.push_back({hd.first, hd.count});
  // The triangle leaves' packs, in node order; the primitives keep only what the packs lack.
  std::vector<std::uint32_t> first_pack(leaves.size());
  h.prims.pack(leaves, first_pack);
  w.pack_node.assign(h.prims.packs().size(), 0);
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    WideHeader& hd = w.headers[i];
    if (hd.leaf != kWideTriangleLeaf) continue;
    hd.block = first_pack[k++];
    const std::uint32_t packs = (hd.count + kWideLanes - 1) / kWideLanes;
    for (std::uint32_t p = 0; p < packs; ++p)
      w.pack_node[hd.block + p] = static_cast<std::uint32_t>(i);
  }
  // A leaf of one pack is referred to by its pack (hierarchy/wide.h).
  const auto leaf_ref = [&](std::uint32_t j) {
    const WideHeader& hd = w.headers[j];
    if (hd.leaf == kWideTriangleLeaf && hd.count <= kWideLanes && hd.block < kWideMaxPackRefs)
      return wide_pack_ref(hd.block, hd.count);
    return kWideRefLeaf | j;
  };
  // No records though the root is interior: more than references address (the generic source).
  if (n_records == 0 && n > 0 && !h.nodes[0].leaf) {
    w = WideNodes{};
    w.unaddressable_nodes = n;
    return;
  }
  const auto ref = [&](std::uint32_t j) {
    const ExplicitNode& c = h.nodes[j];
    return c.leaf ? leaf_ref(j) : interior_ref(w.headers[j].block, c.count);
  };
  allocate(w, n_records);
  for_each_index(n, [&](std::size_t i) {
    const ExplicitNode& nd = h.nodes[i];
    if (nd.leaf) return;
    fill_records(
        w, w.headers[i].block, static_cast<std::uint32_t>(i), nd.count,
        [&](int c) { return h.nodes[nd.first + c].bounds; },
        [&](int c) { return ref(nd.first + static_cast<std::uint32_t>(c)); });
  });
  w.root = n ? ref(0) : 0;
}

void build_wide(InstancedHierarchy& h) {
  for (ExplicitHierarchy& m : h.meshes)
    if (m.wide_stale()) build_wide(m);
  WideNodes& w = h.top_wide;
  w = WideNodes{};
  const std::size_t n = h.top_nodes.size();
  // The instanced source reads every mesh's SIMD form: without one (a mesh of more records than
  // references address), the whole hierarchy goes to the generic source.
  for (const ExplicitHierarchy& m : h.meshes) {
    if (!m.nodes.empty() && !m.wide_nodes()) {
      w.unaddressable_nodes = n;
      return;
    }
  }
  w.headers.assign(n, WideHeader{});
  for (std::size_t i = 0; i < n; ++i) {
    const ExplicitNode& nd = h.top_nodes[i];
    w.headers[i] = {nd.first, 0, nd.count, nd.leaf ? kWideLeaf : kWideInterior, 0};
  }
  // Every top node has records: a leaf's lanes are its instances.
  const std::size_t n_records = assign_records(w.headers, [](std::size_t) { return true; });
  if (n_records == 0) {
    w = WideNodes{};
    w.unaddressable_nodes = n;
    return;
  }
  const auto ref = [&](std::uint32_t j) {
    const ExplicitNode& c = h.top_nodes[j];
    return (c.leaf ? kWideRefLeaf : 0u) | interior_ref(w.headers[j].block, c.count);
  };
  allocate(w, n_records);
  for (std::size_t i = 0; i < n; ++i) {
    const ExplicitNode& nd = h.top_nodes[i];
    fill_records(
        w, w.headers[i].block, static_cast<std::uint32_t>(i), nd.count,
        [&](int c) {
          return nd.leaf ? h.instances[h.top_items[nd.first + c]].world_bounds
                         : h.top_nodes[nd.first + c].bounds;
        },
        [&](int c) {
          return nd.leaf ? h.top_items[nd.first + c]
                         : ref(nd.first + static_cast<std::uint32_t>(c));
        });
  }
  w.root = n ? ref(0) : 0;
}

}  // namespace amalgam

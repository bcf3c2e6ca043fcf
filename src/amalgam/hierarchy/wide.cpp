#include "amalgam/hierarchy/wide.h"

#include <algorithm>

#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"
#include "amalgam/util/parallel.h"

namespace amalgam {
namespace {

/// Fills `b` with the boxes of children c0 .. c0 + 3 of a node of `count` children, `box(c)`
/// (unused lanes empty).
template <class F>
void fill_block(WideBox4& b, int c0, int count, F&& box) {
  for (int lane = 0; lane < kWideLanes; ++lane) {
    const int c = c0 + lane;
    const Bbox bb = c < count ? box(c) : Bbox{};
    for (int a = 0; a < 3; ++a) b.lo[a][lane] = bb.lo[a], b.hi[a][lane] = bb.hi[a];
  }
}

std::uint8_t lane_mask(int count) {
  return static_cast<std::uint8_t>((1u << std::min<int>(count, 8)) - 1u);
}

}  // namespace

void build_wide(ExplicitHierarchy& h) {
  WideNodes& w = h.wide;
  const std::vector<Primitive>& prims = h.prims.edit();  // the whole form, to classify and pack
  const std::size_t n = h.nodes.size();
  w.headers.assign(n, WideHeader{});
  // Each node's header but for where its blocks or packs start (in parallel: a leaf reads its
  // primitives), then those starts in node order (a prefix sum), then the blocks (in parallel
  // again) and the packs: the layout of a serial pass over the nodes, bit for bit.
  for_each_index(n, [&](std::size_t i) {
    const ExplicitNode& nd = h.nodes[i];
    WideHeader& hd = w.headers[i];
    hd.first = nd.first;
    hd.count = nd.count;
    hd.leaf = nd.leaf ? kWideLeaf : kWideInterior;
    hd.lanes = nd.leaf ? 0 : lane_mask(nd.count);
    if (!nd.leaf) return;
    bool triangles = nd.count > 0;
    for (int j = 0; j < nd.count; ++j)
      triangles = triangles && prims[nd.first + j].kind == PrimKind::kTriangle;
    if (triangles) hd.leaf = kWideTriangleLeaf;  // else spheres or boxes: the scalar loop
  });
  std::size_t n_blocks = 0;
  std::vector<PrimRange> leaves;
  for (WideHeader& hd : w.headers) {
    if (hd.leaf == kWideInterior) {
      hd.block = static_cast<std::uint32_t>(n_blocks);
      n_blocks += (hd.count + kWideLanes - 1) / kWideLanes;
    } else if (hd.leaf == kWideTriangleLeaf) {
      leaves.push_back({hd.first, hd.count});
    } else {
      hd.block = static_cast<std::uint32_t>(n_blocks);  // as the blocks' size at this node
    }
  }
  // One spare block: the AVX2 walk tests a node of up to 4 children with the 8-lane kernel
  // too, reading the block after its own (lanes masked off by WideHeader::lanes).
  w.blocks.assign(n_blocks + 1, WideBox4{});
  for_each_index(n, [&](std::size_t i) {
    const ExplicitNode& nd = h.nodes[i];
    const WideHeader& hd = w.headers[i];
    if (hd.leaf == kWideInterior)
      for (int c0 = 0, b = 0; c0 < nd.count; c0 += kWideLanes, ++b)
        fill_block(w.blocks[hd.block + static_cast<std::size_t>(b)], c0, nd.count,
                   [&](int c) { return h.nodes[nd.first + c].bounds; });
  });
  // The triangle leaves' packs, in node order; the primitives keep only what the packs lack.
  std::vector<std::uint32_t> first_pack(leaves.size());
  h.prims.pack(leaves, first_pack);
  std::size_t k = 0;
  for (WideHeader& hd : w.headers)
    if (hd.leaf == kWideTriangleLeaf) hd.block = first_pack[k++];
}

void build_wide(InstancedHierarchy& h) {
  for (ExplicitHierarchy& m : h.meshes)
    if (!m.wide_nodes()) build_wide(m);
  WideNodes& w = h.top_wide;
  w.headers.assign(h.top_nodes.size(), WideHeader{});
  w.blocks.clear();
  for (std::size_t i = 0; i < h.top_nodes.size(); ++i) {
    const ExplicitNode& n = h.top_nodes[i];
    WideHeader& hd = w.headers[i];
    hd.first = n.first;
    hd.count = n.count;
    hd.leaf = n.leaf ? kWideLeaf : kWideInterior;  // a leaf's children: instances
    hd.lanes = lane_mask(n.count);
    hd.block = static_cast<std::uint32_t>(w.blocks.size());
    for (int c0 = 0; c0 < n.count; c0 += kWideLanes)
      fill_block(w.blocks.emplace_back(), c0, n.count, [&](int c) {
        return n.leaf ? h.instances[h.top_items[n.first + c]].world_bounds
                      : h.top_nodes[n.first + c].bounds;
      });
  }
  w.blocks.emplace_back();  // the spare block, as above
}

}  // namespace amalgam

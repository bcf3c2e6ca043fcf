#include "amalgam/hierarchy/wide.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <limits>

#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
}  // namespace

namespace amalgam {
namespace {

/// Calls f(i) for i in [0, n), in parallel when n is large.
template <class F>
void each(std::size_t n, F&& f) {
  if (n < 16384) {
    for (std::size_t i = 0; i < n; ++i) f(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i < r.end(); ++i) f(i);
                    });
}

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
  const std::size_t n = h.nodes.size();
  w.headers.assign(n, WideHeader{});
  // Each node's header but for where its blocks or packs start (in parallel: a leaf reads its
  // primitives), then those starts in node order (a prefix sum), then the blocks and packs (in
  // parallel again): the layout of a serial pass over the nodes, bit for bit.
  each(n, [&](std::size_t i) {
    const ExplicitNode& nd = h.nodes[i];
    WideHeader& hd = w.headers[i];
    hd.first = nd.first;
    hd.count = nd.count;
    hd.leaf = nd.leaf ? kWideLeaf : kWideInterior;
    hd.lanes = nd.leaf ? 0 : lane_mask(nd.count);
    if (!nd.leaf) return;
    bool triangles = nd.count > 0;
    for (int j = 0; j < nd.count; ++j)
      triangles = triangles && h.prims[nd.first + j].kind == PrimKind::kTriangle;
    if (triangles) hd.leaf = kWideTriangleLeaf;  // else spheres or boxes: the scalar loop
  });
  std::size_t n_blocks = 0, n_packs = 0;
  for (WideHeader& hd : w.headers) {
    const std::size_t k = (hd.count + kWideLanes - 1) / kWideLanes;
    if (hd.leaf == kWideInterior) {
      hd.block = static_cast<std::uint32_t>(n_blocks), n_blocks += k;
    } else if (hd.leaf == kWideTriangleLeaf) {
      hd.block = static_cast<std::uint32_t>(n_packs), n_packs += k;
    } else {
      hd.block = static_cast<std::uint32_t>(n_blocks);  // as the blocks' size at this node
    }
  }
  // One spare block: the AVX2 walk tests a node of up to 4 children with the 8-lane kernel
  // too, reading the block after its own (lanes masked off by WideHeader::lanes).
  w.blocks.assign(n_blocks + 1, WideBox4{});
  w.tris.resize(n_packs);
  each(n, [&](std::size_t i) {
    const ExplicitNode& nd = h.nodes[i];
    const WideHeader& hd = w.headers[i];
    if (hd.leaf == kWideTriangleLeaf) {
      for (int c0 = 0, b = 0; c0 < nd.count; c0 += kWideLanes, ++b) {
        TrianglePack4& pack = w.tris[hd.block + static_cast<std::size_t>(b)];
        for (int lane = 0; lane < kWideLanes; ++lane) {
          const int c = c0 + lane;
          for (int k = 0; k < 3; ++k) {
            const Primitive* p = c < nd.count ? &h.prims[nd.first + c] : nullptr;
            const Vec3 vtx = !p ? Vec3{kNaN, kNaN, kNaN} : k == 0 ? p->a : k == 1 ? p->b : p->c;
            for (int a = 0; a < 3; ++a) pack.v[k][a][lane] = vtx[a];
          }
        }
      }
    } else if (hd.leaf == kWideInterior) {
      for (int c0 = 0, b = 0; c0 < nd.count; c0 += kWideLanes, ++b)
        fill_block(w.blocks[hd.block + static_cast<std::size_t>(b)], c0, nd.count,
                   [&](int c) { return h.nodes[nd.first + c].bounds; });
    }
  });
}

void build_wide(InstancedHierarchy& h) {
  for (ExplicitHierarchy& m : h.meshes)
    if (!m.wide_nodes()) build_wide(m);
  WideNodes& w = h.top_wide;
  w.headers.assign(h.top_nodes.size(), WideHeader{});
  w.blocks.clear();
  w.tris.clear();
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

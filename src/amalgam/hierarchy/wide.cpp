#include "amalgam/hierarchy/wide.h"

#include <algorithm>
#include <limits>

#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"

namespace amalgam {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

/// Appends the SoA blocks of `count` boxes, `box(c)` for c in [0, count) (unused lanes empty).
template <class F>
void append_blocks(std::vector<WideBox4>& blocks, int count, F&& box) {
  for (int c0 = 0; c0 < count; c0 += kWideLanes) {
    WideBox4 b;
    for (int lane = 0; lane < kWideLanes; ++lane) {
      const int c = c0 + lane;
      const Bbox bb = c < count ? box(c) : Bbox{};
      for (int a = 0; a < 3; ++a) b.lo[a][lane] = bb.lo[a], b.hi[a][lane] = bb.hi[a];
    }
    blocks.push_back(b);
  }
}

std::uint8_t lane_mask(int count) {
  return static_cast<std::uint8_t>((1u << std::min<int>(count, 8)) - 1u);
}

}  // namespace

void build_wide(ExplicitHierarchy& h) {
  WideNodes& w = h.wide;
  w.headers.assign(h.nodes.size(), WideHeader{});
  w.blocks.clear();
  w.tris.clear();
  std::size_t n_blocks = 0, n_packs = 0;
  for (const ExplicitNode& n : h.nodes)
    (n.leaf ? n_packs : n_blocks) += (n.count + kWideLanes - 1) / kWideLanes;
  w.blocks.reserve(n_blocks + 1);
  w.tris.reserve(n_packs);  // an upper bound: leaves with spheres or boxes take none
  for (std::size_t i = 0; i < h.nodes.size(); ++i) {
    const ExplicitNode& n = h.nodes[i];
    WideHeader& hd = w.headers[i];
    hd.first = n.first;
    hd.count = n.count;
    hd.leaf = n.leaf ? kWideLeaf : kWideInterior;
    hd.lanes = n.leaf ? 0 : lane_mask(n.count);
    hd.block = static_cast<std::uint32_t>(w.blocks.size());
    if (n.leaf) {
      bool triangles = n.count > 0;
      for (int j = 0; j < n.count; ++j)
        triangles = triangles && h.prims[n.first + j].kind == PrimKind::kTriangle;
      if (!triangles) continue;  // spheres and boxes: the scalar loop over `prims`
      hd.leaf = kWideTriangleLeaf;
      hd.block = static_cast<std::uint32_t>(w.tris.size());
      for (int c0 = 0; c0 < n.count; c0 += kWideLanes) {
        TrianglePack4 pack;
        for (int lane = 0; lane < kWideLanes; ++lane) {
          const int c = c0 + lane;
          for (int k = 0; k < 3; ++k) {
            const Primitive* p = c < n.count ? &h.prims[n.first + c] : nullptr;
            const Vec3 vtx = !p ? Vec3{kNaN, kNaN, kNaN} : k == 0 ? p->a : k == 1 ? p->b : p->c;
            for (int a = 0; a < 3; ++a) pack.v[k][a][lane] = vtx[a];
          }
        }
        w.tris.push_back(pack);
      }
      continue;
    }
    append_blocks(w.blocks, n.count, [&](int c) { return h.nodes[n.first + c].bounds; });
  }
  // One spare block: the AVX2 walk tests a node of up to 4 children with the 8-lane kernel
  // too, reading the block after its own (lanes masked off by WideHeader::lanes).
  w.blocks.emplace_back();
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
    append_blocks(w.blocks, n.count, [&](int c) {
      return n.leaf ? h.instances[h.top_items[n.first + c]].world_bounds
                    : h.top_nodes[n.first + c].bounds;
    });
  }
  w.blocks.emplace_back();  // the spare block, as above
}

}  // namespace amalgam

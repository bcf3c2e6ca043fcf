#include "amalgam/hierarchy/wide.h"

#include "amalgam/hierarchy/explicit.h"

namespace amalgam {

void build_wide(ExplicitHierarchy& h) {
  WideNodes& w = h.wide;
  w.headers.assign(h.nodes.size(), WideHeader{});
  w.blocks.clear();
  std::size_t n_blocks = 0;
  for (const ExplicitNode& n : h.nodes)
    if (!n.leaf) n_blocks += (n.count + kWideLanes - 1) / kWideLanes;
  w.blocks.reserve(n_blocks);
  for (std::size_t i = 0; i < h.nodes.size(); ++i) {
    const ExplicitNode& n = h.nodes[i];
    WideHeader& hd = w.headers[i];
    hd.first = n.first;
    hd.count = n.count;
    hd.leaf = n.leaf ? 1 : 0;
    hd.block = static_cast<std::uint32_t>(w.blocks.size());
    if (n.leaf) continue;
    for (int c0 = 0; c0 < n.count; c0 += kWideLanes) {
      WideBox4 b;
      for (int lane = 0; lane < kWideLanes; ++lane) {
        const int c = c0 + lane;
        const Bbox box = c < n.count ? h.nodes[n.first + c].bounds : Bbox{};
        for (int a = 0; a < 3; ++a) b.lo[a][lane] = box.lo[a], b.hi[a][lane] = box.hi[a];
      }
      w.blocks.push_back(b);
    }
  }
}

}  // namespace amalgam

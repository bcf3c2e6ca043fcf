#pragma once
/// \file Copies a hierarchy that can list its primitives (`src.primitive(PrimId)`) into explicit
/// form (breadth-first node order), keeping its appearances: the same scene, for differential
/// tests of the two forms. Only for small hierarchies.

#include <vector>

#include "amalgam/hierarchy/explicit.h"
#include "amalgam/util/check.h"

namespace amalgam {

template <Hierarchy H>
ExplicitHierarchy flatten(const H& src, int max_levels) {
  ExplicitHierarchy out;
  out.levels = max_levels;
  // Breadth-first so that each node's children are contiguous.
  struct Item {
    NodeId src;
    std::uint32_t dst;
  };
  std::vector<Item> queue{{src.root(), 0}};
  out.nodes.push_back({src.bounds(src.root()), 0, 0, false});
  out.appearances.push_back(src.appearance(src.root()));
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const Item it = queue[q];
    std::vector<Child> kids;
    src.for_each_child(it.src, [&](Child c) {
      kids.push_back(c);
      return true;
    });
    ExplicitNode& node = out.nodes[it.dst];
    node.count = checked_narrow<std::uint16_t>(kids.size(), "flatten: child count");
    node.leaf = !kids.empty() && kids.front().is_primitive;
    if (node.leaf) {
      node.first = static_cast<std::uint32_t>(out.prims.size());
      for (const Child& c : kids) {
        Primitive p = src.primitive(c.id);
        p.material = static_cast<std::uint32_t>(out.materials.size());
        out.materials.push_back(src.surface(c.id));
        out.prims.edit().push_back(p);
      }
    } else {
      node.first = static_cast<std::uint32_t>(out.nodes.size());
      for (const Child& c : kids) {
        queue.push_back({c.id, static_cast<std::uint32_t>(out.nodes.size())});
        out.nodes.push_back({src.bounds(c.id), 0, 0, false});
        out.appearances.push_back(src.appearance(c.id));
      }
    }
  }
  return out;
}

}  // namespace amalgam

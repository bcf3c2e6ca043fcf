#include "amalgam/hierarchy/bake/bake.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <span>
#include <vector>

#include "amalgam/hierarchy/bake/combine.h"
#include "amalgam/hierarchy/bake/lines.h"
#include "amalgam/hierarchy/bake/orientation.h"
#include "amalgam/math/random.h"
#include "amalgam/util/check.h"

namespace amalgam {
namespace {

/// Calls `bake_one(i)` for every node i, deepest level first, all nodes of a level before any
/// of the level above (in parallel within a level when `parallel` and it is wide): the one
/// bottom-up loop of every bake. `level[i]` is node i's level (root 0).
template <class F>
void for_each_level_bottom_up(std::span<const int> level, bool parallel, F&& bake_one) {
  int max_level = 0;
  for (int l : level) max_level = std::max(max_level, l);
  std::vector<std::vector<std::uint32_t>> by_level(static_cast<std::size_t>(max_level) + 1);
  for (std::size_t i = 0; i < level.size(); ++i)
    by_level[static_cast<std::size_t>(level[i])].push_back(static_cast<std::uint32_t>(i));
  for (int l = max_level; l >= 0; --l) {
    const auto& ids = by_level[static_cast<std::size_t>(l)];
    if (parallel && ids.size() > 64) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ids.size(), 16),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t j = r.begin(); j < r.end(); ++j) bake_one(ids[j]);
                        });
    } else {
      for (std::uint32_t id : ids) bake_one(id);
    }
  }
}

/// Levels of `nodes` (children always have larger indices than their parent).
std::vector<int> node_levels(const std::vector<ExplicitNode>& nodes) {
  std::vector<int> level(nodes.size(), 0);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (!nodes[i].leaf)
      for (std::uint32_t c = 0; c < nodes[i].count; ++c) {
        AMALGAM_CHECK(nodes[i].first + c > i, "bake: a child precedes its parent");
        level[nodes[i].first + c] = level[i] + 1;
      }
  return level;
}

/// Exact bake of node `id`: random lines traced (closest hit) against its subtree.
/// `orientation`: closed_orientation of the hierarchy's primitives (0: triangles have no
/// known outside, so the result is never kOriented when one is hit). `colours`: each
/// primitive's bake colour when the hierarchy is textured (else empty: the materials').
BakeResult bake_exact(const ExplicitHierarchy& h, std::uint32_t id, const BakeConfig& cfg,
                      int orientation, const std::vector<Vec3>& colours) {
  const int rays = std::max(cfg.rays, 1);
  const Bbox box = h.nodes[id].bounds;
  Vec3 colour{};
  float spec = 0.0f, shine = 0.0f;
  NormalTensor normals;
  Vec3 outward{};  // sum of the outward normals at the hits
  bool oriented = true;
  int hits = 0;
  std::vector<std::uint32_t> stack;
  for (int r = 0; r < rays; ++r) {
    Sampler s(hash_combine(hash_combine(cfg.seed, id), static_cast<std::uint64_t>(r)));
    float u[6];
    for (float& x : u) x = s.next();
    u[0] = (static_cast<float>(r) + u[0]) / static_cast<float>(rays);
    Ray ray = sample_line(box, u);
    std::optional<SurfaceHit> best;
    std::uint32_t best_prim = 0;
    const ExplicitNode& top = h.nodes[id];
    if (top.leaf) {  // the common case: no stack
      for (std::uint32_t p = top.first; p < top.first + top.count; ++p)
        if (auto hit = intersect(h.prims[p], ray)) {
          best = hit, best_prim = p;
          ray.tmax = hit->t;
        }
    } else {
      stack.assign(1, id);
    }
    while (!stack.empty()) {
      const ExplicitNode& n = h.nodes[stack.back()];
      stack.pop_back();
      if (!intersect_box(ray, n.bounds)) continue;
      if (n.leaf) {
        for (std::uint32_t p = n.first; p < n.first + n.count; ++p)
          if (auto hit = intersect(h.prims[p], ray)) {
            best = hit, best_prim = p;
            ray.tmax = hit->t;
          }
      } else {
        for (std::uint32_t c = 0; c < n.count; ++c) stack.push_back(n.first + c);
      }
    }
    if (!best) continue;
    ++hits;
    const Surface& m = h.materials[h.prims[best_prim].material];
    colour += colours.empty() ? m.colour : colours[best_prim];
    spec += m.reflectance;
    shine += m.shininess;
    normals.add(best->normal, 1.0f);
    const Primitive& bp = h.prims[best_prim];
    if (bp.kind != PrimKind::kTriangle) {
      outward += best->normal;  // facing the line, which comes from outside the solid
    } else if (orientation != 0) {
      const Vec3 w = cross(bp.b - bp.a, bp.c - bp.a);
      const float len = length(w);
      if (len > 0.0f) outward += w * (static_cast<float>(orientation) / len);
    } else {
      oriented = false;
    }
  }
  BakeResult r = finish_bake(rays, hits, colour, spec, shine, normals);
  if (oriented) orient(r, outward, static_cast<float>(hits));
  return r;
}

}  // namespace

void bake(ExplicitHierarchy& h, const BakeConfig& config) {
  const std::size_t n = h.nodes.size();
  const int orientation =
      h.prims.size() <= config.orient_max_triangles ? closed_orientation(h.prims) : 0;
  h.appearances.assign(n, Appearance{});
  // Textured: each primitive's colour, its texture's mean over its coordinates, computed once
  // (every exact bake above it would otherwise average the texture again).
  std::vector<Vec3> colours;
  if (h.textures && !h.textures->empty()) {
    colours.resize(h.prims.size());
    auto fill = [&](std::size_t b, std::size_t e) {
      for (std::size_t p = b; p < e; ++p) colours[p] = h.bake_colour(p);
    };
    if (config.parallel && colours.size() > 4096)
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, colours.size(), 1024),
          [&](const tbb::blocked_range<std::size_t>& r) { fill(r.begin(), r.end()); });
    else
      fill(0, colours.size());
  }
  std::vector<NormalTensor> tensors(n);
  std::vector<std::uint64_t> prims_below(n, 0);
  const std::vector<int> level = node_levels(h.nodes);
  for (std::size_t i = n; i-- > 0;) {
    const ExplicitNode& node = h.nodes[i];
    if (node.leaf) {
      prims_below[i] = node.count;
    } else {
      for (std::uint32_t c = 0; c < node.count; ++c) prims_below[i] += prims_below[node.first + c];
    }
  }
  auto bake_one = [&](std::size_t i) {
    const ExplicitNode& node = h.nodes[i];
    BakeResult r;
    if (node.leaf || prims_below[i] <= static_cast<std::uint64_t>(config.exact_prims)) {
      r = bake_exact(h, static_cast<std::uint32_t>(i), config, orientation, colours);
    } else {
      BakeChild kids[kMaxChildren];
      AMALGAM_CHECK(node.count <= kMaxChildren,
                    "bake: a node with more than kMaxChildren children");
      const int k = node.count;
      for (int c = 0; c < k; ++c)
        kids[c] = {h.nodes[node.first + c].bounds, h.appearances[node.first + c],
                   tensors[node.first + c]};
      r = bake_from_children(node.bounds, std::span<const BakeChild>(kids, k), config.rays,
                             hash_combine(config.seed, i));
    }
    h.appearances[i] = r.app;
    tensors[i] = r.normals;
  };
  for_each_level_bottom_up(level, config.parallel, bake_one);
  h.root_normals = n ? tensors[0] : NormalTensor{};
  build_wide(h);
}

void bake(InstancedHierarchy& h, const BakeConfig& config) {
  h.top_appearances.assign(h.top_nodes.size(), Appearance{});
  std::vector<NormalTensor> tensors(h.top_nodes.size());
  const BakeConfig& bc = config;
  auto bake_one = [&](std::size_t i) {
    const ExplicitNode& node = h.top_nodes[i];
    BakeChild kids[kMaxChildren];
    AMALGAM_CHECK(node.count <= kMaxChildren, "bake: a node with more than kMaxChildren children");
    const int k = node.count;
    for (int c = 0; c < k; ++c) {
      if (node.leaf) {
        const std::uint32_t inst = h.top_items[node.first + c];
        const auto& in = h.instances[inst];
        const NodeId root = InstancedHierarchy::id(inst + 1ull, 0);
        kids[c] = {in.world_bounds, h.appearance(root),
                   in.identity ? h.meshes[in.mesh].root_normals
                               : transform_tensor(h.meshes[in.mesh].root_normals, in.normal_rows)};
      } else {
        kids[c] = {h.top_nodes[node.first + c].bounds, h.top_appearances[node.first + c],
                   tensors[node.first + c]};
      }
    }
    const BakeResult r = bake_from_children(node.bounds, std::span<const BakeChild>(kids, k),
                                            bc.rays, hash_combine(bc.seed ^ 0x70b, i));
    h.top_appearances[i] = r.app;
    tensors[i] = r.normals;
  };
  for_each_level_bottom_up(node_levels(h.top_nodes), config.parallel, bake_one);
}

}  // namespace amalgam

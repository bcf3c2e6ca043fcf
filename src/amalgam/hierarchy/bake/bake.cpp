#include "amalgam/hierarchy/bake/bake.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_sort.h>

#include <algorithm>
#include <bit>
#if defined(__SSE2__)
#include <immintrin.h>
#endif
#include <cstddef>
#include <new>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "amalgam/geometry/intersect.h"
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

/// Room for a node's children as bake_from_children takes them, not initialised (a node has
/// a few of the kMaxChildren it may have: each is constructed in place). BakeChild is trivially
/// destructible.
struct ChildBuffer {
  alignas(BakeChild) std::byte raw[sizeof(BakeChild) * kMaxChildren];
  BakeChild* data() { return reinterpret_cast<BakeChild*>(raw); }
};
static_assert(std::is_trivially_destructible_v<BakeChild>);

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

/// Textured: each primitive's bake colour (its texture's mean over its coordinates, up to
/// 4096 texture samples), computed once per primitive (every exact bake above it would
/// otherwise average the texture again) and once per distinct (material, coordinates): the
/// copies of a small textured mesh that a scene expands instead of instancing share them
/// (scenes/spider-field.json: 262,400 triangles, 1,312 distinct; its bake went from 14.0 s
/// to 0.34 s).
/// Empty when the hierarchy has no textures.
std::vector<Vec3> bake_colours(const ExplicitHierarchy& h, bool parallel) {
  std::vector<Vec3> colours;
  if (!h.textures || h.textures->empty()) return colours;
  const std::size_t n = h.prims.size();
  colours.resize(n);
  auto key_words = [&](std::size_t p, std::uint32_t w[7]) {
    w[0] = h.prims.unpacked(p).material;
    if (h.uvs.empty()) {
      std::fill(w + 1, w + 7, 0u);
      return;
    }
    const TexCoords& c = h.uvs[p];
    for (int i = 0; i < 3; ++i) {
      w[1 + i] = std::bit_cast<std::uint32_t>(c.u[i]);
      w[4 + i] = std::bit_cast<std::uint32_t>(c.v[i]);
    }
  };
  // Primitives ordered by a hash of their key; a run of equal hashes is split by the keys
  // themselves, so a collision only costs a second computation.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order(n);
  auto hash_range = [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) {
      std::uint32_t w[7];
      key_words(p, w);
      std::uint64_t k = 0x636f6c6f;
      for (std::uint32_t x : w) k = hash_combine(k, x);
      order[p] = {k, static_cast<std::uint32_t>(p)};
    }
  };
  const bool par = parallel && n > 4096;
  if (par) {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 4096),
        [&](const tbb::blocked_range<std::size_t>& r) { hash_range(r.begin(), r.end()); });
    tbb::parallel_sort(order.begin(), order.end());
  } else {
    hash_range(0, n);
    std::sort(order.begin(), order.end());
  }
  std::vector<std::size_t> runs;  // starts of the runs of equal hashes, then n
  for (std::size_t i = 0; i < n; ++i)
    if (i == 0 || order[i].first != order[i - 1].first) runs.push_back(i);
  runs.push_back(n);
  auto fill = [&](std::size_t rb, std::size_t re) {
    for (std::size_t r = rb; r < re; ++r) {
      const std::size_t b = runs[r], e = runs[r + 1];
      for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t p = order[i].second;
        std::uint32_t w[7];
        key_words(p, w);
        bool done = false;
        for (std::size_t j = b; j < i && !done; ++j) {  // an earlier one with the same key
          std::uint32_t x[7];
          key_words(order[j].second, x);
          if (std::equal(w, w + 7, x)) colours[p] = colours[order[j].second], done = true;
        }
        if (!done) colours[p] = h.bake_colour(p);
      }
    }
  };
  const std::size_t groups = runs.size() - 1;
  if (par)
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groups, 256),
                      [&](const tbb::blocked_range<std::size_t>& r) { fill(r.begin(), r.end()); });
  else
    fill(0, groups);
  return colours;
}

/// What an exact bake adds for a hit on triangle `p`: its unit normal (its sign does not matter:
/// the bake sums n n^T, bit for bit the same for -n) and, when `orientation` is not 0, its
/// outward normal (none for a degenerate triangle).
struct TriangleBake {
  Vec3 normal, outward;
  bool has_outward = false;
  static TriangleBake of(const Primitive& p, int orientation) {
    TriangleBake t{triangle_normal(p.a, p.b, p.c), {}};
    if (orientation != 0) {
      const Vec3 w = cross(p.b - p.a, p.c - p.a);
      const float len = length(w);
      if (len > 0.0f) t.outward = w * (static_cast<float>(orientation) / len), t.has_outward = true;
    }
    return t;
  }
};

/// Leaves of up to this many primitives have their triangles' normals computed once per bake.
constexpr std::uint32_t kCachedPrims = 8;

/// A leaf of 2 to 4 triangles in SoA form, for a first test of a line against all of them at
/// once: triangle_test's edge functions (the same float operations on the same operands, so
/// the same values) and its first rejection, mixed signs, where none is zero (a zero one is
/// recomputed in double precision by triangle_test: such lanes stay). The lanes left are tested
/// one by one, in order, as before: a rejection does not depend on the ray's tmax, so the
/// closest hit and every bit of the bake are unchanged. Most lines miss most of a leaf's
/// triangles.
struct EdgeFilter {
  alignas(16) float v[3][3][4];  // [vertex][axis][lane]
  unsigned lanes = 0;            // the triangles' lanes; 0: no filter (test them all)

  EdgeFilter(const ExplicitHierarchy& h, const ExplicitNode& n) {
#if defined(__SSE2__)
    if (n.count < 2 || n.count > 4) return;
    for (std::uint32_t k = 0; k < n.count; ++k)
      if (h.prims.unpacked(n.first + k).kind != PrimKind::kTriangle) return;
    for (int lane = 0; lane < 4; ++lane) {
      const Primitive& p = h.prims.unpacked(n.first + std::min<std::uint32_t>(lane, n.count - 1));
      for (int a = 0; a < 3; ++a)
        v[0][a][lane] = p.a[a], v[1][a][lane] = p.b[a], v[2][a][lane] = p.c[a];
    }
    lanes = (1u << n.count) - 1u;
#else
    (void)h, (void)n;
#endif
  }

  /// The lanes that may hit (bit k: the leaf's k-th triangle), or ~0u without a filter.
  unsigned live(const Ray& ray, const TrianglePre& pre) const {
    if (!lanes) return ~0u;
#if defined(__SSE2__)
    const __m128 ox = _mm_set1_ps(ray.origin[pre.kx]), oy = _mm_set1_ps(ray.origin[pre.ky]);
    const __m128 oz = _mm_set1_ps(ray.origin[pre.kz]);
    const __m128 sx = _mm_set1_ps(pre.sx), sy = _mm_set1_ps(pre.sy);
    __m128 x[3], y[3];
    for (int k = 0; k < 3; ++k) {  // A[kx] - sx * A[kz] with A = vertex - origin
      const __m128 z = _mm_sub_ps(_mm_load_ps(v[k][pre.kz]), oz);
      x[k] = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(v[k][pre.kx]), ox), _mm_mul_ps(sx, z));
      y[k] = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(v[k][pre.ky]), oy), _mm_mul_ps(sy, z));
    }
    const __m128 u = _mm_sub_ps(_mm_mul_ps(x[2], y[1]), _mm_mul_ps(y[2], x[1]));
    const __m128 vv = _mm_sub_ps(_mm_mul_ps(x[0], y[2]), _mm_mul_ps(y[0], x[2]));
    const __m128 w = _mm_sub_ps(_mm_mul_ps(x[1], y[0]), _mm_mul_ps(y[1], x[0]));
    const __m128 zero = _mm_setzero_ps();
    const __m128 any_zero =
        _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(vv, zero)), _mm_cmpeq_ps(w, zero));
    const __m128 neg =
        _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(vv, zero)), _mm_cmplt_ps(w, zero));
    const __m128 pos =
        _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(vv, zero)), _mm_cmpgt_ps(w, zero));
    const __m128 reject = _mm_andnot_ps(any_zero, _mm_and_ps(neg, pos));
    return lanes & ~static_cast<unsigned>(_mm_movemask_ps(reject));
#else
    (void)ray, (void)pre;
    return ~0u;
#endif
  }
};

/// Exact bake of node `id`: random lines traced (closest hit) against its subtree.
/// `orientation`: closed_orientation of the hierarchy's primitives (0: triangles have no
/// known outside, so the result is never kOriented when one is hit). `colours`: each
/// primitive's bake colour when the hierarchy is textured (else empty: the materials').
/// kLeaf: the node is a leaf (the common case: no stack, no box tests).
template <bool kLeaf>
BakeResult bake_exact(const ExplicitHierarchy& h, std::uint32_t id, const BakeConfig& cfg,
                      int orientation, const std::vector<Vec3>& colours) {
  const int rays = std::max(cfg.rays, 1);
  const ExplicitNode& top = h.nodes[id];
  const LineSampler lines(top.bounds);
  const std::uint64_t key = hash_combine(cfg.seed, id);
  // A leaf's triangles (the common case) have their normals computed once, not per hit.
  const bool cached = top.leaf && top.count <= kCachedPrims;
  TriangleBake tri[kCachedPrims];
  if (cached)
    for (std::uint32_t k = 0; k < top.count; ++k)
      if (h.prims.unpacked(top.first + k).kind == PrimKind::kTriangle)
        tri[k] = TriangleBake::of(h.prims.unpacked(top.first + k), orientation);
  const EdgeFilter filter = kLeaf ? EdgeFilter(h, top) : EdgeFilter(h, ExplicitNode{});
  Vec3 colour{};
  float spec = 0.0f, shine = 0.0f;
  NormalTensor normals;
  Vec3 outward{};  // sum of the outward normals at the hits
  bool oriented = true;
  int hits = 0;
  std::vector<std::uint32_t> stack;
  for (int r = 0; r < rays; ++r) {
    float u[6];
    line_uniforms(key, r, rays, u);
    Ray ray = lines(u);
    // Closest hit along the line. Triangles: the per-line set-up once, and only the closest
    // one's normal (sign-free, so no SurfaceHit is built for it).
    const TrianglePre pre = TrianglePre::of(ray);
    bool hit = false, hit_triangle = false;
    Vec3 hit_normal{};  // of a sphere or box hit, facing the line
    std::uint32_t best_prim = 0;
    TriangleCandidate best{};  // of the closest triangle: its barycentrics for vertex normals
    auto leaf = [&](const ExplicitNode& n, unsigned live) {
      for (std::uint32_t p = n.first; p < n.first + n.count; ++p) {
        if (!((live >> std::min<std::uint32_t>(p - n.first, 31)) & 1u)) continue;
        const Primitive& prim = h.prims.unpacked(p);
        if (prim.kind == PrimKind::kTriangle) {
          TriangleCandidate c;  // a failed test may leave partial values in it
          if (triangle_test(ray, pre, prim.a, prim.b, prim.c, c)) {
            hit = hit_triangle = true, best_prim = p, best = c;
            ray.tmax = c.t;
          }
        } else if (auto s = intersect(prim, ray)) {
          hit = true, hit_triangle = false, hit_normal = s->normal, best_prim = p;
          ray.tmax = s->t;
        }
      }
    };
    if constexpr (kLeaf) {
      leaf(top, filter.live(ray, pre));
    } else {
      stack.assign(1, id);
    }
    while (!stack.empty()) {
      const ExplicitNode& n = h.nodes[stack.back()];
      stack.pop_back();
      if (!intersect_box(ray, n.bounds)) continue;
      if (n.leaf) {
        leaf(n, ~0u);
      } else {
        for (std::uint32_t c = 0; c < n.count; ++c) stack.push_back(n.first + c);
      }
    }
    if (!hit) continue;
    ++hits;
    const Primitive& bp = h.prims.unpacked(best_prim);
    const Surface& m = h.materials[bp.material];
    colour += colours.empty() ? m.colour : colours[best_prim];
    spec += m.reflectance;
    shine += m.shininess;
    if (!hit_triangle) {
      normals.add(hit_normal, 1.0f);
      outward += hit_normal;  // facing the line, which comes from outside the solid
      continue;
    }
    const TriangleBake t = cached ? tri[best_prim - top.first] : TriangleBake::of(bp, orientation);
    // Smooth triangles bake the normal they are shaded with (interpolated at the hit).
    const Vec3 smooth =
        h.vertex_normals.empty()
            ? Vec3{}
            : interpolate(h.vertex_normals[best_prim], best.v / best.det, best.w / best.det);
    normals.add(smooth == Vec3{} ? t.normal : smooth, 1.0f);
    if (orientation == 0)
      oriented = false;
    else if (t.has_outward)
      outward += t.outward;
  }
  BakeResult r = finish_bake(rays, hits, colour, spec, shine, normals);
  if (oriented) orient(r, outward, static_cast<float>(hits));
  return r;
}

/// Every node's appearance and `h.root_normals`, bottom-up, on the whole form of the primitives.
void bake_appearances(ExplicitHierarchy& h, const BakeConfig& config) {
  const std::size_t n = h.nodes.size();
  // The whole form: the bake reads every primitive many times (build_wide packs them again).
  const std::vector<Primitive>& prims = h.prims.edit();
  const int orientation =
      prims.size() <= config.orient_max_triangles ? closed_orientation(prims) : 0;
  h.appearances.assign(n, Appearance{});
  const std::vector<Vec3> colours = bake_colours(h, config.parallel);
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
      const auto id = static_cast<std::uint32_t>(i);
      r = node.leaf ? bake_exact<true>(h, id, config, orientation, colours)
                    : bake_exact<false>(h, id, config, orientation, colours);
    } else {
      ChildBuffer buf;
      BakeChild* kids = buf.data();
      AMALGAM_CHECK(node.count <= kMaxChildren,
                    "bake: a node with more than kMaxChildren children");
      const int k = node.count;
      for (int c = 0; c < k; ++c)
        new (&kids[c]) BakeChild{h.nodes[node.first + c].bounds, h.appearances[node.first + c],
                                 tensors[node.first + c]};
      r = bake_from_children(node.bounds, std::span<const BakeChild>(kids, k), config.rays,
                             hash_combine(config.seed, i));
    }
    h.appearances[i] = r.app;
    tensors[i] = r.normals;
  };
  for_each_level_bottom_up(level, config.parallel, bake_one);
  h.root_normals = n ? tensors[0] : NormalTensor{};
}

}  // namespace

void bake(ExplicitHierarchy& h, const BakeConfig& config) {
  if (config.appearances) {
    bake_appearances(h, config);
  } else {
    h.appearances.assign(h.nodes.size(), Appearance{});
    h.root_normals = NormalTensor{};
  }
  // After the bake's per-node temporaries are freed: the packing briefly holds the whole
  // primitives, the packs and the slots at once (the build's peak).
  build_wide(h);
}

void bake(InstancedHierarchy& h, const BakeConfig& config) {
  h.top_appearances.assign(h.top_nodes.size(), Appearance{});
  if (!config.appearances) return;
  std::vector<NormalTensor> tensors(h.top_nodes.size());
  const BakeConfig& bc = config;
  auto bake_one = [&](std::size_t i) {
    const ExplicitNode& node = h.top_nodes[i];
    ChildBuffer buf;
    BakeChild* kids = buf.data();
    AMALGAM_CHECK_LE(node.count, kMaxChildren, "bake: a node with more than kMaxChildren children");
    const int k = node.count;
    for (int c = 0; c < k; ++c) {
      if (node.leaf) {
        const std::uint32_t inst = h.top_items[node.first + c];
        const auto& in = h.instances[inst];
        const NodeId root = InstancedHierarchy::id(inst + 1ull, 0);
        new (&kids[c]) BakeChild{
            in.world_bounds, h.appearance(root),
            in.identity ? h.meshes[in.mesh].root_normals
                        : transform_tensor(h.meshes[in.mesh].root_normals, in.normal_rows)};
      } else {
        new (&kids[c]) BakeChild{h.top_nodes[node.first + c].bounds,
                                 h.top_appearances[node.first + c], tensors[node.first + c]};
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

#pragma once
/// \file The traversal, written once: templated on the hierarchy, the level-of-detail policy,
/// the opacity model and the child order. Two entry points, as in pbrt's Intersect /
/// IntersectP: `intersect` (closest hit) and `transmittance` (shadow rays).
///
/// Cost accounting follows the paper: every bounding volume, amalgam and primitive a ray is
/// tested against counts once, on the level of the object tested (root = level 0).
///
/// Child order: sorted tests all children of an entered node, then enters those hit
/// nearest-first and stops as soon as the next entry lies beyond the closest hit (the paper's
/// "examine the bounding volumes in sorted order"); unsorted enters each child as soon as its
/// test succeeds, in stored order.
///
/// Opacity: stochastic decides per (ray, amalgam) with probability = opacity whether the
/// amalgam is fully opaque or fully transparent (a transparent amalgam is passed through, its
/// contents ignored). Deterministic records each rendered translucent amalgam along a closest
/// hit ray (for front-to-back blending by the integrator) and attenuates shadow rays by
/// (1 - opacity) per amalgam crossed.
///
/// Speed (docs/benchmarks.md, "Profiling and optimisation"): the box test is inline; the
/// sorted order keeps only (t, child) per hit child, never a copy of its box (the box is
/// fetched again only when the LOD policy may render on that level); per ray, the
/// watertight triangle setup is done once and a primitive hit's SurfaceHit is built only for
/// the final closest hit. A hierarchy that exposes `wide_nodes()` (ExplicitHierarchy, see
/// hierarchy/wide.h) and `prims` gets, in sorted order, an iterative traversal with an
/// explicit stack that tests all children of a node at once with SIMD, and the triangles of a
/// triangle-only leaf four at a time from SoA packs (same results and counts as testing them
/// one by one). The scalar reference, the original recursive traversal, is
/// ReferenceTraversal (reference.h); the two give the same hits and the same counts
/// (tests/traverse/simd_test.cpp).

#include <algorithm>
#include <bit>
#include <type_traits>
#include <vector>

#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/math/random.h"
#include "amalgam/stats/counters.h"
#include "amalgam/traverse/policies.h"

namespace amalgam {

/// What a closest-hit query found.
struct TraceHit {
  enum class Kind : std::uint8_t { kNone, kPrimitive, kAmalgam };
  Kind kind = Kind::kNone;
  float t = kInfinity;
  std::uint64_t id = 0;  ///< PrimId or NodeId
  int level = 0;
  SurfaceHit surf{};  ///< point, normal facing the ray (box entry face for amalgams)
};

/// A translucent amalgam met by a closest-hit ray under deterministic opacity.
struct TranslucentHit {
  float t;
  NodeId id;
  int level;
  SurfaceHit surf;
  float opacity;
};

enum class OpacityModel : std::uint8_t { kStochastic, kDeterministic };

/// A hierarchy with SoA child boxes (hierarchy/wide.h) and directly addressable primitives:
/// the traversal's fast path. `wide_nodes()` returns null when they are not built.
template <class H>
concept WideHierarchy = requires(const H& h, std::size_t i) {
  { h.wide_nodes() } -> std::same_as<const WideNodes*>;
  { h.prims[i] } -> std::convertible_to<const Primitive&>;
};

/// The two-level instanced hierarchy (hierarchy/instanced.h), detected by its members: the
/// traversal's instanced fast path.
template <class H>
concept InstancedTwoLevel = requires(const H& h, std::size_t i) {
  h.top_nodes[i];
  h.top_items[i];
  h.instances[i].world_bounds;
  h.meshes[i].nodes[i].bounds;
  H::world_box(h.instances[i], h.meshes[i].nodes[i].bounds);
};

/// `Stats` is Counters (exact counts) or NullCounters (counting compiled out, to measure the
/// counters' own overhead).
template <Hierarchy H, class Lod, OpacityModel kOpacity, bool kSorted, class Stats = Counters>
class Traversal {
 public:
  Traversal(const H& h, const Lod& lod, Stats& counters) : h_(h), lod_(lod), counters_(counters) {}

  /// Closest hit along `ray`. `key` seeds this ray's stochastic decisions. Under
  /// deterministic opacity, translucent amalgams in front of the returned hit are appended to
  /// `*translucent` in the order met (the caller sorts them by t).
  TraceHit intersect(const Ray& ray, std::uint64_t key,
                     std::vector<TranslucentHit>* translucent = nullptr) {
    start(ray, key, RayKind::kPrimary, false);
    translucent_ = translucent;
    run();
    if (pending_) finish_pending();
    if (translucent_) {
      const float t_hit = hit_.t;
      std::erase_if(*translucent_, [t_hit](const TranslucentHit& h) { return h.t >= t_hit; });
    }
    return hit_;
  }

  /// Fraction of light that passes along `ray` (0: occluded). Counts one shadow ray.
  float transmittance(const Ray& ray, std::uint64_t key) {
    start(ray, key, RayKind::kShadow, true);
    translucent_ = nullptr;
    run();
    return transmittance_;
  }

 private:
  /// Whether the LOD policy can ever render (TraditionalLod never does: no box is needed
  /// after a node's own test).
  static constexpr bool kMayRender = !std::is_same_v<Lod, TraditionalLod>;
  static constexpr bool kWide = WideHierarchy<H> && kSorted;
  static constexpr bool kInstancedFast = InstancedTwoLevel<H> && kSorted;

  void start(const Ray& ray, std::uint64_t key, RayKind kind, bool any_hit) {
    ray_ = ray;
    key_ = key;
    kind_ = kind;
    any_hit_ = any_hit;
    done_ = false;
    pending_ = false;
    hit_ = TraceHit{};
    transmittance_ = 1.0f;
    counters_.count_ray(kind);
  }

  void run() {
    const NodeId root = h_.root();
    const Bbox b = h_.bounds(root);
    counters_.count_test(kind_, object_kind(0), 0);
    float t0, t1;
    if (!intersect_box(ray_, b, t0, t1)) return;
    if constexpr (kWide) {
      if (const WideNodes* w = h_.wide_nodes()) {
        run_wide(*w, static_cast<std::uint32_t>(root), t0);
        return;
      }
    }
    if constexpr (kInstancedFast) {
      run_instanced(root, t0);
      return;
    }
    enter(root, 0, b, t0);
  }

  ObjectKind object_kind(int level) const {
    return lod_.may_render(level) ? ObjectKind::kAmalgam : ObjectKind::kBoundingVolume;
  }

  /// A node whose box the ray meets at t_entry: render it or descend. `b` is its box (only
  /// read when the LOD policy may render).
  void enter(NodeId id, int level, const Bbox& b, float t_entry) {
    if (t_entry > ray_.tmax) return;  // a closer hit was found since this node was tested
    if constexpr (kMayRender) {
      if (lod_.may_render(level) &&
          lod_.render(b, level, ray_, t_entry, t_entry <= ray_.tmin && b.contains(ray_.origin))) {
        render(id, level, b, t_entry);
        return;
      }
    }
    visit(id, level);
  }

  /// The generic path (any hierarchy; recursive).
  void visit(NodeId node, int level) {
    const int cl = level + 1;
    struct Entry {
      float t;
      int slot;  ///< index into `boxes` (kept unsorted)
      NodeId id;
    };
    Entry entries[kSorted ? kMaxChildren : 1];
    Bbox boxes[kSorted && kMayRender ? kMaxChildren : 1];
    int n = 0;
    h_.for_each_child(node, [&](Child ch) {
      if (ch.is_primitive) {
        counters_.count_test(kind_, ObjectKind::kPrimitive, cl);
        if (auto s = h_.intersect(ch.id, ray_)) on_primitive(ch.id, cl, *s);
        return !done_;
      }
      const Bbox b = h_.bounds(ch.id);
      counters_.count_test(kind_, object_kind(cl), cl);
      float t0, t1;
      if (!intersect_box(ray_, b, t0, t1)) return true;
      if constexpr (kSorted) {
        const int slot = n;
        if constexpr (kMayRender) boxes[slot] = b;
        int i = n++;  // insertion sort, stable for equal t
        while (i > 0 && entries[i - 1].t > t0) entries[i] = entries[i - 1], --i;
        entries[i] = Entry{t0, slot, ch.id};
        return true;
      } else {
        enter(ch.id, cl, b, t0);
        return !done_;
      }
    });
    if constexpr (kSorted) {
      for (int i = 0; i < n && !done_; ++i) {
        if (entries[i].t > ray_.tmax) break;  // every later entry is farther still
        enter(entries[i].id, cl, boxes[kMayRender ? entries[i].slot : 0], entries[i].t);
      }
    }
  }

  struct StackItem {
    float t;
    std::uint32_t node;
    int level;
  };

  /// The fast path: sorted order over SoA child boxes, iterative with an explicit stack.
  /// Pushing a node's hit children farthest-first makes the pops the same depth-first,
  /// nearest-first order as the recursion in `visit`; a popped entry beyond the closest hit
  /// is skipped, as `visit` breaks there (every later sibling is farther still). The stack is
  /// `stack_[0, sp)`, grown before a node's children are pushed (not per push).
  void run_wide(const WideNodes& w, std::uint32_t root, float t_root) {
    if (stack_.size() < 64) stack_.resize(64);
    stack_[0] = {t_root, root, 0};
    // A ray with a zero direction component needs the box test's containment branch per
    // axis; all others (nearly every ray) run a loop without those branches.
    if (ray_.dir.x == 0.0f || ray_.dir.y == 0.0f || ray_.dir.z == 0.0f)
      wide_loop<true>(w);
    else
      wide_loop<false>(w);
  }

  template <bool kZeroAxes>
  void wide_loop(const WideNodes& w) {
    // The per-ray constants and the stack's base and capacity as locals: members would be
    // reloaded after every store to the stack (a float store may alias them).
    const WideRay wr = WideRay::of(ray_);
    tri_ = wr.pre;  // for the primitives of mixed leaves (`primitive_wide`)
    StackItem* s = stack_.data();
    std::size_t cap = stack_.size(), sp = 1;
    while (sp > 0 && !done_) {
      const StackItem it = s[--sp];
      if (it.t > ray_.tmax) continue;
      if constexpr (kMayRender) {
        if (lod_.may_render(it.level)) {
          const Bbox b = h_.bounds(it.node);
          if (lod_.render(b, it.level, ray_, it.t, it.t <= ray_.tmin && b.contains(ray_.origin))) {
            render(it.node, it.level, b, it.t);
            continue;
          }
        }
      }
      expand_wide<kZeroAxes>(w, wr, it.node, it.level, s, cap, sp);
    }
  }

  /// Always inlined into the pop loop of `wide_loop`: as a call per node it cost register
  /// saves and restores and the box kernel's per-ray constants were set up again for every
  /// node (inlining it, with the pushes straight onto the stack below, took the engine primary
  /// rays from 2 578 to 2 133 instructions per ray; docs/benchmarks.md).
  template <bool kZeroAxes>
  [[gnu::always_inline]] void expand_wide(const WideNodes& w, const WideRay& wr, std::uint32_t node,
                                          int level, StackItem*& s, std::size_t& cap,
                                          std::size_t& sp) {
    const WideHeader hd = w.headers[node];
    const int cl = level + 1;
    const int count = hd.count;
    if (hd.leaf == kWideTriangleLeaf) {
      leaf_triangles(w, wr, hd, cl);
      return;
    }
    if (hd.leaf) {
      for (int i = 0; i < count; ++i) {
        counters_.count_test(kind_, ObjectKind::kPrimitive, cl);
        primitive_wide(hd.first + static_cast<std::uint32_t>(i), cl);
        if (done_) return;
      }
      return;
    }
    const ObjectKind ok = object_kind(cl);
    for (int i = 0; i < count; ++i) counters_.count_test(kind_, ok, cl);
    if (sp + count > cap) {
      stack_.resize(2 * cap + count);
      s = stack_.data(), cap = stack_.size();
    }
    // The hit children go straight onto the stack, insertion-sorted farthest first (the
    // nearest is popped first). A later child (stored order) goes below the hits with equal
    // t, so that among equals the first in stored order is popped first, as the recursion
    // enters them (stable sort).
    const std::size_t base = sp;
    auto collect = [&](unsigned mask, const float* t, int c0) {
      for (; mask; mask &= mask - 1) {
        const int lane = std::countr_zero(mask);
        const float te = t[lane];  // never NaN: a NaN entry fails the kernel's t0 <= t1
        std::size_t i = sp++;
        while (i > base && s[i - 1].t <= te) s[i] = s[i - 1], --i;
        s[i] = {te, hd.first + static_cast<std::uint32_t>(c0 + lane), cl};
      }
    };
    const WideBox4* blk = w.blocks.data() + hd.block;
    int c0 = 0;
#if AMALGAM_WIDE_SSE && defined(__AVX2__)
    for (; count - c0 > kWideLanes; c0 += 2 * kWideLanes, blk += 2) {
      alignas(32) float t[2 * kWideLanes];
      const int m = std::min(count - c0, 2 * kWideLanes);
      collect(intersect_wide8<kZeroAxes>(blk[0], blk[1], wr, ray_.tmin, ray_.tmax, m, t), t, c0);
    }
#endif
    for (; c0 < count; c0 += kWideLanes, ++blk) {
      alignas(16) float t[kWideLanes];
      const int m = std::min(count - c0, kWideLanes);
      collect(intersect_wide4<kZeroAxes>(*blk, wr, ray_.tmin, ray_.tmax, m, t), t, c0);
    }
  }

  /// A triangle-only leaf, four triangles at a time (`triangle_test4`), with the results and
  /// counts of the one-by-one loop in `expand_wide`: there, a triangle is tested against the
  /// tmax left by the hits before it, so of the lanes hit (all tested against the same tmax)
  /// a lane is taken in leaf order when its t is still <= tmax (ties: the later one, as
  /// there); a shadow ray stops at the first hit in leaf order, having tested the triangles
  /// up to and including it.
  void leaf_triangles(const WideNodes& w, const WideRay& wr, const WideHeader& hd, int level) {
    const TrianglePack4* pack = w.tris.data() + hd.block;
    const int count = hd.count;
    for (int c0 = 0; c0 < count; c0 += kWideLanes, ++pack) {
      const int m = std::min(count - c0, kWideLanes);
      TrianglePackHits c;
      unsigned mask = triangle_test4(*pack, wr, ray_.tmin, ray_.tmax, m, c);
      if (any_hit_ && mask) {
        const int tested = std::countr_zero(mask) + 1;
        for (int i = 0; i < tested; ++i) counters_.count_test(kind_, ObjectKind::kPrimitive, level);
        transmittance_ = 0.0f;
        done_ = true;
        return;
      }
      for (int i = 0; i < m; ++i) counters_.count_test(kind_, ObjectKind::kPrimitive, level);
      for (; mask; mask &= mask - 1) {
        const int lane = std::countr_zero(mask);
        if (!(c.t[lane] <= ray_.tmax)) continue;  // an earlier lane hit closer
        ray_.tmax = c.t[lane];
        hit_.kind = TraceHit::Kind::kPrimitive;
        hit_.t = c.t[lane];
        hit_.id = hd.first + static_cast<std::uint32_t>(c0 + lane);
        hit_.level = level;
        pending_ = true;
        cand_ = c.lane(lane);
      }
    }
  }

  /// One primitive test on the fast path: triangles with the per-ray setup and a deferred
  /// SurfaceHit; other kinds through the full kernel (as ExplicitHierarchy::intersect).
  void primitive_wide(std::uint32_t id, int level) {
    const Primitive& p = h_.prims[id];
    if (p.kind == PrimKind::kTriangle) {
      TriangleCandidate c;
      if (!triangle_test(ray_, tri_, p.a, p.b, p.c, c)) return;
      if (any_hit_) {
        transmittance_ = 0.0f;
        done_ = true;
        return;
      }
      ray_.tmax = c.t;
      hit_.kind = TraceHit::Kind::kPrimitive;
      hit_.t = c.t;
      hit_.id = id;
      hit_.level = level;
      pending_ = true;
      cand_ = c;
      return;
    }
    if (auto s = amalgam::intersect(p, ray_)) on_primitive(id, level, *s);
  }

  /// Builds the SurfaceHit of the closest hit when it is a deferred triangle.
  void finish_pending() {
    if constexpr (WideHierarchy<H>) {
      const Primitive& p = h_.prims[hit_.id];
      hit_.surf = triangle_finish(ray_, p.a, p.b, p.c, cand_);
    }
    pending_ = false;
  }

  void on_primitive(PrimId id, int level, const SurfaceHit& s) {
    if (any_hit_) {
      transmittance_ = 0.0f;
      done_ = true;
      return;
    }
    ray_.tmax = s.t;
    pending_ = false;
    hit_ = TraceHit{TraceHit::Kind::kPrimitive, s.t, id, level, s};
  }

  void render(NodeId id, int level, const Bbox& b, float t) {
    // The probability that this ray, in its direction, meets the contents (bake.h).
    const float a = directional_opacity(h_.appearance(id), b, ray_.dir);
    bool opaque;
    if constexpr (kOpacity == OpacityModel::kStochastic) {
      opaque = to_unit_float(hash_combine(key_, id)) < a;
    } else {
      opaque = a >= 1.0f;
      if (!opaque) {
        if (a <= 0.0f) return;
        if (any_hit_) {
          transmittance_ *= 1.0f - a;
        } else if (translucent_) {
          translucent_->push_back({t, id, level, box_entry_hit(ray_, b, t), a});
        }
        return;
      }
    }
    if (!opaque) return;
    if (any_hit_) {
      transmittance_ = 0.0f;
      done_ = true;
      return;
    }
    ray_.tmax = t;
    pending_ = false;
    hit_ = TraceHit{TraceHit::Kind::kAmalgam, t, id, level, box_entry_hit(ray_, b, t)};
  }

  /// The instanced fast path (sorted order): iterative like run_wide, the children of a node
  /// tested four at a time with the SIMD slab kernel. Their boxes are gathered: top-level
  /// nodes' and instance roots' world boxes as stored, and, inside an instance, the world box
  /// of each child's transformed box computed four at a time (`world_boxes4`) with the float
  /// operations of InstancedHierarchy::world_box in the same order, so that every test, count
  /// and order is the generic path's (tests/traverse/simd_test.cpp compares them).
  ///
  /// The LOD decision (render or descend) depends only on the box, the level, the entry t and
  /// the ray's cone, none of which change while the ray is traced, so it is taken when a
  /// child is pushed, with its box at hand, instead of recomputing the world box when popped.
  void run_instanced(NodeId root, float t_root) {
    const WideRay wr = WideRay::of(ray_);
    istack_.clear();
    istack_.push_back({t_root, 0, decide(h_.bounds(root), 0, t_root), root});
    while (!istack_.empty() && !done_) {
      const InstItem it = istack_.back();
      istack_.pop_back();
      if (it.t > ray_.tmax) continue;
      if constexpr (kMayRender) {
        if (it.render) {
          render(it.node, it.level, h_.bounds(it.node), it.t);
          continue;
        }
      }
      expand_instanced(wr, it.node, it.level);
    }
  }

  bool decide(const Bbox& b, int level, float t) const {
    if constexpr (kMayRender) {
      return lod_.may_render(level) &&
             lod_.render(b, level, ray_, t, t <= ray_.tmin && b.contains(ray_.origin));
    }
    return false;
  }

  void expand_instanced(const WideRay& wr, NodeId node, int level) {
    const int cl = level + 1;
    const std::uint64_t slot = H::slot(node);
    WideBox4 blk[kMaxChildren / kWideLanes + 1];
    NodeId ids[kMaxChildren];
    int count;
    if (slot == 0) {
      const auto& t = h_.top_nodes[node];
      count = static_cast<int>(t.count);
      for (int i = 0; i < count; ++i) {
        const Bbox* b;
        if (t.leaf) {
          const std::uint32_t inst = h_.top_items[t.first + i];
          ids[i] = H::id(inst + 1ull, 0);
          b = &h_.instances[inst].world_bounds;
        } else {
          ids[i] = t.first + static_cast<std::uint32_t>(i);
          b = &h_.top_nodes[t.first + i].bounds;
        }
        put_box(blk, i, *b);
      }
    } else {
      const auto& in = h_.instances[slot - 1];
      const auto& mesh = h_.meshes[in.mesh];
      const auto& e = mesh.nodes[H::local(node)];
      count = static_cast<int>(e.count);
      if (e.leaf) {
        for (int i = 0; i < count; ++i) {
          counters_.count_test(kind_, ObjectKind::kPrimitive, cl);
          const PrimId p = H::id(slot, e.first + static_cast<std::uint32_t>(i));
          if (auto s = h_.intersect(p, ray_)) on_primitive(p, cl, *s);
          if (done_) return;
        }
        return;
      }
      for (int i = 0; i < count; ++i) {
        ids[i] = H::id(slot, e.first + static_cast<std::uint32_t>(i));
        put_box(blk, i, mesh.nodes[e.first + i].bounds);
      }
      if (!in.identity) {
        for (int c0 = 0; c0 < count; c0 += kWideLanes)
          world_boxes4(in, blk[c0 / kWideLanes], std::min(count - c0, kWideLanes));
      }
    }
    const ObjectKind ok = object_kind(cl);
    for (int i = 0; i < count; ++i) counters_.count_test(kind_, ok, cl);
    const bool may_render = kMayRender && lod_.may_render(cl);
    InstItem hits[kMaxChildren];
    int n = 0;
    for (int c0 = 0; c0 < count; c0 += kWideLanes) {
      alignas(16) float t[kWideLanes];
      unsigned mask = intersect_wide4(blk[c0 / kWideLanes], wr, ray_.tmin, ray_.tmax,
                                      std::min(count - c0, kWideLanes), t);
      while (mask) {
        const int lane = std::countr_zero(mask);
        mask &= mask - 1;
        const float te = t[lane];
        int i = n++;  // insertion sort, stable for equal t (lanes come in stored order)
        while (i > 0 && hits[i - 1].t > te) hits[i] = hits[i - 1], --i;
        const WideBox4& w = blk[c0 / kWideLanes];
        const bool r = may_render && decide(Bbox{{w.lo[0][lane], w.lo[1][lane], w.lo[2][lane]},
                                                 {w.hi[0][lane], w.hi[1][lane], w.hi[2][lane]}},
                                            cl, te);
        hits[i] = {te, static_cast<std::int16_t>(cl), r, ids[c0 + lane]};
      }
    }
    for (int i = n; i-- > 0;) istack_.push_back(hits[i]);
  }

  static void put_box(WideBox4* blk, int i, const Bbox& b) {
    WideBox4& w = blk[i / kWideLanes];
    const int l = i % kWideLanes;
    w.lo[0][l] = b.lo.x, w.lo[1][l] = b.lo.y, w.lo[2][l] = b.lo.z;
    w.hi[0][l] = b.hi.x, w.hi[1][l] = b.hi.y, w.hi[2][l] = b.hi.z;
  }

  /// Replaces the first `n` object-space boxes of `w` by InstancedHierarchy::world_box of each
  /// (empty boxes stay as they are, as there).
  template <class Instance>
  static void world_boxes4(const Instance& in, WideBox4& w, int n) {
#if AMALGAM_WIDE_SSE
    bool any_empty = false;
    for (int l = 0; l < n; ++l)
      any_empty |= w.lo[0][l] > w.hi[0][l] || w.lo[1][l] > w.hi[1][l] || w.lo[2][l] > w.hi[2][l];
    if (!any_empty) {
      const __m128 half = _mm_set1_ps(0.5f);
      const __m128 sign = _mm_set1_ps(-0.0f);
      const __m128 k = _mm_set1_ps(4.0f * gamma(3));
      __m128 c[3], h[3];
      for (int a = 0; a < 3; ++a) {
        const __m128 lo = _mm_load_ps(w.lo[a]), hi = _mm_load_ps(w.hi[a]);
        c[a] = _mm_mul_ps(_mm_add_ps(lo, hi), half);  // Bbox::center
        h[a] = _mm_mul_ps(_mm_sub_ps(hi, lo), half);  // Bbox::extent() * 0.5f
      }
      for (int r = 0; r < 3; ++r) {
        const float* m = in.to_world.m[r];
        // Transform::point: ((m0 x + m1 y) + m2 z) + m3.
        __m128 cw = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(m[0]), c[0]),
                                                     _mm_mul_ps(_mm_set1_ps(m[1]), c[1])),
                                          _mm_mul_ps(_mm_set1_ps(m[2]), c[2])),
                               _mm_set1_ps(m[3]));
        // dot(abs_rows[r], h): (x + y) + z.
        const Vec3 ar = in.abs_rows[r];
        __m128 rw = _mm_add_ps(
            _mm_add_ps(_mm_mul_ps(_mm_set1_ps(ar.x), h[0]), _mm_mul_ps(_mm_set1_ps(ar.y), h[1])),
            _mm_mul_ps(_mm_set1_ps(ar.z), h[2]));
        // r += (|c| + r) * 4 gamma(3)
        rw = _mm_add_ps(rw, _mm_mul_ps(_mm_add_ps(_mm_andnot_ps(sign, cw), rw), k));
        _mm_store_ps(w.lo[r], _mm_sub_ps(cw, rw));
        _mm_store_ps(w.hi[r], _mm_add_ps(cw, rw));
      }
      return;
    }
#endif
    for (int l = 0; l < n; ++l) {
      const Bbox b = H::world_box(
          in, Bbox{{w.lo[0][l], w.lo[1][l], w.lo[2][l]}, {w.hi[0][l], w.hi[1][l], w.hi[2][l]}});
      w.lo[0][l] = b.lo.x, w.lo[1][l] = b.lo.y, w.lo[2][l] = b.lo.z;
      w.hi[0][l] = b.hi.x, w.hi[1][l] = b.hi.y, w.hi[2][l] = b.hi.z;
    }
  }

  struct InstItem {
    float t;
    std::int16_t level;  ///< below 2^15: node ids hold at most 64 bits of levels
    bool render;         ///< the LOD policy renders it (decided when pushed)
    NodeId node;
  };

  const H& h_;
  Lod lod_;
  Stats& counters_;
  Ray ray_;
  std::uint64_t key_ = 0;
  RayKind kind_ = RayKind::kPrimary;
  bool any_hit_ = false;
  bool done_ = false;
  TraceHit hit_;
  float transmittance_ = 1.0f;
  std::vector<TranslucentHit>* translucent_ = nullptr;
  // Fast path state.
  bool pending_ = false;  ///< hit_ is a triangle whose SurfaceHit is not built yet
  TriangleCandidate cand_{};
  TrianglePre tri_{};
  std::vector<StackItem> stack_;
  std::vector<InstItem> istack_;  ///< the instanced fast path's stack
};

}  // namespace amalgam

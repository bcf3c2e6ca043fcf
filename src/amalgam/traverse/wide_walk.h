#pragma once
/// \file The node source (walk.h) of an explicit hierarchy, sorted order: all children of a
/// node tested at once from their SoA boxes (hierarchy/wide.h, geometry/wide_kernels.h), and
/// the triangles of a triangle-only leaf four at a time from SoA packs, with the hits and counts
/// of the scalar reference (tests/traverse/simd_test.cpp).
///
/// Speed: per ray, the watertight triangle setup is done once and a primitive hit's SurfaceHit is
/// built only for the final closest hit; a node's box is fetched again only when the LOD policy may
/// render on its level.

#include <algorithm>
#include <bit>
#include <concepts>
#include <vector>

#include "amalgam/geometry/wide_kernels.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/traverse/state.h"
#include "amalgam/traverse/walk.h"

namespace amalgam {

/// A hierarchy with SoA child boxes (hierarchy/wide.h) and directly addressable primitives:
/// the traversal's fast path. `wide_nodes()` returns null when they are not built.
template <class H>
concept WideHierarchy = requires(const H& h, std::size_t i, Vec3& a) {
  { h.wide_nodes() } -> std::same_as<const WideNodes*>;
  { h.prims[i] } -> std::convertible_to<Primitive>;
  { h.prims.packs().data() } -> std::convertible_to<const TrianglePack4*>;
  h.prims.triangle(i, a, a, a);
};

AMALGAM_ISA_BEGIN

/// The triangles of a triangle-only leaf, tested from their SoA packs against the ray `wr`
/// (the ray in the leaf's own space: the instanced walk passes the object-space ray) over
/// the state's [tmin, tmax]: shared by the explicit and the instanced walk.
template <class State>
struct PackLeaf {
  /// A triangle-only leaf (primitives `first_of()` ..., asked for only when a lane hit is taken:
  /// a one-pack leaf's reference does not carry it), four triangles at a time
  /// (`triangle_test4`; eight, from two packs, in the AVX2 copy), with the results and counts
  /// of the one-by-one loop: there, a triangle is tested against the tmax left by the hits
  /// before it, so of the lanes hit (all tested against the same tmax) a lane is taken in leaf
  /// order when its t is still <= tmax (ties: the later one, as there); a shadow ray stops at
  /// the first hit in leaf order, having tested the triangles up to and including it.
  template <class FirstOf>
  [[gnu::always_inline]] static void test(State& s, const TrianglePack4* pack, const WideRay& wr,
                                          const FirstOf& first, int count, int level) {
    if (count <= kWideLanes) {  // one pack (the default leaves): no loop to set up
      TrianglePackHits c;
      take(s, first, level, 0, count, triangle_test4(*pack, wr, s.ray.tmin, s.ray.tmax, count, c),
           c);
      return;
    }
    int c0 = 0;
#if AMALGAM_WIDE_SSE && defined(AMALGAM_ISA_AVX2)
    for (; count - c0 > kWideLanes; c0 += 2 * kWideLanes, pack += 2) {
      TrianglePackHitsN<2 * kWideLanes> c;
      const int m = std::min(count - c0, 2 * kWideLanes);
      if (!take(s, first, level, c0, m,
                triangle_test_lanes<Lanes8>(pack, wr, s.ray.tmin, s.ray.tmax, m, c), c))
        return;
    }
#endif
    for (; c0 < count; c0 += kWideLanes, ++pack) {
      TrianglePackHits c;
      const int m = std::min(count - c0, kWideLanes);
      if (!take(s, first, level, c0, m, triangle_test4(*pack, wr, s.ray.tmin, s.ray.tmax, m, c), c))
        return;
    }
  }

  /// The lanes `mask` of a pack test of `m` triangles from `c0` of the leaf: counts them and
  /// takes the hits as the one-by-one loop would. False when the ray is done (a shadow ray
  /// occluded).
  template <class FirstOf, class Hits>
  [[gnu::always_inline]] static bool take(State& s, const FirstOf& first, int level, int c0, int m,
                                          unsigned mask, const Hits& c) {
    s.count_pack(level, m, mask);
    if (s.any_hit && mask) {
      s.occlude();
      return false;
    }
    for (; mask; mask &= mask - 1) {
      const int lane = std::countr_zero(mask);
      if (!(c.t[lane] <= s.ray.tmax)) continue;  // an earlier lane hit closer
      s.on_triangle(first() + static_cast<PrimId>(c0 + lane), level, c.lane(lane));
    }
    return true;
  }
};

/// The node source of an explicit hierarchy in SIMD form (walk.h): a node's children tested
/// at once from their SoA boxes, a triangle-only leaf's triangles from their packs.
template <class State>
class ExplicitSource {
 public:
  struct Item {
    float t;
    WideRef ref;  ///< the node (hierarchy/wide.h)
    int level;
  };
  using Root = WideNodes;
  static constexpr bool kBoxKernel = true;

  /// The per-ray constants and the node arrays' bases, as the loop's locals (read through
  /// `WideNodes`, the bases were loaded again at every node: a store to the stack may alias
  /// them); the leaves' headers, read only for leaves that are not one-pack leaves, through
  /// `nodes`.
  struct RayConstants {
    WideRay wr;
    const unsigned char* pool;
    const TrianglePack4* tris;
    const WideNodes* nodes;
  };

  RayConstants begin(const State& s, const WideNodes& w) const {
    return {WideRay::of(s.ray), w.pool_bytes(), s.h.prims.packs().data(), &w};
  }
  static Item root_item(const WideNodes& w, float t) { return {t, w.root, 0}; }
  static NodeId node_id(const State&, const RayConstants& rc, const Item& it) {
    return rc.nodes->node_of(it.ref);
  }

  /// Builds the SurfaceHit of the closest hit when it is a deferred triangle.
  static void finish(State& s) {
    Vec3 a, b, c;
    s.h.prims.triangle(s.hit.id, a, b, c);
    s.hit.surf = triangle_finish(s.ray, a, b, c, s.cand);
    s.pending = false;
  }

  /// Pushing a node's hit children farthest-first makes the pops the same depth-first,
  /// nearest-first order as the recursion of the reference (reference.h); a popped entry
  /// beyond the closest hit is skipped, as the recursion breaks there (every later sibling is
  /// farther still). The nearest hit child is not pushed: the walk goes on with it at once
  /// (what the pop right after the pushes would have given: its entry is <= tmax, as the box
  /// test checked, and nothing between its test and its entry changes tmax or `done`), so a
  /// node with one hit child costs no stack traffic.
  ///
  /// Always inlined into the loop, with the pushes straight onto the stack: as a call per node
  /// it would save and restore registers and set up the box kernel's per-ray constants again
  /// for every node. An interior node is read from its reference alone: the record's address
  /// and the lanes in use come from it, the children's references from the record, beside
  /// their boxes.
  template <BoxRays kRays>
  [[gnu::always_inline]] Next expand(State& s, const RayConstants& w, Item& it,
                                     WalkStack<Item>& st) const {
    const WideRay& wr = w.wr;
    const WideRef ref = it.ref;
    const int cl = it.level + 1;
    if (ref & kWideRefLeaf) {
      // A one-pack leaf (the default leaves) from its reference alone, another leaf from its
      // header (WideNodes::leaf_header). One call of the pack test for both (two inlined copies
      // made the loop a third larger and small scenes 5-15 % slower).
      const WideHeader hd = w.nodes->leaf_header(ref);
      if (hd.leaf == kWideTriangleLeaf) [[likely]] {
        PackLeaf<State>::test(
            s, w.tris + hd.block, wr, [&] { return PrimId{w.nodes->leaf_first(ref, hd)}; },
            hd.count, cl);
        return s.done ? Next::kStop : Next::kPop;
      }
      for (int i = 0; i < hd.count; ++i) {
        s.count_primitives(cl);
        primitive(s, wr.pre, hd.first + static_cast<std::uint32_t>(i), cl);
        if (s.done) return Next::kStop;
      }
      return Next::kPop;
    }
    const int count = static_cast<int>(ref & 15u);
    if (count > kBoxLanes) [[unlikely]]
      return many<kRays>(s, w, it, st, cl);
    const WideRecord rec = WideRecord::at(w.pool, ref);
    s.count_children(cl, count);
    // One kernel call for the whole node: a single hit child is entered at once, without
    // touching the stack.
    alignas(32) float t[kBoxLanes];
    const unsigned mask = box_test_block<kRays>(rec.boxes(), wr, s.ray.tmin, s.ray.tmax, count, t);
    if (mask == 0) return Next::kPop;
    const int l0 = std::countr_zero(mask);
    const unsigned rest = mask & (mask - 1);
    if (rest == 0) {
      it = {t[l0], rec.child(l0), cl};
      return Next::kEnter;
    }
    st.reserve(st.sp + kBoxLanes);
    if ((rest & (rest - 1)) == 0) {  // two hits: one comparison (ties: the first in order)
      const int l1 = std::countr_zero(rest);
      const bool second = t[l1] < t[l0];
      const int near = second ? l1 : l0, far = second ? l0 : l1;
      st.st[st.sp++] = {t[far], prefetched(w, rec.child(far)), cl};
      it = {t[near], rec.child(near), cl};
      return Next::kEnter;
    }
    push_sorted(w, st, st.sp, mask, t, rec, cl);
    it = st.st[--st.sp];
    return Next::kEnter;
  }

 private:
  /// Child reference `c`, its record prefetched when it is an interior node: a child pushed is
  /// entered later, if at all. The nearest child, entered at once, gains nothing from it.
  [[gnu::always_inline]] static WideRef prefetched(const RayConstants& w, WideRef c) {
    if (!(c & kWideRefLeaf)) {
      const unsigned char* p = WideRecord::at(w.pool, c).base;
      __builtin_prefetch(p), __builtin_prefetch(p + 64), __builtin_prefetch(p + 128),
          __builtin_prefetch(p + 192);
    }
    return c;
  }

  /// A node of more than 8 children: its consecutive records, each tested and pushed, the
  /// nearest hit child then entered.
  template <BoxRays kRays>
  static Next many(State& s, const RayConstants& w, Item& it, WalkStack<Item>& st, int cl) {
    const int count = w.nodes->child_count(it.ref);
    s.count_children(cl, count);
    st.reserve(st.sp + static_cast<std::size_t>(count));
    const std::size_t base = st.sp;
    WideRecord rec = w.nodes->record(it.ref);
    for (int c0 = 0; c0 < count; c0 += kBoxLanes, rec = rec.next()) {
      alignas(32) float t[kBoxLanes];
      const int m = std::min(count - c0, kBoxLanes);
      push_sorted(w, st, base,
                  box_test_block<kRays>(rec.boxes(), w.wr, s.ray.tmin, s.ray.tmax, m, t), t, rec,
                  cl);
    }
    if (st.sp == base) return Next::kPop;
    it = st.st[--st.sp];
    return Next::kEnter;
  }

  /// Pushes the lanes of `mask` (children `rec.child(lane)`, entered at `t[lane]`) above
  /// `base` (state.h, `push_sorted`), each interior child's record prefetched: the one push of
  /// both a node's three or more hit children and the records of a node of more than 8.
  [[gnu::always_inline]] static void push_sorted(const RayConstants& w, WalkStack<Item>& st,
                                                 std::size_t base, unsigned mask, const float* t,
                                                 const WideRecord& rec, int level) {
    amalgam::push_sorted(st.st, st.sp, base, mask, t, [&](int lane) {
      return Item{0, prefetched(w, rec.child(lane)), level};
    });
  }

  /// One primitive of a mixed leaf: triangles with the per-ray setup and a deferred
  /// SurfaceHit; other kinds through the full kernel (as ExplicitHierarchy::intersect).
  static void primitive(State& s, const TrianglePre& pre, std::uint32_t id, int level) {
    const Primitive p = s.h.prims[id];
    if (p.kind == PrimKind::kTriangle) {
      TriangleCandidate c;
      if (triangle_test(s.ray, pre, p.a, p.b, p.c, c)) s.on_triangle(id, level, c);
      return;
    }
    if (auto hit = amalgam::intersect(p, s.ray)) s.on_primitive(id, level, *hit);
  }
};

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file The node source (walk.h) of the two-level instanced hierarchy, sorted order: as
/// wide_walk.h's, over the top tree's SoA blocks (`InstancedHierarchy::top_wide`) and, inside an
/// instance, over its mesh's own `WideNodes`, shared by every instance of the mesh.
///
/// The ray stays in world space. A node inside an instance has as children's boxes the world
/// boxes of their transformed boxes (`InstancedHierarchy::world_box`), computed at each visit
/// for the whole node at once (eight lanes in the AVX2 copy) with world_box's float operations
/// in its order, so the boxes, entries, order and counts are the reference's
/// (tests/traverse/simd_test.cpp compares them with the scalar reference). A leaf's triangles
/// are tested from the mesh's packs against the ray taken into the instance's object space
/// once per instance entered (the reference takes it there again for every triangle), and
/// the SurfaceHit of the closest hit is built once, at the end (`finish`).

#include <algorithm>
#include <bit>
#include <concepts>
#include <new>
#include <vector>

#include "amalgam/geometry/wide_kernels.h"
#include "amalgam/hierarchy/instanced.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/traverse/state.h"
#include "amalgam/traverse/walk.h"
#include "amalgam/traverse/wide_walk.h"

namespace amalgam {

/// A two-level hierarchy whose top tree and meshes are in SIMD form (`top_wide_nodes()` is
/// null when they are not built).
template <class H>
concept InstancedWideHierarchy = requires(const H& h) {
  { h.top_wide_nodes() } -> std::same_as<const WideNodes*>;
};

AMALGAM_ISA_BEGIN

/// The node source (walk.h) of the two-level instanced hierarchy: the top tree's nodes, then,
/// at an instance leaf, the roots of its instances, whose nodes are their mesh's.
template <class State>
class InstancedSource {
  using IH = InstancedHierarchy;

 public:
  struct Item {
    float t;
    WideRef ref;         ///< in the top tree (inst 0) or in the instance's mesh (hierarchy/wide.h)
    std::uint32_t inst;  ///< 0: the top tree; else instance index + 1 (IH::slot)
    int level;
  };
  using Root = WideNodes;  ///< the top tree's SIMD form
  static constexpr bool kBoxKernel = true;

  /// The per-ray constants, as the loop's locals.
  struct RayConstants {
    WideRay wr;
    const WideNodes* top;
  };

  RayConstants begin(const State& s, const WideNodes& top) {
    obj_inst_ = 0;
    return {WideRay::of(s.ray), &top};
  }
  static Item root_item(const WideNodes& top, float t) { return {t, top.root, 0, 0}; }

  /// Builds the SurfaceHit of the closest hit when it is a deferred triangle: the generic
  /// path's `InstancedHierarchy::intersect` for that triangle, bit for bit.
  static void finish(State& s) {
    const IH& h = s.h;
    const IH::InstanceData& in = h.instances[IH::slot(s.hit.id) - 1];
    Vec3 a, b, c;
    h.meshes[in.mesh].prims.triangle(IH::local(s.hit.id), a, b, c);
    if (in.identity) {
      s.hit.surf = triangle_finish(s.ray, a, b, c, s.cand);
    } else {
      const Ray obj = IH::object_ray(in, s.ray);
      s.hit.surf = IH::world_hit(in, triangle_finish(obj, a, b, c, s.cand), s.ray.dir);
    }
    s.pending = false;
  }

  /// The hierarchy's id of the node of item `it`.
  static NodeId node_id(const State& s, const RayConstants& rc, const Item& it) {
    if (it.inst == 0) return IH::id(0, rc.top->record_owner(it.ref));
    return IH::id(it.inst, s.h.meshes[s.h.instances[it.inst - 1].mesh].wide.node_of(it.ref));
  }

  template <BoxRays kRays>
  [[gnu::always_inline]] Next expand(State& s, const RayConstants& rc, Item& it,
                                     WalkStack<Item>& st) {
    if (it.inst == 0) return top_node<kRays>(s, *rc.top, rc.wr, it, st);
    return instance_node<kRays>(s, rc.wr, it, st);
  }

 private:
  /// A top-level node: its children are top nodes or, for a leaf, instance roots.
  template <BoxRays kRays>
  static Next top_node(State& s, const WideNodes& top, const WideRay& wr, Item& it,
                       WalkStack<Item>& st) {
    const WideRecord rec = top.record(it.ref);
    const int count = top.child_count(it.ref);
    const int cl = it.level + 1;
    s.count_children(cl, count);
    const bool instances = it.ref & kWideRefLeaf;
    return children(
        it, st, count,
        [&](int c0, int m, float* t) {
          return box_test_block<kRays>(nth(rec, c0).boxes(), wr, s.ray.tmin, s.ray.tmax, m, t);
        },
        [&](int c) {
          const WideRef r = nth(rec, c).child(c % kBoxLanes);
          if (!instances) return Item{0, r, 0, cl};
          return Item{0, s.h.meshes[s.h.instances[r].mesh].wide.root, r + 1u, cl};
        });
  }

  /// A node inside instance `it.inst`.
  template <BoxRays kRays>
  Next instance_node(State& s, const WideRay& wr, Item& it, WalkStack<Item>& st) {
    const std::uint32_t inst = it.inst;
    const IH::InstanceData& in = s.h.instances[inst - 1];
    const ExplicitHierarchy& mesh = s.h.meshes[in.mesh];
    const WideNodes& w = mesh.wide;
    const int cl = it.level + 1;
    if (it.ref & kWideRefLeaf) {
      const WideRef r = it.ref;
      const WideHeader hd = w.leaf_header(r);
      if (hd.leaf == kWideTriangleLeaf) {
        const WideRay& owr = in.identity ? wr : object_ray(s, in, inst);
        PackLeaf<State>::test(
            s, mesh.prims.packs().data() + hd.block, owr,
            [&] { return IH::id(inst, w.leaf_first(r, hd)); }, hd.count, cl);
        return s.done ? Next::kStop : Next::kPop;
      }
      for (int i = 0; i < hd.count; ++i) {  // spheres or boxes: the generic path's test
        s.count_primitives(cl);
        const PrimId id = IH::id(inst, hd.first + static_cast<std::uint32_t>(i));
        if (auto hit = s.h.intersect(id, s.ray)) s.on_primitive(id, cl, *hit);
        if (s.done) return Next::kStop;
      }
      return Next::kPop;
    }
    const WideRecord rec = w.record(it.ref);
    const int count = w.child_count(it.ref);
    s.count_children(cl, count);
    auto child = [&](int c) { return Item{0, nth(rec, c).child(c % kBoxLanes), inst, cl}; };
    if (in.identity) {
      return children(
          it, st, count,
          [&](int c0, int m, float* t) {
            return box_test_block<kRays>(nth(rec, c0).boxes(), wr, s.ray.tmin, s.ray.tmax, m, t);
          },
          child);
    }
    return children(
        it, st, count,
        [&](int c0, int m, float* t) {
          return world_boxes<kRays>(in, nth(rec, c0).boxes(), wr, s.ray.tmin, s.ray.tmax, m, t);
        },
        child);
  }

  /// The record holding child `c` of a node whose first record is `rec`.
  [[gnu::always_inline]] static WideRecord nth(WideRecord rec, int c) {
    for (; c >= kBoxLanes; c -= kBoxLanes) rec = rec.next();
    return rec;
  }

  /// The hit children of a node of `count` children, tested a block (8) at a time by
  /// `test(c0, m, t)` (the mask of the hit lanes among children c0 .. c0 + m, their entries in
  /// t), pushed farthest first as WideWalk does (ties: stored order); `make(c)` is child c's
  /// stack item (its t filled in here). kEnter with `it` the nearest hit child.
  template <class Test, class Make>
  [[gnu::always_inline]] static Next children(Item& it, WalkStack<Item>& st, int count, Test&& test,
                                              Make&& make) {
    st.reserve(st.sp + static_cast<std::size_t>(count));
    const std::size_t base = st.sp;
    for (int c0 = 0; c0 < count; c0 += kBoxLanes) {
      alignas(32) float t[kBoxLanes];
      push_sorted(st.st, st.sp, base, test(c0, std::min(count - c0, kBoxLanes), t), t,
                  [&](int lane) { return make(c0 + lane); });
    }
    if (st.sp == base) return Next::kPop;
    it = st.st[--st.sp];
    return Next::kEnter;
  }

  /// `box_test_block` on the world boxes of the transformed object boxes of instance `in` in
  /// the rows `b` (`InstancedHierarchy::world_box` of each), the first `m` lanes.
  template <BoxRays kRays>
  [[gnu::always_inline]] static unsigned world_boxes(const IH::InstanceData& in, BoxRows b,
                                                     const WideRay& wr, float tmin, float tmax,
                                                     int m, float* t) {
#if AMALGAM_WIDE_SSE
#if defined(AMALGAM_ISA_AVX2)
    return world_box_test<Lanes8, kRays>(in, b, 0, wr, tmin, tmax, m, t);
#else
    unsigned mask =
        world_box_test<Lanes4, kRays>(in, b, 0, wr, tmin, tmax, std::min(m, kWideLanes), t);
    if (m > kWideLanes)
      mask |= world_box_test<Lanes4, kRays>(in, b, kWideLanes, wr, tmin, tmax, m - kWideLanes,
                                            t + kWideLanes)
              << kWideLanes;
    return mask;
#endif
#else
    WideBox8 w;
    for (int l = 0; l < m; ++l) {
      Bbox ob;
      for (int a = 0; a < 3; ++a)
        ob.lo[a] = b.rows[a * b.stride + l], ob.hi[a] = b.rows[(3 + a) * b.stride + l];
      const Bbox wb = IH::world_box(in, ob);
      for (int a = 0; a < 3; ++a) w.lo[a][l] = wb.lo[a], w.hi[a][l] = wb.hi[a];
    }
    return box_test_block<kRays>(w.rows(), wr, tmin, tmax, m, t);
#endif
  }

#if AMALGAM_WIDE_SSE
  /// world_box on lanes c0 .. c0 + L::kLanes - 1 of the rows `b` at once, in registers, then
  /// the box kernel on them. The float operations are world_box's, in its order, lane by lane
  /// (no fused multiply-add: the build enables none). An empty box (unused lanes included)
  /// keeps its bounds, as there.
  template <class L, BoxRays kRays>
  [[gnu::always_inline]] static unsigned world_box_test(const IH::InstanceData& in, BoxRows b,
                                                        int c0, const WideRay& wr, float tmin,
                                                        float tmax, int m, float* t) {
    using V = typename L::V;
    V lo[3], hi[3], c[3], h[3];
    const V half = L::set1(0.5f);
    for (int a = 0; a < 3; ++a) {
      lo[a] = L::load(b.rows + a * b.stride + c0),
      hi[a] = L::load(b.rows + (3 + a) * b.stride + c0);
      c[a] = L::mul(L::add(lo[a], hi[a]), half);  // Bbox::center
      h[a] = L::mul(L::sub(hi[a], lo[a]), half);  // Bbox::extent() * 0.5f
    }
    const V empty = L::bor(L::bor(L::gt(lo[0], hi[0]), L::gt(lo[1], hi[1])), L::gt(lo[2], hi[2]));
    const V sign = L::set1(-0.0f), k = L::set1(4.0f * gamma(3));
    V wlo[3], whi[3];
    for (int r = 0; r < 3; ++r) {
      const float* mr = in.to_world.m[r];
      // Transform::point: ((m0 x + m1 y) + m2 z) + m3.
      const V cw = L::add(L::add(L::add(L::mul(L::set1(mr[0]), c[0]), L::mul(L::set1(mr[1]), c[1])),
                                 L::mul(L::set1(mr[2]), c[2])),
                          L::set1(mr[3]));
      // dot(abs_rows[r], h): (x + y) + z; then r += (|c| + r) * 4 gamma(3).
      const Vec3 ar = in.abs_rows[r];
      V rw = L::add(L::add(L::mul(L::set1(ar.x), h[0]), L::mul(L::set1(ar.y), h[1])),
                    L::mul(L::set1(ar.z), h[2]));
      rw = L::add(rw, L::mul(L::add(L::andnot(sign, cw), rw), k));
      wlo[r] = L::sub(cw, rw), whi[r] = L::add(cw, rw);
    }
    if (L::mask(empty) & ((1u << m) - 1u)) [[unlikely]] {
      for (int r = 0; r < 3; ++r) {
        wlo[r] = L::bor(L::band(empty, lo[r]), L::andnot(empty, wlo[r]));
        whi[r] = L::bor(L::band(empty, hi[r]), L::andnot(empty, whi[r]));
      }
    }
    return box_test_vectors<L, kRays>(wlo, whi, wr, tmin, tmax, m, t);
  }
#endif

  /// The ray in the object space of instance `inst` (not an identity), set up for the pack
  /// test once per instance entered: a ray's leaves in one instance come one after another.
  const WideRay& object_ray(const State& s, const IH::InstanceData& in, std::uint32_t inst) {
    if (obj_inst_ != inst) {
      obj_inst_ = inst;
      ::new (&obj_wr_) WideRay(WideRay::of(IH::object_ray(in, s.ray)));  // no copy of 0.5 KB
    }
    return obj_wr_;
  }

  std::uint32_t obj_inst_ = 0;  ///< the instance (+ 1) `obj_wr_` is for; 0: none yet
  WideRay obj_wr_{};
};

AMALGAM_ISA_END
}  // namespace amalgam

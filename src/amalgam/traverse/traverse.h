#pragma once
/// \file The traversal: templated on the hierarchy, the level-of-detail policy (lod.h), the
/// opacity model (opacity.h) and the child order (order.h). Two entry points, as in pbrt's
/// Intersect / IntersectP: `intersect` (closest hit) and `transmittance` (shadow rays).
///
/// Every hierarchy is traced by the one walk loop (walk.h) with the ray state and its rules
/// (state.h); the node source is picked per hierarchy:
/// - a hierarchy with SoA child boxes (ExplicitHierarchy, `wide_nodes()`), sorted order:
///   wide_walk.h, a node's children tested at once with SIMD;
/// - the two-level instanced hierarchy (`top_wide_nodes()`), sorted order: instanced_walk.h,
///   the top tree and each instance's mesh;
/// - otherwise (the builtin implicit scenes; stored order): generic_walk.h, one child at a time.
/// The scalar reference, reference.h, a separate recursive program, gives the same hits and
/// counts for every combination (tests/traverse/simd_test.cpp).

#include <vector>

#include "amalgam/traverse/generic_walk.h"
#include "amalgam/traverse/instanced_walk.h"
#include "amalgam/traverse/order.h"
#include "amalgam/traverse/walk.h"
#include "amalgam/traverse/wide_walk.h"
#include "amalgam/util/check.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

static_assert(kMaxLevels <= kCountedLevels, "every level must have its own counter");

/// `Stats` is Counters (exact counts) or NullCounters (counting compiled out, to measure the
/// counters' own overhead).
template <Hierarchy H, class Lod, class Opacity, class Order = SortedOrder, class Stats = Counters>
class Traversal {
 public:
  using State = RayState<H, Lod, Opacity, Stats>;

  Traversal(const H& h, const Lod& lod, Stats& counters) : s_(h, lod, counters) {
    if constexpr (requires { h.wide_stale(); })
      AMALGAM_CHECK(!h.wide_stale(),
                    "Traversal: the hierarchy's SIMD form is missing or stale (build_wide after "
                    "changing its nodes or primitives)");
  }

  /// Closest hit along `ray`. `key` seeds this ray's stochastic decisions. Under
  /// deterministic opacity, translucent amalgams in front of the returned hit are appended to
  /// `*translucent` in the order met (the caller sorts them by t).
  TraceHit intersect(const Ray& ray, std::uint64_t key,
                     std::vector<TranslucentHit>* translucent = nullptr) {
    s_.start(ray, key, RayKind::kPrimary, false);
    s_.translucent = translucent;
    run();
    if constexpr (kWide) {
      if (s_.pending) ExplicitSource<State>::finish(s_);
    } else if constexpr (kInstanced) {
      if (s_.pending) InstancedSource<State>::finish(s_);
    }
    if (translucent) {
      const float t_hit = s_.hit.t;
      std::erase_if(*translucent, [t_hit](const TranslucentHit& h) { return h.t >= t_hit; });
    }
    return s_.hit;
  }

  /// Fraction of light that passes along `ray` (0: occluded). Counts one shadow ray. Under an
  /// opacity model that defers amalgams (DeferredOpacity), those the ray meets are appended to
  /// `*deferred`.
  float transmittance(const Ray& ray, std::uint64_t key,
                      std::vector<TranslucentHit>* deferred = nullptr) {
    s_.start(ray, key, RayKind::kShadow, true);
    s_.translucent = deferred;
    run();
    return s_.transmittance;
  }

  /// The level-of-detail policy, to change between rays (ObjectLod's origin instance).
  Lod& lod() { return s_.lod; }
  Opacity& opacity() { return s_.opacity; }
  /// `n` cells of volumetric amalgams stepped through by a ray of kind `k` on `level`
  /// (render/volume_integrator.h marches them outside the walk; counted as the walk counts).
  void count_cells(RayKind k, int level, std::uint64_t n) { s_.count_cells(k, level, n); }

 private:
  static constexpr bool kSorted = Order::kSorted;
  static constexpr bool kWide = WideHierarchy<H> && kSorted;
  static constexpr bool kInstanced = InstancedWideHierarchy<H> && kSorted;

  void run() {
    const NodeId root = s_.h.root();
    const Bbox b = s_.h.bounds(root);
    s_.count_root();
    float t0, t1;
    if (!intersect_box(s_.ray, b, t0, t1)) return;
    if constexpr (kWide) {
      if (const WideNodes* w = s_.h.wide_nodes()) {
        wide_.run(s_, *w, t0);
        return;
      }
    }
    if constexpr (kInstanced) {
      if (const WideNodes* w = s_.h.top_wide_nodes()) {
        instanced_.run(s_, *w, t0);
        return;
      }
    }
    generic_.run(s_, {root, b}, t0);
  }

  struct None {};
  State s_;
  [[no_unique_address]] std::conditional_t<kWide, Walk<State, ExplicitSource<State>>, None> wide_;
  [[no_unique_address]] std::conditional_t<kInstanced, Walk<State, InstancedSource<State>>, None>
      instanced_;
  Walk<State, GeneratorSource<State, kSorted>> generic_;
};

AMALGAM_ISA_END
}  // namespace amalgam

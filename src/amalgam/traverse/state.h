#pragma once
/// \file The state every traversal algorithm shares while it traces one ray, and the rules
/// applied when a ray meets a primitive or renders an amalgam, written once for the walk
/// (walk.h and its node sources) and the scalar reference (reference.h).
///
/// Cost accounting follows the paper: every bounding volume, amalgam and primitive a ray is
/// tested against counts once, on the level of the object tested (root = level 0); a node is
/// counted as an amalgam on the levels where the LOD policy may render, else as a bounding
/// volume.

#include <algorithm>
#include <bit>
#include <cstddef>
#include <type_traits>
#include <utility>
#include <vector>

#include "amalgam/geometry/intersect.h"
#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/stats/counters.h"
#include "amalgam/traverse/hit.h"
#include "amalgam/traverse/lod.h"
#include "amalgam/traverse/opacity.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// The depth at which the translucent amalgams `hits`, blended front to back, leave less than
/// kSaturatedTransmittance of the light behind: the entry of the one that saturates them
/// (infinity if they do not).
inline float saturation_depth(const std::vector<TranslucentHit>& hits) {
  thread_local std::vector<std::pair<float, float>> by_depth;
  by_depth.clear();
  for (const TranslucentHit& h : hits) by_depth.push_back({h.t, h.opacity});
  std::sort(by_depth.begin(), by_depth.end());
  float through = 1.0f;
  for (const auto& [t, a] : by_depth) {
    through *= 1.0f - a;
    if (through < kSaturatedTransmittance) return t;
  }
  return kInfinity;
}

/// One traversal's state: the hierarchy and policies it runs with, and the ray in flight.
/// `Stats` is Counters (exact counts) or NullCounters (counting compiled out).
template <Hierarchy H, class Lod, class Opacity, class Stats>
struct RayState {
  RayState(const H& hierarchy, const Lod& l, Stats& c) : h(hierarchy), lod(l), counters(c) {}

  /// Whether the LOD policy can ever render (TraditionalLod never does: no box is needed
  /// after a node's own test).
  static constexpr bool kMayRender = !std::is_same_v<Lod, TraditionalLod>;

  const H& h;
  Lod lod;
  Opacity opacity;
  Stats& counters;

  Ray ray;
  std::uint64_t key = 0;  ///< seeds this ray's stochastic decisions
  RayKind kind = RayKind::kPrimary;
  bool any_hit = false;  ///< a shadow ray: stop at the first opaque thing met
  bool done = false;     ///< nothing further can change the result
  TraceHit hit;
  float transmittance = 1.0f;
  std::vector<TranslucentHit>* translucent = nullptr;
  /// `hit` is a triangle whose SurfaceHit is not built yet (`cand` holds its test's values):
  /// the fast paths build it once, for the final closest hit only.
  bool pending = false;
  TriangleCandidate cand{};

  void start(const Ray& r, std::uint64_t k, RayKind rk, bool shadow) {
    ray = r;
    key = k;
    kind = rk;
    any_hit = shadow;
    done = false;
    pending = false;
    // A shadow ray never writes or returns `hit` (an opaque thing occludes it): only a
    // closest-hit ray starts from an empty one (a fifth of a short shadow ray's entry).
    if (!shadow) hit = TraceHit{};
    transmittance = 1.0f;
    counters.count_ray(rk);
  }

  ObjectKind object_kind(int level) const {
    return lod.may_render(level) ? ObjectKind::kAmalgam : ObjectKind::kBoundingVolume;
  }

  // Cost accounting: the one place where a walk's events become counts (the paper's unit: one
  // ray/object test, on the level of the object tested). Each walk calls these once per event.

  /// The root's own box test (level 0), before the walk starts.
  void count_root() { counters.count_test(kind, object_kind(0), 0); }
  /// A node taken from the walk's order and then entered or rendered (Counters::reached).
  void count_reached() { counters.count_reached(kind); }
  /// `n` children of a node tested, on level `level`: amalgams where the LOD policy may render
  /// there, else bounding volumes.
  void count_children(int level, int n) {
    counters.count_tests(kind, object_kind(level), level, static_cast<std::uint64_t>(n));
  }
  /// `n` cells of volumetric amalgams on `level`, stepped through by a ray of kind `k` (a
  /// camera or shadow march of render/volume_integrator.h, which runs beside the walk).
  void count_cells(RayKind k, int level, std::uint64_t n) {
    counters.count_tests(k, ObjectKind::kCell, level, n);
  }
  /// `n` primitives tested on `level`.
  void count_primitives(int level, int n = 1) {
    counters.count_tests(kind, ObjectKind::kPrimitive, level, static_cast<std::uint64_t>(n));
  }
  /// A pack of `m` primitives on `level` tested at once, with hits in the lanes `mask`: counted
  /// as the one-by-one loop tests them -- all m, except that a shadow ray stops at its first hit
  /// (lanes up to and including the lowest set one).
  void count_pack(int level, int m, unsigned mask) {
    count_primitives(level, any_hit && mask ? std::countr_zero(mask) + 1 : m);
  }

  /// The LOD policy's answer for a node on `level` with box `b`, entered at `t`: render it
  /// (true) or descend. A node that contains the ray's origin (the ray starts inside it) is
  /// flagged to the policy as such.
  /// A policy with `render_node` (ObjectLod, traverse/object_lod.h) is also given the node's
  /// id and the ray's key.
  bool renders(NodeId id, const Bbox& b, int level, float t) const {
    if (!lod.may_render(level)) return false;
    const bool inside = t <= ray.tmin && b.contains(ray.origin);
    if constexpr (requires { lod.render_node(id, b, level, ray, t, inside, key); })
      return lod.render_node(id, b, level, ray, t, inside, key);
    else
      return lod.render(b, level, ray, t, inside);
  }

  /// The walk's step on reaching node `id_of()` (level `level`, entered at `t`, box
  /// `box_of(id)`): when the LOD policy renders it, renders it (true); else false: the walk
  /// descends. The node's id and box are looked up only where the policy may render.
  template <class IdOf, class BoxOf>
  [[gnu::always_inline]] bool render_if_policy([[maybe_unused]] IdOf&& id_of,
                                               [[maybe_unused]] BoxOf&& box_of,
                                               [[maybe_unused]] int level,
                                               [[maybe_unused]] float t) {
    if constexpr (kMayRender) {
      if (lod.may_render(level)) {
        const NodeId id = id_of();
        const Bbox b = box_of(id);
        if (renders(id, b, level, t)) {
          render_amalgam(id, level, b, t);
          return true;
        }
      }
    }
    return false;
  }

  /// Pops the next entry of the stack `st[0, sp)` of the walk into `it`, skipping those
  /// entered beyond the closest hit so far; false when none is left.
  template <class Item>
  [[gnu::always_inline]] bool pop_nearer(Item& it, const Item* st, std::size_t& sp) const {
    do {
      if (sp == 0) return false;
      it = st[--sp];
    } while (it.t > ray.tmax);
    return true;
  }

  /// A shadow ray met something opaque.
  void occlude() {
    transmittance = 0.0f;
    done = true;
  }

  /// Primitive `id` (on `level`) hit at `s`.
  void on_primitive(PrimId id, int level, const SurfaceHit& s) {
    if (any_hit) return occlude();
    ray.tmax = s.t;
    pending = false;
    hit = TraceHit{TraceHit::Kind::kPrimitive, s.t, id, level, s};
  }

  /// Triangle `id` hit with the test's values `c`; its SurfaceHit is built later.
  void on_triangle(PrimId id, int level, const TriangleCandidate& c) {
    if (any_hit) return occlude();
    ray.tmax = c.t;
    hit.kind = TraceHit::Kind::kPrimitive;
    hit.t = c.t;
    hit.id = id;
    hit.level = level;
    pending = true;
    cand = c;
  }

  /// The LOD policy renders amalgam `id` (box `b`, entered at `t`): the opacity model decides
  /// what that does to the ray, with the amalgam's opacity in the ray's direction.
  void render_amalgam(NodeId id, int level, const Bbox& b, float t) {
    if constexpr (requires { Opacity::kDefers; }) {
      // Deferred (DeferredOpacity): handed to its sink, or recorded for the caller, for camera
      // and shadow rays alike.
      if (opacity.sink)
        opacity.sink->deferred(id, level, t, ray, key, any_hit, done, transmittance);
      else if (translucent)
        translucent->push_back({t, id, level, SurfaceHit{}, 0.0f});
      return;
    }
    const float a = directional_opacity(h.appearance(id), b, ray.dir);
    switch (opacity.effect(a, key, id, any_hit)) {
      case AmalgamEffect::kPass:
        return;
      case AmalgamEffect::kBlend:
        if (any_hit) {
          transmittance *= 1.0f - a;
        } else if (translucent) {
          translucent->push_back({t, id, level, box_entry_hit(ray, b, t), a});
          if constexpr (Opacity::kSaturates) {
            // Once what was collected can saturate the ray, nothing beyond the depth where it
            // does, front to back, can show: the ray ends there. (Stopping the walk itself
            // would be wrong: it collects in subtree order, not depth order, and may not have
            // met a nearer primitive yet.)
            transmittance *= 1.0f - a;
            if (transmittance < kSaturatedTransmittance)
              ray.tmax = std::min(ray.tmax, saturation_depth(*translucent));
          }
        }
        return;
      case AmalgamEffect::kStop:
        if (any_hit) return occlude();
        ray.tmax = t;
        pending = false;
        hit = TraceHit{TraceHit::Kind::kAmalgam, t, id, level, box_entry_hit(ray, b, t)};
        return;
    }
  }
};

/// The walk's stack `stack`, whose base `st` and capacity `cap` the walk keeps as locals
/// (members would be reloaded after every store to the stack): grown to hold `need` items.
template <class Item>
[[gnu::always_inline]] inline void reserve_stack(std::vector<Item>& stack, Item*& st,
                                                 std::size_t& cap, std::size_t need) {
  if (need <= cap) return;
  stack.resize(2 * cap + need);
  st = stack.data(), cap = stack.size();
}

/// Pushes `item` (entered at `item.t`, never NaN) onto the stack `st` above `base`,
/// insertion-sorted farthest first (the nearest is popped first). A later child (stored order)
/// goes below the items with equal t, so that among equals the first in stored order is popped
/// first, as a recursion enters them (stable sort).
template <class Item>
[[gnu::always_inline]] inline void push_one_sorted(Item* st, std::size_t& sp, std::size_t base,
                                                   const Item& item) {
  std::size_t i = sp++;
  while (i > base && st[i - 1].t <= item.t) st[i] = st[i - 1], --i;
  st[i] = item;
}

/// Pushes the hit lanes `mask` of a node's box test (entered at `t[lane]`; `make(lane)` is the
/// child's item, its t set here) with `push_one_sorted`, in lane (stored) order. Never NaN: a
/// NaN entry fails the kernel's t0 <= t1.
template <class Item, class Make>
[[gnu::always_inline]] inline void push_sorted(Item* st, std::size_t& sp, std::size_t base,
                                               unsigned mask, const float* t, Make&& make) {
  for (; mask; mask &= mask - 1) {
    const int lane = std::countr_zero(mask);
    Item item = make(lane);
    item.t = t[lane];
    push_one_sorted(st, sp, base, item);
  }
}

AMALGAM_ISA_END
}  // namespace amalgam

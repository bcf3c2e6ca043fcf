#pragma once
/// \file The fast traversal of a hierarchy that gathers a node's children for a SIMD test
/// (`gather_children`, hierarchy/wide.h; the two-level instanced hierarchy): sorted order,
/// iterative, the children's boxes tested four at a time with the slab kernel. Every test,
/// count and order is the generic walk's (tests/traverse/simd_test.cpp compares them).
///
/// The LOD decision (render or descend) depends only on the box, the level, the entry t and
/// the ray's cone, none of which change while the ray is traced, so it is taken when a child is
/// pushed, with its box at hand, instead of gathering the box again when it is popped.

#include <algorithm>
#include <bit>
#include <vector>

#include "amalgam/geometry/wide_kernels.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/traverse/state.h"

namespace amalgam {

/// A hierarchy that hands the traversal a node's children gathered for a SIMD test.
template <class H>
concept GatheringHierarchy = requires(const H& h, NodeId n, GatheredChildren& g) {
  h.gather_children(n, g);
};

AMALGAM_ISA_BEGIN

template <class State>
class GatheredWalk {
 public:
  void run(State& s, NodeId root, float t_root) {
    const WideRay wr = WideRay::of(s.ray);
    stack_.clear();
    stack_.push_back({t_root, 0, decide(s, s.h.bounds(root), 0, t_root), root});
    while (!stack_.empty() && !s.done) {
      const Item it = stack_.back();
      stack_.pop_back();
      if (it.t > s.ray.tmax) continue;
      s.counters.count_reached(s.kind);
      if constexpr (State::kMayRender) {
        if (it.render) {
          s.render_amalgam(it.node, it.level, s.h.bounds(it.node), it.t);
          continue;
        }
      }
      expand(s, wr, it.node, it.level);
    }
  }

 private:
  struct Item {
    float t;
    std::int16_t level;  ///< below 2^15: node ids hold at most 64 bits of levels
    bool render;         ///< the LOD policy renders it (decided when pushed)
    NodeId node;
  };

  static bool decide(const State& s, const Bbox& b, int level, float t) {
    if constexpr (State::kMayRender) return s.renders(b, level, t);
    return false;
  }

  void expand(State& s, const WideRay& wr, NodeId node, int level) {
    const int cl = level + 1;
    s.h.gather_children(node, g_);
    const int count = g_.count;
    if (g_.primitives) {
      for (int i = 0; i < count; ++i) {
        s.counters.count_test(s.kind, ObjectKind::kPrimitive, cl);
        if (auto hit = s.h.intersect(g_.ids[i], s.ray)) s.on_primitive(g_.ids[i], cl, *hit);
        if (s.done) return;
      }
      return;
    }
    const ObjectKind ok = s.object_kind(cl);
    s.counters.count_tests(s.kind, ok, cl, static_cast<std::uint64_t>(count));
    const bool may_render = State::kMayRender && s.lod.may_render(cl);
    Item hits[kMaxChildren];
    int n = 0;
    for (int c0 = 0; c0 < count; c0 += kWideLanes) {
      alignas(16) float t[kWideLanes];
      unsigned mask = intersect_wide4(g_.boxes[c0 / kWideLanes], wr, s.ray.tmin, s.ray.tmax,
                                      std::min(count - c0, kWideLanes), t);
      while (mask) {
        const int lane = std::countr_zero(mask);
        mask &= mask - 1;
        const float te = t[lane];
        int i = n++;  // insertion sort, stable for equal t (lanes come in stored order)
        while (i > 0 && hits[i - 1].t > te) hits[i] = hits[i - 1], --i;
        const bool r = may_render && decide(s, g_.box(c0 + lane), cl, te);
        hits[i] = {te, static_cast<std::int16_t>(cl), r, g_.ids[c0 + lane]};
      }
    }
    for (int i = n; i-- > 0;) stack_.push_back(hits[i]);
  }

  std::vector<Item> stack_;
  GatheredChildren g_;
};

AMALGAM_ISA_END
}  // namespace amalgam

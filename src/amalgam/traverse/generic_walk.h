#pragma once
/// \file The generic traversal: recursive, one child at a time, for any hierarchy (the builtin
/// implicit scenes, whose children are computed on demand; and every hierarchy in stored
/// order). See order.h for the two child orders.

#include "amalgam/traverse/state.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

template <class State, bool kSorted>
struct GenericWalk {
  /// A node whose box the ray meets at t_entry: render it or descend. `b` is its box (only
  /// read when the LOD policy may render).
  static void enter(State& s, NodeId id, int level, const Bbox& b, float t_entry) {
    if (t_entry > s.ray.tmax) return;  // a closer hit was found since this node was tested
    s.count_reached();
    if constexpr (State::kMayRender) {
      if (s.renders(id, b, level, t_entry)) {
        s.render_amalgam(id, level, b, t_entry);
        return;
      }
    }
    visit(s, id, level);
  }

  static void visit(State& s, NodeId node, int level) {
    constexpr bool kMayRender = State::kMayRender;
    const int cl = level + 1;
    struct Entry {
      float t;
      int slot;  ///< index into `boxes` (kept unsorted)
      NodeId id;
    };
    Entry entries[kSorted ? kMaxChildren : 1];
    Bbox boxes[kSorted && kMayRender ? kMaxChildren : 1];
    int n = 0;
    s.h.for_each_child(node, [&](Child ch) {
      if (ch.is_primitive) {
        s.count_primitives(cl);
        if (auto hit = s.h.intersect(ch.id, s.ray)) s.on_primitive(ch.id, cl, *hit);
        return !s.done;
      }
      const Bbox b = s.h.bounds(ch.id);
      s.count_children(cl, 1);
      float t0, t1;
      if (!intersect_box(s.ray, b, t0, t1)) return true;
      if constexpr (kSorted) {
        const int slot = n;
        if constexpr (kMayRender) boxes[slot] = b;
        int i = n++;  // insertion sort, stable for equal t
        while (i > 0 && entries[i - 1].t > t0) entries[i] = entries[i - 1], --i;
        entries[i] = Entry{t0, slot, ch.id};
        return true;
      } else {
        enter(s, ch.id, cl, b, t0);
        return !s.done;
      }
    });
    if constexpr (kSorted) {
      for (int i = 0; i < n && !s.done; ++i) {
        if (entries[i].t > s.ray.tmax) break;  // every later entry is farther still
        enter(s, entries[i].id, cl, boxes[kMayRender ? entries[i].slot : 0], entries[i].t);
      }
    }
  }
};

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file The node source (walk.h) of any hierarchy, through its `for_each_child` (the builtin
/// implicit scenes, whose children are computed on demand; and every hierarchy in stored order),
/// one child at a time with the scalar box test. See order.h for the two child orders:
/// - sorted: a node's primitives are tested and its node children's boxes tested in stored
///   order, the hit children pushed farthest first (ties: stored order), so that the pops
///   enter them nearest first; a popped child beyond the closest hit is skipped;
/// - stored: a node's children are listed untested (a frame of a recursion), and each is tested
///   when the walk comes back to the node, then entered at once if hit: the tests and entries
///   come in the order of a recursion that enters each child as soon as its test succeeds.

#include <cstdint>
#include <type_traits>
#include <vector>

#include "amalgam/traverse/state.h"
#include "amalgam/traverse/walk.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

template <class State, bool kSorted>
class GeneratorSource {
  struct NoBox {};
  /// A node's box is kept from its test only when the LOD policy may render it.
  using KeptBox = std::conditional_t<State::kMayRender, Bbox, NoBox>;

 public:
  /// A node to enter (its box tested, met at `t`).
  struct Item {
    float t;
    int level;
    NodeId id;
    [[no_unique_address]] KeptBox box;
  };
  struct Root {
    NodeId id;
    Bbox box;
  };
  struct RayConstants {};
  static constexpr bool kBoxKernel = false;

  static Item root_item(const Root& r, float t) { return {t, 0, r.id, keep(r.box)}; }
  static NodeId node_id(const State&, const RayConstants&, const Item& it) { return it.id; }
  /// The box of the node of `it`, kept from its test (no second `bounds` of a computed node).
  static const Bbox& box(const Item& it) requires State::kMayRender { return it.box; }

  RayConstants begin(const State&, const Root&) {
    frames_.clear();  // a ray that stopped early (occluded) left its frames
    n_kids_ = 0;
    return {};
  }

  template <BoxRays>
  Next expand(State& s, const RayConstants&, Item& it, WalkStack<Item>& st) {
    const int cl = it.level + 1;
    if constexpr (!kSorted) {
      // The children listed after those of the nodes being visited (at most kMaxChildren).
      if (n_kids_ + kMaxChildren > kids_.size()) kids_.resize(2 * kids_.size() + kMaxChildren);
      const std::uint32_t first = n_kids_;
      Child* kids = kids_.data();
      std::uint32_t n = first;
      s.h.for_each_child(it.id, [&](Child ch) {
        kids[n++] = ch;
        return true;
      });
      n_kids_ = n;
      frames_.push_back({first, first, cl});
      return Next::kPop;
    } else {
      st.reserve(st.sp + kMaxChildren);
      const std::size_t base = st.sp;
      s.h.for_each_child(it.id, [&](Child ch) {
        if (ch.is_primitive) {
          primitive(s, ch.id, cl);
          return !s.done;
        }
        const Bbox b = s.h.bounds(ch.id);
        s.count_children(cl, 1);
        float t0, t1;
        if (intersect_box(s.ray, b, t0, t1))
          push_one_sorted(st.st, st.sp, base, Item{t0, cl, ch.id, keep(b)});
        return true;
      });
      if (s.done) return Next::kStop;
      if (st.sp == base) return Next::kPop;
      // The nearest hit child next, unless a primitive tested after its box brought the closest
      // hit nearer than its entry (then every sibling is beyond it too).
      it = st.st[--st.sp];
      if (it.t <= s.ray.tmax) return Next::kEnter;
      st.sp = base;
      return Next::kPop;
    }
  }

  /// The next node to enter. Sorted: the nearest entry on the stack not beyond the closest
  /// hit. Stored: the next child of the innermost node with children left, in stored order,
  /// tested now (a primitive: tested and passed; a node: entered if hit).
  bool pop(State& s, Item& it, WalkStack<Item>& st) {
    if constexpr (kSorted) {
      return s.pop_nearer(it, st.st, st.sp);
    } else {
      while (!frames_.empty()) {
        Frame& f = frames_.back();
        if (f.next == n_kids_) {
          n_kids_ = f.first;
          frames_.pop_back();
          continue;
        }
        const Child ch = kids_[f.next++];
        if (ch.is_primitive) {
          primitive(s, ch.id, f.level);
          if (s.done) return false;
          continue;
        }
        const Bbox b = s.h.bounds(ch.id);
        s.count_children(f.level, 1);
        float t0, t1;
        if (!intersect_box(s.ray, b, t0, t1)) continue;
        it = {t0, f.level, ch.id, keep(b)};  // t0 <= tmax: the test clipped to it
        return true;
      }
      return false;
    }
  }

 private:
  static KeptBox keep(const Bbox& b) {
    if constexpr (State::kMayRender)
      return b;
    else
      return {};
  }

  [[gnu::always_inline]] static void primitive(State& s, PrimId id, int level) {
    s.count_primitives(level);
    if (auto hit = s.h.intersect(id, s.ray)) s.on_primitive(id, level, *hit);
  }

  /// Stored order: the children of the nodes being visited, innermost last (a recursion's
  /// frames; the memory kept across rays): a frame's children are kids_[first, ...), the next
  /// to test at `next`, on `level`; kids_[0, n_kids_) are in use.
  struct Frame {
    std::uint32_t first, next;
    int level;
  };
  std::vector<Frame> frames_;
  std::vector<Child> kids_;
  std::uint32_t n_kids_ = 0;
};

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file The scalar reference traversal, an oracle written to be obviously right rather than
/// fast: recursion on the call stack, one child at a time through `for_each_child` and
/// `bounds` (never the SIMD form), `intersect_box` and the hierarchy's full `intersect` per
/// test, a `SurfaceHit` for every accepted primitive, a node's hit children gathered in a
/// vector and ordered with `std::stable_sort`. It shares only the ray state's rules (state.h:
/// counting, LOD decisions, opacity effects) with the walk of traverse.h (walk.h and its node
/// sources), so that tests/traverse/simd_test.cpp compares two different programs: same hit,
/// same counts per ray kind, object kind and level, for every policy combination. Not used for
/// rendering.

#include <algorithm>
#include <vector>

#include "amalgam/traverse/order.h"
#include "amalgam/traverse/state.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

template <Hierarchy H, class Lod, class Opacity, class Order = SortedOrder, class Stats = Counters>
class ReferenceTraversal {
 public:
  ReferenceTraversal(const H& h, const Lod& lod, Stats& counters) : s_(h, lod, counters) {}

  TraceHit intersect(const Ray& ray, std::uint64_t key,
                     std::vector<TranslucentHit>* translucent = nullptr) {
    s_.start(ray, key, RayKind::kPrimary, false);
    s_.translucent = translucent;
    run();
    if (translucent) {
      const float t_hit = s_.hit.t;
      std::erase_if(*translucent, [t_hit](const TranslucentHit& h) { return h.t >= t_hit; });
    }
    return s_.hit;
  }

  float transmittance(const Ray& ray, std::uint64_t key) {
    s_.start(ray, key, RayKind::kShadow, true);
    s_.translucent = nullptr;
    run();
    return s_.transmittance;
  }

 private:
  void run() {
    const NodeId root = s_.h.root();
    const Bbox b = s_.h.bounds(root);
    s_.count_root();
    if (auto span = intersect_box(s_.ray, b)) enter(root, 0, b, span->t0);
  }

  void enter(NodeId id, int level, const Bbox& b, float t_entry) {
    if (t_entry > s_.ray.tmax) return;  // a closer hit was found since this node was tested
    s_.count_reached();
    if (s_.renders(id, b, level, t_entry))
      s_.render_amalgam(id, level, b, t_entry);
    else
      visit(id, level);
  }

  /// Sorted: every child tested (primitives at once, in stored order), then the hit node
  /// children entered by entry distance (ties: stored order), stopping at the first beyond the
  /// closest hit. Stored: each child entered as soon as its test succeeds.
  void visit(NodeId node, int level) {
    const int cl = level + 1;
    struct Entry {
      float t;
      NodeId id;
      Bbox b;
    };
    std::vector<Entry> hit;
    s_.h.for_each_child(node, [&](Child ch) {
      if (ch.is_primitive) {
        s_.count_primitives(cl);
        if (auto h = s_.h.intersect(ch.id, s_.ray)) s_.on_primitive(ch.id, cl, *h);
        return !s_.done;
      }
      const Bbox b = s_.h.bounds(ch.id);
      s_.count_children(cl, 1);
      const auto span = intersect_box(s_.ray, b);
      if (!span) return true;
      if (!Order::kSorted) {
        enter(ch.id, cl, b, span->t0);
        return !s_.done;
      }
      hit.push_back({span->t0, ch.id, b});
      return true;
    });
    std::stable_sort(hit.begin(), hit.end(),
                     [](const Entry& a, const Entry& b) { return a.t < b.t; });
    for (const Entry& e : hit) {
      if (s_.done || e.t > s_.ray.tmax) return;  // every later entry is farther still
      enter(e.id, cl, e.b, e.t);
    }
  }

  RayState<H, Lod, Opacity, Stats> s_;
};

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file The scalar reference traversal: the original recursive traversal (one child at a
/// time, `intersect_box` and the hierarchy's full `intersect` per test, a `SurfaceHit` for
/// every accepted primitive), with the same ray state, LOD policy and opacity model as the
/// fast one (state.h), so the fast traversal of traverse.h can be tested against it
/// (tests/traverse/simd_test.cpp): same hit, same counts per ray kind, object kind and level,
/// for every policy combination. Not used for rendering.

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

  void visit(NodeId node, int level) {
    const int cl = level + 1;
    struct Entry {
      float t;
      NodeId id;
      Bbox b;
    };
    Entry entries[Order::kSorted ? kMaxChildren : 1];
    int n = 0;
    s_.h.for_each_child(node, [&](Child ch) {
      if (ch.is_primitive) {
        s_.count_primitives(cl);
        if (auto hit = s_.h.intersect(ch.id, s_.ray)) s_.on_primitive(ch.id, cl, *hit);
        return !s_.done;
      }
      const Bbox b = s_.h.bounds(ch.id);
      s_.count_children(cl, 1);
      const auto span = intersect_box(s_.ray, b);
      if (!span) return true;
      if constexpr (Order::kSorted) {
        int i = n++;  // insertion sort, stable for equal t
        while (i > 0 && entries[i - 1].t > span->t0) entries[i] = entries[i - 1], --i;
        entries[i] = Entry{span->t0, ch.id, b};
        return true;
      } else {
        enter(ch.id, cl, b, span->t0);
        return !s_.done;
      }
    });
    if constexpr (Order::kSorted) {
      for (int i = 0; i < n && !s_.done; ++i) {
        if (entries[i].t > s_.ray.tmax) break;  // every later entry is farther still
        enter(entries[i].id, cl, entries[i].b, entries[i].t);
      }
    }
  }

  RayState<H, Lod, Opacity, Stats> s_;
};

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file The scalar reference traversal: the original, recursive `Traversal`, kept verbatim
/// (one child at a time, `intersect_box` and the hierarchy's full `intersect` per test, a
/// `SurfaceHit` for every accepted primitive) so the fast traversal of traverse.h can be
/// tested against it (tests/traverse/simd_test.cpp): same hit, same counts per ray kind,
/// object kind and level, for every policy combination. Not used for rendering.

#include <algorithm>
#include <vector>

#include "amalgam/traverse/traverse.h"

namespace amalgam {

/// `Stats` is Counters (exact counts) or NullCounters (counting compiled out, to measure the
/// counters' own overhead).
template <Hierarchy H, class Lod, OpacityModel kOpacity, bool kSorted, class Stats = Counters>
class ReferenceTraversal {
 public:
  ReferenceTraversal(const H& h, const Lod& lod, Stats& counters)
      : h_(h), lod_(lod), counters_(counters) {}

  /// Closest hit along `ray`. `key` seeds this ray's stochastic decisions. Under
  /// deterministic opacity, translucent amalgams in front of the returned hit are appended to
  /// `*translucent` in the order met (the caller sorts them by t).
  TraceHit intersect(const Ray& ray, std::uint64_t key,
                     std::vector<TranslucentHit>* translucent = nullptr) {
    start(ray, key, RayKind::kPrimary, false);
    translucent_ = translucent;
    run();
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
  void start(const Ray& ray, std::uint64_t key, RayKind kind, bool any_hit) {
    ray_ = ray;
    key_ = key;
    kind_ = kind;
    any_hit_ = any_hit;
    done_ = false;
    hit_ = TraceHit{};
    transmittance_ = 1.0f;
    counters_.count_ray(kind);
  }

  void run() {
    const NodeId root = h_.root();
    const Bbox b = h_.bounds(root);
    counters_.count_test(kind_, object_kind(0), 0);
    if (auto span = intersect_box(ray_, b)) enter(root, 0, b, span->t0);
  }

  ObjectKind object_kind(int level) const {
    return lod_.may_render(level) ? ObjectKind::kAmalgam : ObjectKind::kBoundingVolume;
  }

  /// A node whose box the ray meets at t_entry: render it or descend.
  void enter(NodeId id, int level, const Bbox& b, float t_entry) {
    if (t_entry > ray_.tmax) return;  // a closer hit was found since this node was tested
    if (lod_.may_render(level) &&
        lod_.render(b, level, ray_, t_entry, t_entry <= ray_.tmin && b.contains(ray_.origin))) {
      render(id, level, b, t_entry);
    } else {
      visit(id, level);
    }
  }

  void visit(NodeId node, int level) {
    const int cl = level + 1;
    struct Entry {
      float t;
      NodeId id;
      Bbox b;
    };
    Entry entries[kSorted ? kMaxChildren : 1];
    int n = 0;
    h_.for_each_child(node, [&](Child ch) {
      if (ch.is_primitive) {
        counters_.count_test(kind_, ObjectKind::kPrimitive, cl);
        if (auto s = h_.intersect(ch.id, ray_)) on_primitive(ch.id, cl, *s);
        return !done_;
      }
      const Bbox b = h_.bounds(ch.id);
      counters_.count_test(kind_, object_kind(cl), cl);
      const auto span = intersect_box(ray_, b);
      if (!span) return true;
      if constexpr (kSorted) {
        int i = n++;  // insertion sort, stable for equal t
        while (i > 0 && entries[i - 1].t > span->t0) entries[i] = entries[i - 1], --i;
        entries[i] = Entry{span->t0, ch.id, b};
        return true;
      } else {
        enter(ch.id, cl, b, span->t0);
        return !done_;
      }
    });
    if constexpr (kSorted) {
      for (int i = 0; i < n && !done_; ++i) {
        if (entries[i].t > ray_.tmax) break;  // every later entry is farther still
        enter(entries[i].id, cl, entries[i].b, entries[i].t);
      }
    }
  }

  void on_primitive(PrimId id, int level, const SurfaceHit& s) {
    if (any_hit_) {
      transmittance_ = 0.0f;
      done_ = true;
      return;
    }
    ray_.tmax = s.t;
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
    hit_ = TraceHit{TraceHit::Kind::kAmalgam, t, id, level, box_entry_hit(ray_, b, t)};
  }

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
};

}  // namespace amalgam

#pragma once
/// \file Axis-aligned bounding boxes.

#include "amalgam/geometry/ray.h"

namespace amalgam {

/// An axis-aligned box [lo, hi]. The default box is empty (lo = +inf, hi = -inf).
struct Bbox {
  Vec3 lo{kInfinity, kInfinity, kInfinity};
  Vec3 hi{-kInfinity, -kInfinity, -kInfinity};

  static constexpr Bbox of(Vec3 a, Vec3 b) { return {min(a, b), max(a, b)}; }
  constexpr void extend(Vec3 p) { lo = min(lo, p), hi = max(hi, p); }
  constexpr void extend(const Bbox& b) { lo = min(lo, b.lo), hi = max(hi, b.hi); }
  constexpr bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  constexpr Vec3 center() const { return (lo + hi) * 0.5f; }
  constexpr Vec3 extent() const { return hi - lo; }
  /// Length of the diagonal: the box's size for level-of-detail decisions.
  float diagonal() const { return length(extent()); }
  constexpr bool contains(Vec3 p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
  friend constexpr bool operator==(const Bbox&, const Bbox&) = default;
};

/// Surface area of a box (0 for an empty box).
inline float surface_area(const Bbox& b) {
  if (b.empty()) return 0.0f;
  const Vec3 e = b.extent();
  return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

}  // namespace amalgam

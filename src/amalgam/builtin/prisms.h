#pragma once
/// \file The implicit hierarchy of builtin:prisms, the paper's Figure 2: nested
/// rectangular-prism amalgams. The root is the cube [-1, 1]^3; every amalgam on levels
/// 0 .. depth-2 has split^3 children (a regular grid); each amalgam on level depth-1 holds
/// `leaf` box primitives, stacked along z, each its slab shrunk by `fill` about its centre.
/// Primitives are on level l_max = depth.
///
/// Appearance is exact and O(1) per node: colour is a linear field of position, so the mean
/// over an amalgam's contents is the field at its centre; opacity is fill^2, which is exactly
/// the fraction of axis-parallel rays through any amalgam that hit one of its primitives.

#include <cstdint>

#include "amalgam/builtin/params.h"
#include "amalgam/hierarchy/hierarchy.h"

namespace amalgam {

class PrismsHierarchy {
 public:
  struct Config {
    int split = 2;
    int depth = 6;
    int leaf = 2;
    double fill = 0.8;
  };
  static constexpr int kAxisBits = 19;

  explicit PrismsHierarchy(const Config& c);

  NodeId root() const { return encode(0, 0, 0, 0); }
  Bbox bounds(NodeId id) const {
    const int l = level_of(id);
    const float w = cell_[l];
    const Vec3 lo{-1.0f + w * static_cast<float>(ix(id)), -1.0f + w * static_cast<float>(iy(id)),
                  -1.0f + w * static_cast<float>(iz(id))};
    return Bbox{lo, lo + Vec3{w, w, w}};
  }
  Appearance appearance(NodeId id) const;
  template <class F>
  void for_each_child(NodeId id, F&& f) const {
    const int l = level_of(id);
    if (l + 1 == c_.depth) {  // bottom amalgam: `leaf` primitives stacked along z
      for (int j = 0; j < c_.leaf; ++j)
        if (!f(Child{encode(l + 1, ix(id), iy(id), iz(id) * c_.leaf + j), true})) return;
      return;
    }
    const std::uint64_t s = static_cast<std::uint64_t>(c_.split);
    for (std::uint64_t a = 0; a < s; ++a)
      for (std::uint64_t b = 0; b < s; ++b)
        for (std::uint64_t c = 0; c < s; ++c)
          if (!f(Child{encode(l + 1, ix(id) * s + a, iy(id) * s + b, iz(id) * s + c), false}))
            return;
  }
  std::optional<SurfaceHit> intersect(PrimId id, const Ray& ray) const {
    return intersect_solid_box(ray, prim_box(id));
  }
  Surface surface(PrimId id) const;
  Primitive primitive(PrimId id) const {
    const Bbox b = prim_box(id);
    return Primitive::box(b.lo, b.hi);
  }
  HierarchyInfo info() const;
  Bbox prim_box(PrimId id) const;
  const Config& config() const { return c_; }
  /// view: "front" looks down -z, slightly off the cube's centre lines so that the centre
  /// ray meets `split` children per amalgam; "corner" is a three-quarter view.
  Environment environment(const std::string& view, int lights) const;

  static constexpr int level_of(NodeId id) { return static_cast<int>(id >> 58); }
  static constexpr std::uint64_t mask() { return (1ull << kAxisBits) - 1; }
  static constexpr std::uint64_t ix(NodeId id) { return (id >> (2 * kAxisBits)) & mask(); }
  static constexpr std::uint64_t iy(NodeId id) { return (id >> kAxisBits) & mask(); }
  static constexpr std::uint64_t iz(NodeId id) { return id & mask(); }
  static constexpr NodeId encode(int l, std::uint64_t x, std::uint64_t y, std::uint64_t z) {
    return (static_cast<std::uint64_t>(l) << 58) | (x << (2 * kAxisBits)) | (y << kAxisBits) | z;
  }

 private:
  Vec3 colour_at(Vec3 p) const;
  Config c_;
  float cell_[kMaxLevels + 1]{};
};

}  // namespace amalgam

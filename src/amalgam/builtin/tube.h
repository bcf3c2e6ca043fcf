#pragma once
/// \file The implicit "tube" hierarchy behind builtin:line (the paper's Figure 3) and
/// builtin:poisson (the expected-case model of Eq. 9).
///
/// Nodes are nested intervals along the x axis: node k on level l spans
/// [x0 + k w_l, x0 + (k + 1) w_l] x [-1/2, 1/2]^2 with w_l = n^(l_max - l); x0 = -n^l_max for
/// the line (it ends at x = 0, at its hit primitive) and x0 = 0 for poisson (it starts at
/// x = 0, near its first hits): the hits lie where floats are finest. Each node has n
/// children; leaf cells (level l_max - 1 nodes) hold n primitives, one per unit cell. Each
/// primitive is a sphere of radius 0.2, either on the x axis (the default primary ray hits
/// it) or 0.3 off it (the ray misses it). The camera and a point light sit on the axis at
/// x = x0 - n^l_max, so the default ray and its shadow ray examine the whole line.
///
/// With m > 0 every node also holds m "failed" objects (the paper's "A Second Look"): spheres
/// of radius 0.2 at its centre, 0.3 off the axis at angles 2 pi j / m, listed after its n
/// children. A ray along the axis tests them and misses them, so every entered node costs
/// n + m tests while the traversal still continues through n children.

#include <cmath>
#include <cstdint>

#include "amalgam/builtin/params.h"
#include "amalgam/hierarchy/hierarchy.h"

namespace amalgam {

class TubeHierarchy {
 public:
  enum class Mode { kLine, kPoisson };

  struct Config {
    Mode mode = Mode::kLine;
    int n = 3;               ///< children per node
    int depth = 6;           ///< l_max: primitives live on level l_max
    double alpha = 0.0;      ///< line: opacity of amalgams not holding the hit primitive
    double p = 64.0;         ///< poisson: expected hits along the axis through the scene
    std::uint64_t seed = 0;  ///< poisson: which realisation of the process
    int m = 0;               ///< failed objects per node (n + m <= kMaxChildren)
  };

  explicit TubeHierarchy(const Config& c);

  NodeId root() const { return encode(0, 0); }
  Bbox bounds(NodeId id) const {
    const int l = level_of(id);
    const double w = width_[l];
    const double lo = x0_ + static_cast<double>(index_of(id)) * w;
    return Bbox{{static_cast<float>(lo), -0.5f, -0.5f}, {static_cast<float>(lo + w), 0.5f, 0.5f}};
  }
  Appearance appearance(NodeId id) const;
  template <class F>
  void for_each_child(NodeId id, F&& f) const {
    const int l = level_of(id);
    const std::uint64_t first = index_of(id) * static_cast<std::uint64_t>(c_.n);
    const bool prims = l + 1 == c_.depth;
    for (int j = 0; j < c_.n; ++j) {
      if (prims) {
        if (!f(Child{first + j, true})) return;
      } else if (!f(Child{encode(l + 1, first + j), false})) {
        return;
      }
    }
    const std::uint64_t failed = failed_base(l, index_of(id));
    for (int j = 0; j < c_.m; ++j)
      if (!f(Child{failed + static_cast<std::uint64_t>(j), true})) return;
  }
  std::optional<SurfaceHit> intersect(PrimId k, const Ray& ray) const {
    return intersect_sphere(ray, prim_centre(k), 0.2f);
  }
  Surface surface(PrimId k) const;
  Primitive primitive(PrimId k) const { return Primitive::sphere(prim_centre(k), 0.2f); }
  HierarchyInfo info() const;

  /// True when primitive k lies on the axis (is hit by the default ray).
  bool on_axis(PrimId k) const;
  Vec3 prim_centre(PrimId k) const;
  const Config& config() const { return c_; }
  /// The environment: camera at x0 - n^l_max looking down +x, point light(s) at the camera.
  Environment environment(int lights) const;

  static constexpr int level_of(NodeId id) { return static_cast<int>(id >> 58); }
  static constexpr std::uint64_t index_of(NodeId id) { return id & ((1ull << 58) - 1); }
  static constexpr NodeId encode(int level, std::uint64_t index) {
    return (static_cast<std::uint64_t>(level) << 58) | index;
  }

 private:
  /// The id of the first failed object of node (l, k): failed objects follow the n^l_max
  /// primitives, m per node, nodes in level order.
  std::uint64_t failed_base(int l, std::uint64_t k) const {
    return count_[c_.depth] + (offset_[l] + k) * static_cast<std::uint64_t>(c_.m);
  }

  Config c_;
  double x0_ = -1.0;
  std::uint64_t offset_[kMaxLevels]{};  ///< nodes on the levels above l
  double width_[kMaxLevels]{};
  std::uint64_t count_[kMaxLevels]{};
};

}  // namespace amalgam

#pragma once
/// \file Exact intersection-test counters, as the paper counts cost (one unit per ray/object
/// test of a primitive, bounding volume or amalgam). One `Counters` per thread; merged at the
/// end. Plain increments, no atomics.

#include <array>
#include <cstdint>

namespace amalgam {

enum class RayKind : std::uint8_t { kPrimary = 0, kShadow = 1 };
/// What was tested: a primitive; a node tested only as a container (bounding volume); a
/// node the renderer may render (amalgam); or a cell of a volumetric amalgam read by the cone
/// march (traverse/cone_march.h: one per cell stepped through).
enum class ObjectKind : std::uint8_t {
  kPrimitive = 0,
  kBoundingVolume = 1,
  kAmalgam = 2,
  kCell = 3
};
inline constexpr int kObjectKinds = 4;

/// Levels counted separately (`by_level`); deeper tests are counted on the last one.
inline constexpr int kCountedLevels = 64;

struct Counters {
  /// tests[ray kind][object kind]
  std::array<std::array<std::uint64_t, kObjectKinds>, 2> tests{};
  std::array<std::uint64_t, kCountedLevels> by_level{};
  std::array<std::uint64_t, 2> rays{};
  /// Nodes (bounding volumes and amalgams) a traversal reached -- took from its sorted list
  /// (or, in stored order, entered) and then entered or rendered -- per ray kind. With the
  /// primitive tests this is the paper's count of "objects traversed" (Eq. 4, Figure 4): a
  /// sorted traversal tests all children of a node it enters, but the paper counts only those
  /// reached in sorted order until the first hit, as if a space-partitioning modeller delivered
  /// them in order. `tests` is unchanged by it.
  std::array<std::uint64_t, 2> reached{};

  void count_test(RayKind r, ObjectKind o, int level) { count_tests(r, o, level, 1); }
  /// `n` tests of one kind on one level at once (a node's children tested together): the
  /// same counts as n calls of count_test, in two additions.
  void count_tests(RayKind r, ObjectKind o, int level, std::uint64_t n) {
    tests[static_cast<int>(r)][static_cast<int>(o)] += n;
    // A branch, not a minimum: with a minimum GCC kept the level in a vector register and
    // took it with a 16-byte load of the slot it had just stored 4 bytes of (a failed store
    // forwarding at every node of a counted walk).
    if (static_cast<unsigned>(level) < kCountedLevels) [[likely]]
      by_level[static_cast<unsigned>(level)] += n;
    else
      by_level[kCountedLevels - 1] += n;
  }
  void count_ray(RayKind r) { ++rays[static_cast<int>(r)]; }
  void count_reached(RayKind r) { ++reached[static_cast<int>(r)]; }

  /// The paper's "objects traversed" for ray kind r: nodes reached plus primitives tested.
  std::uint64_t traversed_of(RayKind r) const {
    return reached[static_cast<int>(r)] + tests[static_cast<int>(r)][0];
  }

  std::uint64_t tests_of(RayKind r) const {
    const auto& t = tests[static_cast<int>(r)];
    return t[0] + t[1] + t[2] + t[3];
  }
  std::uint64_t tests_of(ObjectKind o) const {
    return tests[0][static_cast<int>(o)] + tests[1][static_cast<int>(o)];
  }
  std::uint64_t total() const { return tests_of(RayKind::kPrimary) + tests_of(RayKind::kShadow); }

  void merge(const Counters& o) {
    for (int r = 0; r < 2; ++r)
      for (int k = 0; k < kObjectKinds; ++k) tests[r][k] += o.tests[r][k];
    for (int l = 0; l < kCountedLevels; ++l) by_level[l] += o.by_level[l];
    for (int r = 0; r < 2; ++r) rays[r] += o.rays[r], reached[r] += o.reached[r];
  }
};

/// The Counters interface with every operation a no-op: the compiler removes the counting.
struct NullCounters {
  void count_test(RayKind, ObjectKind, int) {}
  void count_tests(RayKind, ObjectKind, int, std::uint64_t) {}
  void count_ray(RayKind) {}
  void count_reached(RayKind) {}
  std::uint64_t total() const { return 0; }
};

}  // namespace amalgam

#pragma once
/// \file The cells a camera ray of the volumetric renderer met, of every object, kept in depth
/// order as the walk hands them over one object at a time (render/volume_integrator.h), with
/// the depth where what is left behind them falls to nothing: the walk need look no deeper.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "amalgam/geometry/ray.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// One cell's stretch of the ray: [t0, t1], its coverage alpha.
struct CellSegment {
  float t0, t1;
  std::uint32_t cell;
  std::uint32_t obj;  ///< the integrator's index of its object (or a world cell's tag)
  float alpha;
};

class CellBlend {
 public:
  /// Sorted by depth (ties by object and cell: the same order on any thread), except the
  /// segments appended since the last merge.
  std::vector<CellSegment> items;

  void clear() {
    items.clear();
    prefix_.assign(1, 1.0f);
    scanned_ = 0;
  }

  /// Merges items[first..) (sorted) into the sorted items[0..first); returns t0 of the first
  /// segment at which the product of 1 - alpha in depth order is `opaque` or less (infinity if
  /// none). The products are taken in depth order from the first segment, resumed where the
  /// merge changed nothing before, so they are the same numbers as a scan from the start.
  float merge(std::size_t first, float opaque) {
    std::size_t k = std::min(scanned_, merge_tail(first));
    float through = prefix_[k];
    prefix_.resize(items.size() + 1);
    float saturated = kInfinity;
    for (; k < items.size(); ++k) {
      through *= 1.0f - items[k].alpha;
      prefix_[k + 1] = through;
      if (through <= opaque) {
        saturated = items[k].t0;
        break;
      }
    }
    scanned_ = k;
    return saturated;
  }

 private:
  static bool by_depth(const CellSegment& a, const CellSegment& b) {
    return a.t0 < b.t0 || (a.t0 == b.t0 && (a.obj < b.obj || (a.obj == b.obj && a.cell < b.cell)));
  }

  /// The merge, stable (an older segment before an equal new one), from the back: only what
  /// lies behind the first new segment moves. Returns the first index whose segment changed.
  std::size_t merge_tail(std::size_t first) {
    if (first == 0 || first == items.size()) return first;
    const auto begin = items.begin();
    const auto lo =
        static_cast<std::size_t>(std::upper_bound(begin, begin + static_cast<std::ptrdiff_t>(first),
                                                  items[first], by_depth) -
                                 begin);
    if (lo == first) return first;  // every new segment lies behind the old ones
    fresh_.assign(begin + static_cast<std::ptrdiff_t>(first), items.end());
    std::size_t out = items.size(), i = first, j = fresh_.size();
    while (j > 0) {
      if (i > lo && by_depth(fresh_[j - 1], items[i - 1]))
        items[--out] = items[--i];
      else
        items[--out] = fresh_[--j];
    }
    return lo;
  }

  /// prefix_[k]: the product of 1 - alpha over items[0..k), valid for k <= scanned_.
  std::vector<float> prefix_;
  std::size_t scanned_ = 0;
  std::vector<CellSegment> fresh_;  ///< merge_tail's copy of the new segments
};

AMALGAM_ISA_END
}  // namespace amalgam

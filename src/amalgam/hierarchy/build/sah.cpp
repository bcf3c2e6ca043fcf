#include "amalgam/hierarchy/build/sah.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_invoke.h>
#include <oneapi/tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>

#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/util/check.h"

namespace amalgam {

namespace {

constexpr int kMaxBins = 256;
constexpr std::uint32_t kParallelSubtree = 4096;  // items: below, build the subtree serially
constexpr std::uint32_t kParallelBinning = 1u << 16;

/// The bin of a scaled centroid offset; NaN and negative go to bin 0, +inf to the last (so
/// NaN or infinite input coordinates cannot index out of range).
int bin_of(float f, int nb) {
  return f > 0.0f ? (f < static_cast<float>(nb) ? static_cast<int>(f) : nb - 1) : 0;
}

struct BinaryNode {
  Bbox box;
  std::uint32_t a = 0, b = 0;  // children, or (begin, count) of a leaf
  bool leaf = true;
};

struct Bin {
  Bbox box, cbox;  // item bounds and centroid bounds
  std::uint32_t n = 0;
};

/// Bins of the three axes; only the first `n` per axis are used (small ranges use fewer
/// bins, so that a node does not pay for initialising all of them).
struct Bins {
  explicit Bins(int n = 0) : n(n), bins(static_cast<std::size_t>(3 * n)) {}
  Bin* axis(int a) { return bins.data() + a * n; }
  const Bin* axis(int a) const { return bins.data() + a * n; }
  int n;
  std::vector<Bin> bins;
};

/// An item as the builder moves it: its box and its index. Binning and partitioning read the
/// items in place, in order (a node's items are contiguous), instead of gathering boxes and
/// centroids through an index array; the centroid is the box's centre, computed when needed.
struct Ref {
  Bbox box;
  std::uint32_t item;
};

class BinaryBuilder {
 public:
  BinaryBuilder(std::span<const Bbox> boxes, const SahConfig& c) : cfg_(c) {
    const auto n = static_cast<std::uint32_t>(boxes.size());
    refs_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) refs_[i] = {boxes[i], i};
    bins_ = std::clamp(cfg_.bins, 2, kMaxBins);
    leaf_ = static_cast<std::uint32_t>(std::clamp(cfg_.leaf_size, 1, kMaxChildren));
  }

  void run() {
    nodes_.resize(std::max<std::size_t>(1, 2 * refs_.size()));
    Bbox box, cbox;
    for (const Ref& r : refs_) box.extend(r.box), cbox.extend(r.box.center());
    build(0, 0, static_cast<std::uint32_t>(refs_.size()), box, cbox);
  }

  /// The same, freeing `boxes` once copied (before the nodes are allocated: a lower peak).
  BinaryBuilder(std::vector<Bbox>&& boxes, const SahConfig& c)
      : BinaryBuilder(std::span<const Bbox>(boxes), c) {
    boxes = {};
  }

  /// Item i of the final order (leaves' items are ranges of it).
  std::uint32_t item(std::size_t i) const { return refs_[i].item; }

  std::vector<BinaryNode> nodes_;

 private:
  Bins bin(std::uint32_t begin, std::uint32_t end, const Bbox& cbox, int nb) const {
    const Vec3 lo = cbox.lo, ext = cbox.extent();
    Vec3 scale;
    for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0 ? nb / ext[a] : 0.0f;
    auto fill = [&](std::uint32_t b, std::uint32_t e, Bins& out) {
      for (std::uint32_t i = b; i < e; ++i) {
        const Bbox& item = refs_[i].box;
        const Vec3 c = item.center();
        for (int a = 0; a < 3; ++a) {
          const int k = bin_of((c[a] - lo[a]) * scale[a], nb);
          Bin& bin = out.axis(a)[k];
          bin.box.extend(item);
          bin.cbox.extend(c);
          ++bin.n;
        }
      }
    };
    Bins result(nb);
    if (cfg_.parallel && end - begin >= kParallelBinning) {
      result = tbb::parallel_reduce(
          tbb::blocked_range<std::uint32_t>(begin, end, 8192), Bins(nb),
          [&](const tbb::blocked_range<std::uint32_t>& r, Bins acc) {
            fill(r.begin(), r.end(), acc);
            return acc;
          },
          [&](Bins x, const Bins& y) {
            for (int a = 0; a < 3; ++a)
              for (int k = 0; k < nb; ++k) {
                x.axis(a)[k].box.extend(y.axis(a)[k].box);
                x.axis(a)[k].cbox.extend(y.axis(a)[k].cbox);
                x.axis(a)[k].n += y.axis(a)[k].n;
              }
            return x;
          });
    } else {
      fill(begin, end, result);
    }
    return result;
  }

  void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, const Bbox& box,
             const Bbox& cbox) {
    BinaryNode& out = nodes_[node];
    out.box = box;
    const std::uint32_t count = end - begin;
    if (count <= leaf_) {
      out.leaf = true, out.a = begin, out.b = count;
      return;
    }
    // Best split over all axes and bin boundaries.
    int best_axis = -1, best_k = 0;
    float best_cost = kInfinity;
    Bbox lbox, rbox, lcbox, rcbox;
    const Vec3 ext = cbox.extent();
    const int nb = static_cast<int>(
        std::min<std::uint32_t>(static_cast<std::uint32_t>(bins_), std::max(count, 4u)));
    if (max_component(ext) > 0) {
      const Bins bins = bin(begin, end, cbox, nb);
      for (int a = 0; a < 3; ++a) {
        if (!(ext[a] > 0)) continue;
        const Bin* bs = bins.axis(a);
        std::array<float, kMaxBins> right_cost{};
        Bbox acc;
        std::uint32_t n = 0;
        for (int k = nb - 1; k > 0; --k) {
          acc.extend(bs[k].box);
          n += bs[k].n;
          right_cost[k] = n ? surface_area(acc) * static_cast<float>(n) : 0.0f;
        }
        acc = Bbox{};
        n = 0;
        for (int k = 0; k < nb - 1; ++k) {
          acc.extend(bs[k].box);
          n += bs[k].n;
          if (n == 0 || n == count) continue;
          const float cost = surface_area(acc) * static_cast<float>(n) + right_cost[k + 1];
          if (cost < best_cost) best_cost = cost, best_axis = a, best_k = k;
        }
      }
      if (best_axis >= 0) {
        const Bin* bs = bins.axis(best_axis);
        for (int k = 0; k < nb; ++k) {
          (k <= best_k ? lbox : rbox).extend(bs[k].box);
          (k <= best_k ? lcbox : rcbox).extend(bs[k].cbox);
        }
      }
    }
    std::uint32_t mid;
    if (best_axis >= 0) {
      const float lo = cbox.lo[best_axis];
      const float scale = nb / ext[best_axis];
      const int bins = nb, k = best_k, a = best_axis;
      mid = static_cast<std::uint32_t>(
          std::partition(
              refs_.begin() + begin, refs_.begin() + end,
              [&](const Ref& r) { return bin_of((r.box.center()[a] - lo) * scale, bins) <= k; }) -
          refs_.begin());
    } else {
      mid = begin + count / 2;  // all centroids coincide: any split is as good
    }
    if (best_axis < 0 || mid == begin || mid == end) {
      mid = begin + count / 2;
      lbox = rbox = lcbox = rcbox = Bbox{};
      for (std::uint32_t i = begin; i < mid; ++i)
        lbox.extend(refs_[i].box), lcbox.extend(refs_[i].box.center());
      for (std::uint32_t i = mid; i < end; ++i)
        rbox.extend(refs_[i].box), rcbox.extend(refs_[i].box.center());
    }
    const std::uint32_t left = next_.fetch_add(2, std::memory_order_relaxed);
    out.leaf = false, out.a = left, out.b = left + 1;
    if (cfg_.parallel && count >= kParallelSubtree) {
      tbb::parallel_invoke([&] { build(left, begin, mid, lbox, lcbox); },
                           [&] { build(left + 1, mid, end, rbox, rcbox); });
    } else {
      build(left, begin, mid, lbox, lcbox);
      build(left + 1, mid, end, rbox, rcbox);
    }
  }

  SahConfig cfg_;
  std::vector<Ref> refs_;
  int bins_ = 16;
  std::uint32_t leaf_ = 4;
  std::atomic<std::uint32_t> next_{1};
};

SahTree collapse(const BinaryBuilder& b, std::size_t items, const SahConfig& config) {
  const auto& bin = b.nodes_;
  const auto arity = static_cast<std::size_t>(std::clamp(config.arity, 2, kMaxChildren));

  // Collapse breadth-first: open the child with the largest surface area until a node has
  // `arity` children (or only leaves are left).
  SahTree t;
  t.order.reserve(items);
  t.nodes.push_back({bin[0].box, 0, 0, true});
  t.level.push_back(0);
  std::vector<std::uint32_t> queue{0};  // binary node of wide node q
  std::vector<std::uint32_t> kids;
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const BinaryNode& n = bin[queue[q]];
    const std::uint8_t level = t.level[q];
    t.depth = std::max<int>(t.depth, level);
    if (n.leaf) {
      t.nodes[q].first = static_cast<std::uint32_t>(t.order.size());
      t.nodes[q].count = checked_narrow<std::uint16_t>(n.b, "SAH leaf size");
      t.nodes[q].leaf = true;
      for (std::uint32_t k = n.a; k < n.a + n.b; ++k) t.order.push_back(b.item(k));
      continue;
    }
    kids = {n.a, n.b};
    while (kids.size() < arity) {
      int best = -1;
      float best_area = -1.0f;
      for (std::size_t i = 0; i < kids.size(); ++i) {
        if (bin[kids[i]].leaf) continue;
        const float area = surface_area(bin[kids[i]].box);
        if (area > best_area) best_area = area, best = static_cast<int>(i);
      }
      if (best < 0) break;
      const BinaryNode& open = bin[kids[static_cast<std::size_t>(best)]];
      kids[static_cast<std::size_t>(best)] = open.a;
      kids.insert(kids.begin() + best + 1, open.b);
    }
    t.nodes[q].first = static_cast<std::uint32_t>(t.nodes.size());
    t.nodes[q].count = checked_narrow<std::uint16_t>(kids.size(), "SAH node arity");
    t.nodes[q].leaf = false;
    for (std::uint32_t k : kids) {
      t.nodes.push_back({bin[k].box, 0, 0, true});
      t.level.push_back(static_cast<std::uint8_t>(std::min(level + 1, 255)));
      queue.push_back(k);
    }
  }
  return t;
}

}  // namespace

SahTree build_sah(std::span<const Bbox> boxes, const SahConfig& config) {
  BinaryBuilder b(boxes, config);
  b.run();
  return collapse(b, boxes.size(), config);
}

SahTree build_sah(std::vector<Bbox>&& boxes, const SahConfig& config) {
  const std::size_t items = boxes.size();
  BinaryBuilder b(std::move(boxes), config);
  b.run();
  return collapse(b, items, config);
}

}  // namespace amalgam

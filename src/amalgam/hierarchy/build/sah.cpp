#include "amalgam/hierarchy/build/sah.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_invoke.h>
#include <oneapi/tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstddef>
#include <memory>
#include <new>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/util/check.h"
#include "amalgam/util/parallel.h"

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

/// Four floats (x, y, z and a spare lane) and the few operations the binning needs: SSE2 where
/// there is SSE2, else plain loops. min/max take the accumulator second and return it when the
/// other operand is NaN, as std::min(acc, x) and std::max(acc, x) (Bbox::extend) do.
struct F4 {
#if defined(__SSE2__)
  __m128 v;
  static F4 load(const float* p) {
    return {_mm_load_ps(p)};
  }
  static F4 set(float x, float y, float z) {
    return {_mm_setr_ps(x, y, z, 0.0f)};
  }
  static F4 splat(float x) {
    return {_mm_set1_ps(x)};
  }
  friend F4 operator+(F4 a, F4 b) {
    return {_mm_add_ps(a.v, b.v)};
  }
  friend F4 operator-(F4 a, F4 b) {
    return {_mm_sub_ps(a.v, b.v)};
  }
  friend F4 operator*(F4 a, F4 b) {
    return {_mm_mul_ps(a.v, b.v)};
  }
  friend F4 min(F4 x, F4 acc) {
    return {_mm_min_ps(x.v, acc.v)};
  }
  friend F4 max(F4 x, F4 acc) {
    return {_mm_max_ps(x.v, acc.v)};
  }
  /// The same with the spare lane zero (bitwise: no arithmetic on what it held).
  F4 xyz() const {
    return {_mm_and_ps(v, _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)))};
  }
  /// The bins of the lanes of f, as bin_of.
  void bins(F4 top, int out[4]) const {
    const __m128 f = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), top.v);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_cvttps_epi32(f));
  }
  void store(float* p) const {
    _mm_store_ps(p, v);
  }
#else
  float v[4];
  static F4 load(const float* p) {
    return {{p[0], p[1], p[2], p[3]}};
  }
  static F4 set(float x, float y, float z) {
    return {{x, y, z, 0.0f}};
  }
  static F4 splat(float x) {
    return {{x, x, x, x}};
  }
  template <class Op>
  static F4 map(F4 a, F4 b, Op op) {
    return {{op(a.v[0], b.v[0]), op(a.v[1], b.v[1]), op(a.v[2], b.v[2]), op(a.v[3], b.v[3])}};
  }
  friend F4 operator+(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x + y; });
  }
  friend F4 operator-(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x - y; });
  }
  friend F4 operator*(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x * y; });
  }
  friend F4 min(F4 x, F4 acc) {
    return map(acc, x, [](float c, float y) { return std::min(c, y); });
  }
  friend F4 max(F4 x, F4 acc) {
    return map(acc, x, [](float c, float y) { return std::max(c, y); });
  }
  void bins(F4 top, int out[4]) const {
    for (int i = 0; i < 4; ++i) out[i] = bin_of(v[i], static_cast<int>(top.v[i]) + 1);
  }
  F4 xyz() const {
    return {{v[0], v[1], v[2], 0.0f}};
  }
  void store(float* p) const {
    std::copy(v, v + 4, p);
  }
#endif
};

/// Not initialised: the node array is allocated for the worst case (2n - 1 nodes) and only the
/// nodes built are ever written (the pages of the rest are never touched).
struct BinaryNode {
  Bbox box;
  std::uint32_t a, b;  // children, or (begin, count) of a leaf
  bool leaf;
};

/// An item as the builder moves it: its box, its index in the spare lane of `lo` (the box's
/// lanes are masked before arithmetic) and a zero in the spare lane of `hi`. Binning and
/// partitioning read the items in place, in order (a node's items are contiguous), instead of
/// gathering boxes through an index array; the centroid is computed when needed.
struct alignas(16) Ref {
  float lo[4];
  float hi[4];
  std::uint32_t item() const { return std::bit_cast<std::uint32_t>(lo[3]); }
  /// The box's corners (spare lanes zero) and its centroid, as Bbox::center computes it.
  void load(F4& l, F4& h, F4& c) const {
    l = F4::load(lo).xyz(), h = F4::load(hi);
    c = (l + h) * F4::splat(0.5f);
  }
};

/// surface_area of the box [lo, hi] (spare lanes ignored), bit for bit: the same extent, and a
/// box is empty (some lo > hi) exactly when some extent hi - lo is negative.
float area(F4 lo, F4 hi) {
  alignas(16) float e[4];
  (hi - lo).store(e);
  if (e[0] < 0.0f || e[1] < 0.0f || e[2] < 0.0f) return 0.0f;
  return 2.0f * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
}

/// Bins of the three axes, `nb` of each used: their boxes and item counts.
struct Bins {
  explicit Bins(int nb) : nb(nb) {
    for (int k = 0; k < 3 * nb; ++k)
      lo[k] = F4::splat(kInfinity), hi[k] = F4::splat(-kInfinity), n[k] = 0;
  }
  Bbox box(int a, int k) const {
    alignas(16) float l[4], h[4];
    lo[a * nb + k].store(l), hi[a * nb + k].store(h);
    return {{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
  }
  void add(const Bins& o) {
    for (int k = 0; k < 3 * nb; ++k)
      lo[k] = min(o.lo[k], lo[k]), hi[k] = max(o.hi[k], hi[k]), n[k] += o.n[k];
  }
  int nb;
  F4 lo[3 * kMaxBins], hi[3 * kMaxBins];
  std::uint32_t n[3 * kMaxBins];
};

/// A node's split: where its items go (axis, last bin on the left) and the children's boxes.
struct Split {
  int axis = -1, k = 0, nb = 0;
  float lo = 0.0f, scale = 0.0f;  // bin of an item: bin_of((centroid - lo) * scale, nb)
  Bbox lbox, rbox;
};

class BinaryBuilder {
 public:
  BinaryBuilder(std::span<const Bbox> boxes, const SahConfig& c) : cfg_(c) {
    const auto n = static_cast<std::uint32_t>(boxes.size());
    refs_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      const Bbox& b = boxes[i];
      refs_[i] = {{b.lo.x, b.lo.y, b.lo.z, std::bit_cast<float>(i)}, {b.hi.x, b.hi.y, b.hi.z, 0}};
    }
    bins_ = std::clamp(cfg_.bins, 2, kMaxBins);
    leaf_ = static_cast<std::uint32_t>(std::clamp(cfg_.leaf_size, 1, kMaxChildren));
  }

  void run() {
    nodes_ =
        std::make_unique_for_overwrite<BinaryNode[]>(std::max<std::size_t>(1, 2 * refs_.size()));
    Bbox box, cbox;
    for (const Ref& r : refs_) {
      const Bbox b{{r.lo[0], r.lo[1], r.lo[2]}, {r.hi[0], r.hi[1], r.hi[2]}};
      box.extend(b), cbox.extend(b.center());
    }
    build(0, 0, static_cast<std::uint32_t>(refs_.size()), box, cbox);
  }

  /// The same, freeing `boxes` once copied (before the nodes are allocated: a lower peak).
  BinaryBuilder(std::vector<Bbox>&& boxes, const SahConfig& c)
      : BinaryBuilder(std::span<const Bbox>(boxes), c) {
    boxes = {};
  }

  /// Item i of the final order (leaves' items are ranges of it).
  std::uint32_t item(std::size_t i) const { return refs_[i].item(); }

  std::unique_ptr<BinaryNode[]> nodes_;

 private:
  void fill(std::uint32_t b, std::uint32_t e, F4 clo, F4 scale, Bins& out) const {
    const F4 top = F4::splat(static_cast<float>(out.nb - 1));
    alignas(16) int k[4];
    for (std::uint32_t i = b; i < e; ++i) {
      F4 lo, hi, c;
      refs_[i].load(lo, hi, c);
      ((c - clo) * scale).bins(top, k);
      for (int a = 0; a < 3; ++a) {
        const int j = a * out.nb + k[a];
        out.lo[j] = min(lo, out.lo[j]), out.hi[j] = max(hi, out.hi[j]), ++out.n[j];
      }
    }
  }

  /// The best binned SAH split of items [begin, end) (axis -1: none, all centroids coincide
  /// or no bin boundary separates them), evaluated as Wald (2007) does.
  [[gnu::noinline]] Split choose(std::uint32_t begin, std::uint32_t end, const Bbox& cbox) const {
    Split s;
    const std::uint32_t count = end - begin;
    const Vec3 ext = cbox.extent();
    if (!(max_component(ext) > 0)) return s;
    const int nb = static_cast<int>(
        std::min<std::uint32_t>(static_cast<std::uint32_t>(bins_), std::max(count, 4u)));
    Vec3 scale;
    for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0 ? nb / ext[a] : 0.0f;
    const F4 clo = F4::set(cbox.lo.x, cbox.lo.y, cbox.lo.z);
    const F4 sc = F4::set(scale.x, scale.y, scale.z);
    std::unique_ptr<Bins> owned;  // large ranges: the partial bins of the tasks on the heap
    alignas(16) std::byte local[sizeof(Bins)];
    Bins* bins;
    if (cfg_.parallel && count >= kParallelBinning) {
      owned = std::make_unique<Bins>(tbb::parallel_reduce(
          tbb::blocked_range<std::uint32_t>(begin, end, 8192), Bins(nb),
          [&](const tbb::blocked_range<std::uint32_t>& r, Bins acc) {
            fill(r.begin(), r.end(), clo, sc, acc);
            return acc;
          },
          [](Bins x, const Bins& y) {
            x.add(y);
            return x;
          }));
      bins = owned.get();
    } else {
      bins = new (local) Bins(nb);
      fill(begin, end, clo, sc, *bins);
    }
    float best_cost = kInfinity;
    for (int a = 0; a < 3; ++a) {
      if (!(ext[a] > 0)) continue;
      float right_cost[kMaxBins];  // [k]: of bins k..nb-1, for k >= 1
      F4 lo = F4::splat(kInfinity), hi = F4::splat(-kInfinity);
      std::uint32_t n = 0;
      for (int k = nb - 1; k > 0; --k) {
        lo = min(bins->lo[a * nb + k], lo), hi = max(bins->hi[a * nb + k], hi);
        n += bins->n[a * nb + k];
        right_cost[k] = n ? area(lo, hi) * static_cast<float>(n) : 0.0f;
      }
      lo = F4::splat(kInfinity), hi = F4::splat(-kInfinity);
      n = 0;
      for (int k = 0; k < nb - 1; ++k) {
        lo = min(bins->lo[a * nb + k], lo), hi = max(bins->hi[a * nb + k], hi);
        n += bins->n[a * nb + k];
        if (n == 0 || n == count) continue;
        const float cost = area(lo, hi) * static_cast<float>(n) + right_cost[k + 1];
        if (cost < best_cost) best_cost = cost, s.axis = a, s.k = k;
      }
    }
    if (s.axis >= 0) {
      for (int k = 0; k < nb; ++k) (k <= s.k ? s.lbox : s.rbox).extend(bins->box(s.axis, k));
      s.nb = nb, s.lo = cbox.lo[s.axis], s.scale = nb / ext[s.axis];
    }
    return s;
  }

  /// Partitions items [begin, end) by `s` as std::partition does (the same exchanges, so the
  /// same order), computing the centroid bounds of both sides on the way. Returns the first
  /// item of the right side.
  std::uint32_t partition(std::uint32_t begin, std::uint32_t end, const Split& s, Bbox& lcbox,
                          Bbox& rcbox) {
    F4 lc_lo = F4::splat(kInfinity), lc_hi = F4::splat(-kInfinity);
    F4 rc_lo = lc_lo, rc_hi = lc_hi;
    // Classifies item i (once) and extends the centroid bounds of its side.
    auto left = [&](std::uint32_t i) {
      F4 lo, hi, c;
      refs_[i].load(lo, hi, c);
      alignas(16) float cc[4];
      c.store(cc);
      const bool l = bin_of((cc[s.axis] - s.lo) * s.scale, s.nb) <= s.k;
      if (l)
        lc_lo = min(c, lc_lo), lc_hi = max(c, lc_hi);
      else
        rc_lo = min(c, rc_lo), rc_hi = max(c, rc_hi);
      return l;
    };
    std::uint32_t first = begin, last = end;
    for (;;) {
      for (;; ++first) {
        if (first == last) goto done;
        if (!left(first)) break;
      }
      for (--last;; --last) {
        if (first == last) goto done;
        if (left(last)) break;
      }
      std::swap(refs_[first], refs_[last]);
      ++first;
    }
  done:
    alignas(16) float l[4], h[4];
    lc_lo.store(l), lc_hi.store(h);
    lcbox = {{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
    rc_lo.store(l), rc_hi.store(h);
    rcbox = {{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
    return first;
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
    const Split s = choose(begin, end, cbox);
    Bbox lbox = s.lbox, rbox = s.rbox, lcbox, rcbox;
    std::uint32_t mid = begin + count / 2;  // all centroids coincide: any split is as good
    if (s.axis >= 0) mid = partition(begin, end, s, lcbox, rcbox);
    if (s.axis < 0 || mid == begin || mid == end) {
      mid = begin + count / 2;
      lbox = rbox = lcbox = rcbox = Bbox{};
      for (std::uint32_t i = begin; i < end; ++i) {
        const Ref& r = refs_[i];
        const Bbox b{{r.lo[0], r.lo[1], r.lo[2]}, {r.hi[0], r.hi[1], r.hi[2]}};
        (i < mid ? lbox : rbox).extend(b), (i < mid ? lcbox : rcbox).extend(b.center());
      }
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
  const BinaryNode* bin = b.nodes_.get();
  const auto arity = static_cast<std::size_t>(std::clamp(config.arity, 2, kMaxChildren));
  auto each = [&](std::size_t n, auto&& f) { for_each_index(n, f, 4096, 1024, config.parallel); };

  // Collapse breadth-first: open the child with the largest surface area until a node has
  // `arity` children (or only leaves are left). One level at a time: its nodes are opened in
  // parallel, their children's and items' places follow in node order (a prefix sum), and
  // are filled in parallel; the same tree as taking the nodes one by one from a queue.
  SahTree t;
  t.order.resize(items);
  t.nodes.push_back({bin[0].box, 0, 0, true});
  t.level.push_back(0);
  std::vector<std::uint32_t> queue{0};  // binary node of wide node q
  std::vector<std::uint32_t> kids;      // of the level's node j: [j * arity, + count[j])
  std::vector<std::uint32_t> count;
  std::size_t next_item = 0;
  for (std::size_t begin = 0, level = 0; begin < t.nodes.size(); ++level) {
    const std::size_t end = t.nodes.size(), m = end - begin;
    t.depth = static_cast<int>(std::min<std::size_t>(level, 255));
    kids.resize(m * arity);
    count.assign(m, 0);
    each(m, [&](std::size_t j) {
      const BinaryNode& n = bin[queue[begin + j]];
      if (n.leaf) return;
      std::uint32_t* k = kids.data() + j * arity;
      std::size_t size = 2;
      k[0] = n.a, k[1] = n.b;
      while (size < arity) {
        int best = -1;
        float best_area = -1.0f;
        for (std::size_t i = 0; i < size; ++i) {
          if (bin[k[i]].leaf) continue;
          const float area = surface_area(bin[k[i]].box);
          if (area > best_area) best_area = area, best = static_cast<int>(i);
        }
        if (best < 0) break;
        const BinaryNode& open = bin[k[best]];
        std::copy_backward(k + best + 1, k + size, k + size + 1);
        k[best] = open.a, k[best + 1] = open.b, ++size;
      }
      count[j] = static_cast<std::uint32_t>(size);
    });
    std::size_t at = end;
    for (std::size_t j = 0; j < m; ++j) {
      const BinaryNode& n = bin[queue[begin + j]];
      SahTree::Node& node = t.nodes[begin + j];
      node.leaf = n.leaf;
      if (n.leaf) {
        node.first = static_cast<std::uint32_t>(next_item);
        node.count = checked_narrow<std::uint16_t>(n.b, "SAH leaf size");
        next_item += n.b;
      } else {
        node.first = static_cast<std::uint32_t>(at);
        node.count = checked_narrow<std::uint16_t>(count[j], "SAH node arity");
        at += count[j];
      }
    }
    t.nodes.resize(at);
    t.level.resize(at, static_cast<std::uint8_t>(std::min<std::size_t>(level + 1, 255)));
    queue.resize(at);
    each(m, [&](std::size_t j) {
      const BinaryNode& n = bin[queue[begin + j]];
      const SahTree::Node& node = t.nodes[begin + j];
      if (n.leaf) {
        for (std::uint32_t k = 0; k < n.b; ++k) t.order[node.first + k] = b.item(n.a + k);
        return;
      }
      for (std::uint32_t c = 0; c < node.count; ++c) {
        const std::uint32_t k = kids[j * arity + c];
        t.nodes[node.first + c] = {bin[k].box, 0, 0, true};
        queue[node.first + c] = k;
      }
    });
    begin = end;
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

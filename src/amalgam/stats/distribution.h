#pragma once
/// \file An exact distribution of per-primary-ray costs (integers), for mean and percentiles.

#include <cstdint>
#include <map>
#include <vector>

namespace amalgam {

/// Exact histogram of non-negative integers: dense below kDense, a sorted map above.
class CostDistribution {
 public:
  static constexpr std::uint64_t kDense = 1u << 14;

  CostDistribution() : dense_(kDense, 0) {}
  void add(std::uint64_t v, std::uint64_t times = 1) {
    count_ += times;
    sum_ += static_cast<long double>(v) * static_cast<long double>(times);
    if (v < kDense)
      dense_[v] += times;
    else
      sparse_[v] += times;
  }
  /// Calls f(value, times) for every value present, in increasing order.
  template <class F>
  void for_each(F&& f) const {
    for (std::uint64_t v = 0; v < kDense; ++v)
      if (dense_[v]) f(v, dense_[v]);
    for (const auto& [v, c] : sparse_) f(v, c);
  }
  void merge(const CostDistribution& o);
  std::uint64_t count() const { return count_; }
  double mean() const { return count_ ? static_cast<double>(sum_) / count_ : 0.0; }
  /// The smallest value v such that at least q * count values are <= v (q in [0, 1]).
  std::uint64_t quantile(double q) const;
  std::uint64_t max() const;

 private:
  std::vector<std::uint64_t> dense_;
  std::map<std::uint64_t, std::uint64_t> sparse_;
  std::uint64_t count_ = 0;
  long double sum_ = 0;  // exact for sums below 2^64
};

}  // namespace amalgam

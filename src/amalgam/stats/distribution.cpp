#include "amalgam/stats/distribution.h"

#include <cmath>

namespace amalgam {

void CostDistribution::merge(const CostDistribution& o) {
  for (std::uint64_t v = 0; v < kDense; ++v) dense_[v] += o.dense_[v];
  for (const auto& [v, c] : o.sparse_) sparse_[v] += c;
  count_ += o.count_;
  sum_ += o.sum_;
}

std::uint64_t CostDistribution::quantile(double q) const {
  if (count_ == 0) return 0;
  const auto need = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_)));
  const std::uint64_t target = need == 0 ? 1 : need;
  std::uint64_t seen = 0;
  for (std::uint64_t v = 0; v < kDense; ++v) {
    seen += dense_[v];
    if (seen >= target) return v;
  }
  for (const auto& [v, c] : sparse_) {
    seen += c;
    if (seen >= target) return v;
  }
  return max();
}

std::uint64_t CostDistribution::max() const {
  if (!sparse_.empty()) return sparse_.rbegin()->first;
  for (std::uint64_t v = kDense; v-- > 0;)
    if (dense_[v]) return v;
  return 0;
}

}  // namespace amalgam

#pragma once
/// \file The noise experiments' estimates with their error bars: the per-sample variance of a
/// render across seeds, its standard error, and the ratio of two "tests to reach equal noise"
/// (sigma^2 x tests per sample) with a 95 % interval, judged as below 1, above 1 or a tie.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "amalgam/analysis/experiments/common.h"

namespace amalgam::experiments::detail {

/// Per-sample variance sigma^2 of the pixels' luminance (the mean over pixels of each pixel's
/// variance across seeds, times spp), its standard error (the spread of the per-pixel
/// variances over the pixels, / sqrt(pixels)), and the intersection tests per sample.
struct VarianceEstimate {
  double sigma2 = 0, se = 0, tests_per_sample = 0;
};

inline VarianceEstimate variance_across_seeds(const LoadedScene& s, RenderOptions o, int seeds,
                                              std::uint64_t first_seed) {
  std::vector<double> sum, sum2;
  double tests = 0;
  for (int k = 0; k < seeds; ++k) {
    o.seed = first_seed + static_cast<std::uint64_t>(k);
    const RenderOutput out = render(s, o);
    if (sum.empty()) sum.assign(out.image.size(), 0), sum2.assign(out.image.size(), 0);
    for (std::size_t i = 0; i < out.image.size(); ++i) {
      const double l = luma(out.image[i]);
      sum[i] += l, sum2[i] += l * l;
    }
    tests += u(out.counters.total());
  }
  const double n = static_cast<double>(sum.size());
  double mean = 0, mean2 = 0;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double m = sum[i] / seeds;
    const double v = std::max(0.0, sum2[i] / seeds - m * m) * seeds / (seeds - 1) * o.spp;
    mean += v, mean2 += v * v;
  }
  mean /= n, mean2 /= n;
  VarianceEstimate e;
  e.sigma2 = mean;
  e.se = std::sqrt(std::max(0.0, mean2 - mean * mean) / std::max(1.0, n - 1));
  e.tests_per_sample = tests / (double(seeds) * o.width * o.height * o.spp);
  return e;
}

/// The mean of several estimates of one sigma^2 (e.g. at several spp), errors combined.
inline VarianceEstimate mean_of(const std::vector<VarianceEstimate>& es) {
  VarianceEstimate m;
  double se2 = 0;
  for (const VarianceEstimate& e : es) {
    m.sigma2 += e.sigma2, m.tests_per_sample += e.tests_per_sample, se2 += e.se * e.se;
  }
  const double k = static_cast<double>(es.size());
  m.sigma2 /= k, m.tests_per_sample /= k, m.se = std::sqrt(se2) / k;
  return m;
}

/// value = (a.sigma2 a.tests) / (b.sigma2 b.tests) with a 95 % interval [lo, hi] (two standard
/// errors of its logarithm, the two variances independent; the test counts taken as exact);
/// order -1 when hi < 1, +1 when lo > 1, 0 a tie.
struct CostRatio {
  double value = 0, lo = 0, hi = 0;
  int order = 0;
};

inline CostRatio cost_ratio(const VarianceEstimate& a, const VarianceEstimate& b,
                            bool with_tests = true) {
  CostRatio r;
  r.value = a.sigma2 / b.sigma2 * (with_tests ? a.tests_per_sample / b.tests_per_sample : 1.0);
  const double rel = std::sqrt(std::pow(a.se / a.sigma2, 2) + std::pow(b.se / b.sigma2, 2));
  r.lo = r.value * std::exp(-2 * rel), r.hi = r.value * std::exp(2 * rel);
  r.order = r.hi < 1 ? -1 : r.lo > 1 ? 1 : 0;
  return r;
}

/// "0.93 [0.88, 0.98]".
inline std::string with_interval(const CostRatio& r) {
  return fmt(r.value) + " [" + fmt(r.lo) + ", " + fmt(r.hi) + "]";
}

}  // namespace amalgam::experiments::detail

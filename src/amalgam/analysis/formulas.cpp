/// \file Implementation of the Thompson & Fussell (TR-91-01) cost formulas; see formulas.h for
/// the equations, their derivations and which printed forms are correct.

#include "amalgam/analysis/formulas.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "amalgam/util/error.h"

namespace amalgam::formulas {
namespace {

void require(bool ok, const char* what) {
  if (!ok) throw InternalError(std::string("amalgam::formulas: ") + what);
}

std::uint64_t checked_add(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r;
  if (__builtin_add_overflow(a, b, &r)) {
    throw std::overflow_error("amalgam::formulas: count exceeds uint64");
  }
  return r;
}

std::uint64_t checked_mul(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r;
  if (__builtin_mul_overflow(a, b, &r)) {
    throw std::overflow_error("amalgam::formulas: count exceeds uint64");
  }
  return r;
}

std::uint64_t checked_pow(std::uint64_t n, int e) {
  std::uint64_t r = 1;
  for (int i = 0; i < e; ++i) r = checked_mul(r, n);
  return r;
}

/// sum_{i=0}^{l} n^i, exactly.
std::uint64_t power_sum_exact(int n, int l) {
  require(n >= 1, "branching factor n must be >= 1");
  require(l >= 0, "level must be >= 0");
  std::uint64_t sum = 0, term = 1;
  for (int i = 0; i <= l; ++i) {
    sum = checked_add(sum, term);
    if (i < l) term = checked_mul(term, static_cast<std::uint64_t>(n));
  }
  return sum;
}

/// sum_{i=0}^{l} n^i in floating point (exact while the result fits the long double mantissa).
long double power_sum(int n, int l) {
  require(n >= 1, "branching factor n must be >= 1");
  require(l >= 0, "level must be >= 0");
  long double sum = 0, term = 1;
  for (int i = 0; i <= l; ++i) {
    sum += term;
    term *= n;
  }
  return sum;
}

/// log_n(b).
double log_base(int n, double b) {
  return std::log(b) / std::log(static_cast<double>(n));
}

/// G(n, mu) = sum_{j=0}^{n-1} e^{-j mu} = expm1(-n mu)/expm1(-mu): the expected number of n
/// siblings processed when each one's subtree independently stops the ray with probability
/// 1 - e^{-mu} (equivalently the mean of Eq. 9's distribution with b = n, p/b = mu).
double siblings_processed(int n, double mu) {
  if (mu == 0.0) return n;
  return std::expm1(-n * mu) / std::expm1(-mu);
}

void require_visits_args(double p, double b) {
  require(p >= 0.0, "p must be >= 0");
  require(b >= 1.0, "b must be >= 1");
}

}  // namespace

// --- Worst case -----------------------------------------------------------------------------

double c_t0(int n, int l_max) {
  return static_cast<double>(power_sum(n, l_max));
}
std::uint64_t c_t0_exact(int n, int l_max) {
  return power_sum_exact(n, l_max);
}

double c_s0(int n, int l1) {
  return static_cast<double>(power_sum(n, l1));
}
std::uint64_t c_s0_exact(int n, int l1) {
  return power_sum_exact(n, l1);
}

double c_sd1(int n, int l1) {
  return static_cast<double>(std::pow(static_cast<long double>(n), l1) * power_sum(n, l1));
}
std::uint64_t c_sd1_exact(int n, int l1) {
  const std::uint64_t s0 = power_sum_exact(n, l1);
  return checked_mul(checked_pow(static_cast<std::uint64_t>(n), l1), s0);
}

double deterministic_total(int n, int l1) {
  return c_s0(n, l1) + c_sd1(n, l1);
}

double stochastic_total(int n, int l1) {
  return 2.0 * c_s0(n, l1);
}
std::uint64_t stochastic_total_exact(int n, int l1) {
  return checked_mul(2, power_sum_exact(n, l1));
}

double efficient_fraction(double p) {
  require(p > 0.0, "p must be > 0");
  return std::sqrt(1.0 / p);
}

double efficient_fraction_as_printed(double alpha, double p) {
  return alpha * efficient_fraction(p);
}

double efficient_fraction_exact(int n, int l_max) {
  require(n >= 2, "branching factor n must be >= 2");
  require(l_max >= 0 && l_max % 2 == 0, "l_max must be even and >= 0");
  const double m = n;
  return (std::pow(m, l_max / 2 + 1) - 1.0) / (std::pow(m, l_max + 1) - 1.0);
}

// --- "A Second Look" ------------------------------------------------------------------------

double failed_tests_worst(int n, int m, int l1) {
  require(n >= 1, "branching factor n must be >= 1");
  require(m >= 0, "m must be >= 0");
  require(l1 >= 0, "level must be >= 0");
  long double sum = 1, prev = 1;  // prev = n^{i-1}
  for (int i = 1; i <= l1; ++i) {
    const long double cur = prev * n;  // n^i
    sum += cur + m * prev;
    prev = cur;
  }
  return static_cast<double>(sum);
}

std::uint64_t failed_tests_worst_exact(int n, int m, int l1) {
  require(n >= 1, "branching factor n must be >= 1");
  require(m >= 0, "m must be >= 0");
  require(l1 >= 0, "level must be >= 0");
  std::uint64_t sum = 1, prev = 1;
  for (int i = 1; i <= l1; ++i) {
    const std::uint64_t cur = checked_mul(prev, static_cast<std::uint64_t>(n));
    sum = checked_add(sum, checked_add(cur, checked_mul(static_cast<std::uint64_t>(m), prev)));
    prev = cur;
  }
  return sum;
}

double failed_tests_worst_as_printed(int n, int m, int l1) {
  require(n >= 1, "branching factor n must be >= 1");
  require(m >= 0, "m must be >= 0");
  require(l1 >= 0, "level must be >= 0");
  if (l1 == 0) return 1.0;
  const long double nl = std::pow(static_cast<long double>(n), l1);
  const long double nl1 = std::pow(static_cast<long double>(n), l1 - 1);
  return static_cast<double>(1 + static_cast<long double>(l1) * (nl + m * nl1));
}

// --- Eqs. 4-8 -------------------------------------------------------------------------------

double eq4_lower_bound(int n, double b, double i) {
  require(n >= 2, "branching factor n must be >= 2");
  require(b >= 1.0, "b must be >= 1");
  return log_base(n, b) + i;
}

double c_l1(int n, int l1) {
  return static_cast<double>(power_sum(n, l1));
}

double c_l1_approx(int n, double b) {
  require(n >= 2, "branching factor n must be >= 2");
  return n * b / (n - 1.0);
}

double c_b(int n) {
  require(n >= 2, "branching factor n must be >= 2");
  return n / (n - 1.0);
}

double c_b_exact(int n, int l1) {
  require(n >= 2, "branching factor n must be >= 2");
  return static_cast<double>(power_sum(n, l1) / std::pow(static_cast<long double>(n), l1));
}

double eq7_linear_cost(int n, double i) {
  return i * c_b(n);
}

namespace {
// sum_{k=0}^{l1} ceil(i / n^{l1 - k}): the level-k ancestors of the first i amalgams.
double ancestors(int n, int l1, double i) {
  require(n >= 2, "branching factor n must be >= 2");
  require(l1 >= 0, "level must be >= 0");
  require(i >= 1 && i <= std::pow(static_cast<double>(n), l1), "i must be in [1, n^l1]");
  double sum = 0, w = 1;
  for (int k = l1; k >= 0; --k, w *= n) sum += std::ceil(i / w);
  return sum;
}
}  // namespace

double objects_traversed_to(int n, int l1, double i) {
  return ancestors(n, l1, i);
}

double tests_to(int n, int l1, double i) {
  // Entered nodes are the ancestors on levels 0 .. l1 - 1 (all but the i on level l1); each
  // tests its n children.
  return 1.0 + n * (ancestors(n, l1, i) - std::ceil(i));
}

double eq8_cost(int n, double b, double i) {
  return std::max(eq4_lower_bound(n, b, i), eq7_linear_cost(n, i));
}

// --- Eqs. 9-13 ------------------------------------------------------------------------------

double visit_probability(std::uint64_t i, double p, std::uint64_t b) {
  require_visits_args(p, static_cast<double>(b));
  if (i == 0 || i > b) return 0.0;
  const double mu = p / static_cast<double>(b);
  if (i < b) return std::exp(-mu * static_cast<double>(i - 1)) * -std::expm1(-mu);
  return std::exp(-mu * static_cast<double>(b - 1));
}

double visit_probability_as_printed(std::uint64_t i, double p, double b) {
  require_visits_args(p, b);
  // (e^{p/b-1})(e^{-p/b})^i with (e^{p/b-1}) read as e^{p/b} - 1.
  const long double mu = static_cast<long double>(p) / b;
  return static_cast<double>(std::expm1(mu) * std::pow(std::exp(-mu), static_cast<long double>(i)));
}

double expected_visits_exact(double p, double b) {
  require_visits_args(p, b);
  if (p == 0.0) return b;
  // (1 - x^b)/(1 - x) with x = e^{-p/b} and x^b = e^{-p}.
  return std::expm1(-p) / std::expm1(-p / b);
}

double expected_visits_sum(double p, std::uint64_t b) {
  require_visits_args(p, static_cast<double>(b));
  long double sum = 0;
  for (std::uint64_t i = 1; i <= b; ++i) {
    sum += static_cast<long double>(i) * visit_probability(i, p, b);
  }
  return static_cast<double>(sum);
}

double expected_visits_eq9_as_printed(double p, double b) {
  require(p > 0.0, "p must be > 0 (Eq. 9 is 0/0 at p = 0)");
  require(b >= 1.0, "b must be >= 1");
  using L = long double;
  const L P = p, B = b, mu = P / B;
  const L c = std::expm1(mu);   // printed (e^{p/b-1})  = e^{p/b} - 1
  const L d = std::expm1(-mu);  // printed (e^{-p/b-1}) = e^{-p/b} - 1
  const L x = std::exp(-mu);    // e^{-p/b}
  const L ep = std::exp(-P);    // e^{-p}
  const L line1 = c * (1 / (d * d)) * ((B * x - x - B) * ep + x);
  const L line2 = B * c * (1 / d) * ep;
  return static_cast<double>(line1 - line2);
}

double eq10_traditional(int n, double p) {
  require(n >= 1, "branching factor n must be >= 1");
  require(p > 0.0, "p must be > 0");
  using L = long double;
  const L N = n, P = p, pn = P / N;
  const L c = std::expm1(N);   // (e^{n-1})  = e^n - 1
  const L d = std::expm1(-N);  // (e^{-n-1}) = e^{-n} - 1
  const L en = std::exp(-N);   // e^{-n}
  const L ep = std::exp(-P);   // e^{-p}
  const L line1 = c * (1 / (d * d)) * ((pn * en - en - pn) * ep + en);
  const L line2 = pn * c * (1 / d) * ep;
  return static_cast<double>(line1 - line2);
}

double eq12_limit(int n) {
  require(n >= 1, "branching factor n must be >= 1");
  return -std::expm1(-static_cast<double>(n));  // 1 - e^{-n}
}

double eq12_lhs_as_printed(int n) {
  require(n >= 1, "branching factor n must be >= 1");
  using L = long double;
  const L N = n;
  const L d = std::expm1(-N);
  return static_cast<double>(std::exp(-N) * std::expm1(N) * (1 / (d * d)));
}

double eq12_correct_limit(int n) {
  require(n >= 1, "branching factor n must be >= 1");
  return -1.0 / std::expm1(-static_cast<double>(n));  // 1/(1 - e^{-n})
}

double eq13_scale_sensitive(double p, double b) {
  require(p > 0.0, "p must be > 0 (Eq. 13 is 0/0 at p = 0)");
  require(b >= 1.0, "b must be >= 1");
  using L = long double;
  const L P = p, B = b, mu = P / B;
  const L a = std::exp(-P * (1 - 1 / B)) - std::exp(-P);  // e^{-p(1-1/b)} - e^{-p}
  const L d = std::expm1(-mu);                            // (e^{-p/b-1}) = e^{-p/b} - 1
  const L x = std::exp(-mu);                              // e^{-p/b}
  const L line1 = a * (1 / (d * d)) * (B * x - x - B) - 1 / d;
  const L line2 = B * a * (1 / d);
  return static_cast<double>(line1 - line2);
}

double expected_eq8_cost(int n, std::uint64_t b, double p) {
  require(n >= 2, "branching factor n must be >= 2");
  require_visits_args(p, static_cast<double>(b));
  const double lb = log_base(n, static_cast<double>(b));
  const double cb = c_b(n);
  // log_n b + i >= i C_b  <=>  i <= (n - 1) log_n b.
  const double switch_at = std::floor((n - 1) * lb + 1e-9);
  const std::uint64_t k =
      std::min<std::uint64_t>(b, switch_at <= 0 ? 0 : static_cast<std::uint64_t>(switch_at));
  long double head = 0, head_i = 0;
  for (std::uint64_t i = 1; i <= k; ++i) {
    const long double pr = visit_probability(i, p, b);
    head += pr * (lb + static_cast<long double>(i));
    head_i += pr * static_cast<long double>(i);
  }
  if (k == b) return static_cast<double>(head);
  const long double tail_i = expected_visits_exact(p, static_cast<double>(b)) - head_i;
  return static_cast<double>(head + cb * std::max<long double>(tail_i, 0));
}

// --- Exact expected test counts of explicit traversals --------------------------------------

double expected_tests_sorted(int n, int l1, double p, int m) {
  require(n >= 1, "branching factor n must be >= 1");
  require(l1 >= 0, "level must be >= 0");
  require(p >= 0.0, "p must be >= 0");
  require(m >= 0, "failed objects m must be >= 0");
  double t = 0.0;  // t_{l1}
  for (int k = l1 - 1; k >= 0; --k) {
    const double mu_child = p / std::pow(static_cast<double>(n), k + 1);
    t = (n + m) + t * siblings_processed(n, mu_child);
  }
  return 1.0 + t;
}

double expected_tests_sorted_lazy(int n, int l1, double p) {
  require(n >= 1, "branching factor n must be >= 1");
  require(l1 >= 0, "level must be >= 0");
  require(p >= 0.0, "p must be >= 0");
  double t = 0.0;
  for (int k = l1 - 1; k >= 0; --k) {
    const double mu_child = p / std::pow(static_cast<double>(n), k + 1);
    t = siblings_processed(n, mu_child) * (1.0 + t);
  }
  return 1.0 + t;
}

double expected_tests_traditional(int n, int l_max, double p, int m) {
  require(n >= 1, "branching factor n must be >= 1");
  require(l_max >= 1, "l_max must be >= 1");
  require(p >= 0.0, "p must be >= 0");
  require(m >= 0, "failed objects m must be >= 0");
  double t = n + m;  // t_{l_max - 1}: a bottom node always tests all its n + m objects
  for (int k = l_max - 2; k >= 0; --k) {
    const double mu_child = p / std::pow(static_cast<double>(n), k + 1);
    t = (n + m) + t * siblings_processed(n, mu_child);
  }
  return 1.0 + t;
}

}  // namespace amalgam::formulas

// Tests for amalgam::formulas (Thompson & Fussell, TR-91-01, Eqs. 1-13).

#include "amalgam/analysis/formulas.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "amalgam/util/error.h"

namespace f = amalgam::formulas;

namespace {

double ipow(double n, int e) {
  return std::pow(n, e);
}

/// sum_{i=0}^{top} n^i, summed here term by term (C_t0, C_s0, C_{l1}: Eqs. 1 and 5).
std::uint64_t power_sum(std::uint64_t n, int top) {
  std::uint64_t s = 0, p = 1;
  for (int i = 0; i <= top; ++i) s += p, p *= n;
  return s;
}

/// The truncated geometric mean of Eq. 9's distribution, (1 - x^b) / (1 - x), x = e^{-p/b}.
double truncated_geometric_mean(double p, double b) {
  const long double x = std::exp(-static_cast<long double>(p) / b);
  return static_cast<double>((1 - std::pow(x, static_cast<long double>(b))) / (1 - x));
}

/// Relative difference, safe near zero.
double rel(double a, double b) {
  return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300});
}

/// Running mean/variance (Welford).
struct Moments {
  long double n = 0, mean = 0, m2 = 0;
  void add(double v) {
    n += 1;
    const long double d = v - mean;
    mean += d / n;
    m2 += d * (v - mean);
  }
  double standard_error() const { return static_cast<double>(std::sqrt(m2 / (n - 1) / n)); }
};

/// One simulated primary ray of the traversal documented at f::expected_tests_sorted (eager:
/// all n children tested on entering a node) or f::expected_tests_sorted_lazy.
class SortedTraversal {
 public:
  SortedTraversal(int n, int l1, double p, bool lazy, std::mt19937_64& rng)
      : n_(n), l1_(l1), lazy_(lazy), hit_(-std::expm1(-p / ipow(n, l1))), rng_(rng) {}

  /// Returns {tests, level-l1 nodes processed}.
  std::pair<std::uint64_t, std::uint64_t> run() {
    tests_ = 1;  // the root
    visits_ = 0;
    if (l1_ == 0) {
      visits_ = 1;  // the root itself is the rendered unit
    } else {
      enter(0);
    }
    return {tests_, visits_};
  }

 private:
  bool enter(int k) {
    if (!lazy_) tests_ += n_;
    for (int j = 0; j < n_; ++j) {
      if (lazy_) tests_ += 1;
      if (k + 1 == l1_) {
        ++visits_;
        if (u_(rng_) < hit_) return true;
      } else if (enter(k + 1)) {
        return true;
      }
    }
    return false;
  }

  int n_, l1_;
  bool lazy_;
  double hit_;
  std::mt19937_64& rng_;
  std::uniform_real_distribution<double> u_{0.0, 1.0};
  std::uint64_t tests_ = 0, visits_ = 0;
};

/// One simulated primary ray of the traditional traversal of f::expected_tests_traditional.
class TraditionalTraversal {
 public:
  TraditionalTraversal(int n, int l_max, double p, std::mt19937_64& rng)
      : n_(n), l_max_(l_max), hit_(-std::expm1(-p / ipow(n, l_max))), rng_(rng) {}

  std::uint64_t run() {
    tests_ = 1;
    enter(0);
    return tests_;
  }

 private:
  bool enter(int k) {
    tests_ += n_;  // all children (or all primitives of a bottom node) are tested
    if (k == l_max_ - 1) {
      bool any = false;
      for (int j = 0; j < n_; ++j) any = (u_(rng_) < hit_) || any;  // draw all n
      return any;
    }
    for (int j = 0; j < n_; ++j) {
      if (enter(k + 1)) return true;
    }
    return false;
  }

  int n_, l_max_;
  double hit_;
  std::mt19937_64& rng_;
  std::uniform_real_distribution<double> u_{0.0, 1.0};
  std::uint64_t tests_ = 0;
};

struct Case {
  int n, levels;
  double p;
};

const std::vector<Case> kMcCases = {
    {2, 3, 1.0}, {2, 5, 8.0}, {3, 2, 5.0}, {3, 4, 20.0}, {4, 3, 0.5}, {2, 6, 64.0}, {5, 1, 2.0},
};

}  // namespace

// --- Worst case -----------------------------------------------------------------------------

TEST(Formulas, TraditionalWorstCase) {
  EXPECT_EQ(f::c_t0_exact(3, 6), 1093u);
  EXPECT_DOUBLE_EQ(f::c_t0(3, 6), 1093.0);
  EXPECT_EQ(f::c_t0_exact(2, 10), 2047u);
  EXPECT_EQ(f::c_t0_exact(1, 5), 6u);  // n = 1: l_max + 1
  EXPECT_DOUBLE_EQ(f::c_t0(1, 5), 6.0);
  EXPECT_EQ(f::c_t0_exact(7, 0), 1u);
  // Closed form (n^{l+1} - 1)/(n - 1).
  for (int n = 2; n <= 6; ++n) {
    for (int l = 0; l <= 8; ++l) {
      EXPECT_DOUBLE_EQ(f::c_t0(n, l), (ipow(n, l + 1) - 1) / (n - 1));
    }
  }
  EXPECT_EQ(f::c_t0_exact(2, 63), ~std::uint64_t{0});  // 2^64 - 1 fits exactly
  EXPECT_THROW(f::c_t0_exact(2, 64), std::overflow_error);
  EXPECT_THROW(f::c_t0(0, 3), amalgam::InternalError);
  EXPECT_THROW(f::c_t0(2, -1), amalgam::InternalError);
}

TEST(Formulas, Eq1Eq2Eq3) {
  for (int n = 1; n <= 5; ++n) {
    for (int l1 = 0; l1 <= 7; ++l1) {
      const std::uint64_t s0 = power_sum(n, l1);
      EXPECT_EQ(f::c_s0_exact(n, l1), s0) << "Eq. 1, n=" << n << " l1=" << l1;
      EXPECT_EQ(f::c_t0_exact(n, l1), s0);
      EXPECT_DOUBLE_EQ(f::c_s0(n, l1), static_cast<double>(s0));
      // Eq. 2: C_sd1 = n^{l1} C_s0.
      const auto nl = static_cast<std::uint64_t>(ipow(n, l1));
      EXPECT_EQ(f::c_sd1_exact(n, l1), nl * s0);
      EXPECT_DOUBLE_EQ(f::c_sd1(n, l1), static_cast<double>(nl * s0));
      if (n >= 2) {  // Eq. 2's closed form (n^{2 l1 + 1} - n^{l1})/(n - 1)
        EXPECT_DOUBLE_EQ(f::c_sd1(n, l1), (ipow(n, 2 * l1 + 1) - ipow(n, l1)) / (n - 1));
      }
      EXPECT_DOUBLE_EQ(f::deterministic_total(n, l1), static_cast<double>(s0 + nl * s0));
      // Eq. 3: 2 C_s0.
      EXPECT_EQ(f::stochastic_total_exact(n, l1), 2 * s0);
      EXPECT_DOUBLE_EQ(f::stochastic_total(n, l1), 2.0 * static_cast<double>(s0));
    }
  }
  EXPECT_EQ(f::c_s0_exact(3, 4), 121u);
  EXPECT_EQ(f::c_s0_exact(2, 10), 2047u);
  EXPECT_DOUBLE_EQ(f::deterministic_total(2, 3), 15.0 + 8.0 * 15.0);
  EXPECT_DOUBLE_EQ(f::stochastic_total(4, 2), 42.0);
  EXPECT_EQ(f::c_sd1_exact(3, 4), 81u * 121u);
  EXPECT_THROW(f::c_sd1_exact(2, 40), std::overflow_error);
}

TEST(Formulas, EfficientFraction) {
  EXPECT_DOUBLE_EQ(f::efficient_fraction(4.0), 0.5);
  EXPECT_DOUBLE_EQ(f::efficient_fraction(100.0), 0.1);
  EXPECT_DOUBLE_EQ(f::efficient_fraction_as_printed(3.0, 100.0), 0.3);
  for (int n = 2; n <= 5; ++n) {
    for (int l = 0; l <= 12; l += 2) {
      // The exact ratio of the sums, written out: sum_{i <= l/2} n^i / sum_{i <= l} n^i.
      double half = 0, all = 0;
      for (int i = 0; i <= l; ++i) (i <= l / 2 ? half : all) += ipow(n, i);
      all += half;
      EXPECT_NEAR(f::efficient_fraction_exact(n, l), half / all, 1e-15) << n << " " << l;
      // It tends to sqrt(1/p) with p = n^{l_max} (the ratio is (1 - n^{-l/2-1})/(1 - n^{-l-1}))
      // whatever the alpha of the printed form, which it matches for alpha = 1 only.
      const double sqrt_1_p = f::efficient_fraction(ipow(n, l));
      EXPECT_NEAR(f::efficient_fraction_exact(n, l) / sqrt_1_p,
                  (1 - std::pow(n, -l / 2 - 1.0)) / (1 - std::pow(n, -l - 1.0)), 1e-12);
      if (l >= 10) {
        EXPECT_NEAR(f::efficient_fraction_exact(n, l) / sqrt_1_p, 1.0, 0.02) << n << " " << l;
        for (double alpha : {0.25, 0.5, 0.9, 1.1, 2.0})
          EXPECT_GT(std::fabs(f::efficient_fraction_as_printed(alpha, ipow(n, l)) /
                                  f::efficient_fraction_exact(n, l) -
                              1.0),
                    0.05)
              << n << " " << l << " alpha " << alpha;
      }
    }
  }
  EXPECT_THROW(f::efficient_fraction(0.0), amalgam::InternalError);
  EXPECT_THROW(f::efficient_fraction_exact(2, 3), amalgam::InternalError);
}

// Eq. 7's exact counterpart: the cost of a sorted traversal stopped by the i-th amalgam of
// l1, against a direct walk of the implicit tree (node k of level l is reached when one of
// the first i amalgams lies under it), and its bounds around i C_b.
TEST(Formulas, CostOfReachingTheIthAmalgam) {
  for (int n = 2; n <= 5; ++n)
    for (int l1 = 0; l1 <= 5; ++l1) {
      const double b = ipow(n, l1);
      for (double i = 1; i <= b; ++i) {
        double reached = 0, entered = 0;
        for (int l = 0; l <= l1; ++l) {
          const double width = ipow(n, l1 - l);  // amalgams of l1 under a node of level l
          for (double k = 0; k < ipow(n, l); ++k)
            if (k * width < i) ++reached, entered += l < l1;
        }
        EXPECT_EQ(f::objects_traversed_to(n, l1, i), reached) << n << " " << l1 << " " << i;
        EXPECT_EQ(f::tests_to(n, l1, i), 1 + n * entered) << n << " " << l1 << " " << i;
        const double eq7 = f::eq7_linear_cost(n, i);
        EXPECT_LE(std::fabs(reached - eq7), l1 + 1);
        EXPECT_LE(std::fabs(1 + n * entered - eq7), n * l1 + 1);
      }
      EXPECT_EQ(f::objects_traversed_to(n, l1, 1), l1 + 1);                    // Eq. 4, attained
      EXPECT_EQ(f::objects_traversed_to(n, l1, b), double(power_sum(n, l1)));  // Eq. 5
    }
  EXPECT_THROW(f::objects_traversed_to(2, 3, 9), amalgam::InternalError);
  EXPECT_THROW(f::tests_to(2, 3, 0), amalgam::InternalError);
}

// Failed objects in the expected case: every entered node costs n + m tests, so the
// expectation is 1 + (1 + m/n)(E_0 - 1), and p = 0 gives the worst-case Second-Look sum.
TEST(Formulas, ExpectedTestsWithFailedObjects) {
  for (int n = 2; n <= 4; ++n)
    for (int l = 1; l <= 6; ++l)
      for (int m : {0, 1, 6})
        for (double p : {0.0, 0.5, 8.0, 1000.0}) {
          const double k = 1.0 + double(m) / n;
          EXPECT_NEAR(f::expected_tests_sorted(n, l, p, m),
                      1 + k * (f::expected_tests_sorted(n, l, p) - 1), 1e-9);
          EXPECT_NEAR(f::expected_tests_traditional(n, l, p, m),
                      1 + k * (f::expected_tests_traditional(n, l, p) - 1), 1e-9);
          if (p == 0) {
            EXPECT_DOUBLE_EQ(f::expected_tests_traditional(n, l, p, m),
                             f::failed_tests_worst(n, m, l));
          }
        }
}

TEST(Formulas, FailedTestsWorstCase) {
  for (int n = 1; n <= 5; ++n) {
    for (int l1 = 0; l1 <= 6; ++l1) {
      // m = 0: no failed tests, back to Eq. 1.
      EXPECT_EQ(f::failed_tests_worst_exact(n, 0, l1), power_sum(n, l1));
      for (int m = 0; m <= 6; ++m) {
        double direct = 1;
        for (int i = 1; i <= l1; ++i) direct += ipow(n, i) + m * ipow(n, i - 1);
        EXPECT_DOUBLE_EQ(f::failed_tests_worst(n, m, l1), direct);
        EXPECT_DOUBLE_EQ(static_cast<double>(f::failed_tests_worst_exact(n, m, l1)), direct);
        // The paper's right-hand side 1 + (1 + m/n) sum_{i=1}^{l1} n^i (with index i).
        double rhs_sum = 0;
        for (int i = 1; i <= l1; ++i) rhs_sum += ipow(n, i);
        EXPECT_NEAR(f::failed_tests_worst(n, m, l1), 1 + (1 + double(m) / n) * rhs_sum, 1e-9);
      }
    }
  }
  // Figure 2: n = 2 children hit, m = 6 failed, l1 = 3: 1 + (2+6) + (4+12) + (8+24) = 57.
  EXPECT_EQ(f::failed_tests_worst_exact(2, 6, 3), 57u);
  // The printed summand n^{l1} + m n^{l1-1} (typo) gives 1 + 3 * (8 + 24) = 97 instead.
  EXPECT_DOUBLE_EQ(f::failed_tests_worst_as_printed(2, 6, 3), 97.0);
  EXPECT_DOUBLE_EQ(f::failed_tests_worst_as_printed(2, 6, 1), f::failed_tests_worst(2, 6, 1));
}

// --- Eqs. 4-8 -------------------------------------------------------------------------------

TEST(Formulas, Eq4ToEq8) {
  EXPECT_NEAR(f::eq4_lower_bound(2, 1024, 3), 13.0, 1e-12);
  EXPECT_NEAR(f::eq4_lower_bound(3, 81, 1), 5.0, 1e-12);
  EXPECT_DOUBLE_EQ(f::c_l1(3, 4), 121.0);
  EXPECT_DOUBLE_EQ(f::c_l1_approx(3, 81), 121.5);
  EXPECT_DOUBLE_EQ(f::c_b(2), 2.0);
  EXPECT_DOUBLE_EQ(f::c_b(3), 1.5);
  EXPECT_DOUBLE_EQ(f::c_b_exact(3, 4), 121.0 / 81.0);
  EXPECT_NEAR(f::c_b_exact(3, 30), 1.5, 1e-12);
  for (int l1 = 0; l1 <= 8; ++l1)  // C_{l1} / b, Eq. 5 over b = 3^l1
    EXPECT_DOUBLE_EQ(f::c_b_exact(3, l1), double(power_sum(3, l1)) / ipow(3, l1)) << l1;
  EXPECT_DOUBLE_EQ(f::c_l1(4, 3), 85.0);
  EXPECT_DOUBLE_EQ(f::eq7_linear_cost(4, 6), 8.0);
  // Eq. 8: max(log_n b + i, i C_b); n = 2, b = 1024: switch at i = (n-1) log_n b = 10.
  EXPECT_NEAR(f::eq8_cost(2, 1024, 1), 11.0, 1e-12);
  EXPECT_NEAR(f::eq8_cost(2, 1024, 10), 20.0, 1e-12);
  EXPECT_NEAR(f::eq8_cost(2, 1024, 30), 60.0, 1e-12);
  // The paper's remark on Figure 5: traversing through A costs l1 + 1 > 1 * C_b.
  EXPECT_GT(f::eq4_lower_bound(3, 81, 1), f::eq7_linear_cost(3, 1));
}

// --- Eq. 9 and its consequences -------------------------------------------------------------

TEST(Formulas, VisitDistributionSumsToOne) {
  for (std::uint64_t b : {1u, 2u, 5u, 64u, 1000u}) {
    for (double p : {0.0, 0.01, 1.0, 7.5, 300.0}) {
      long double total = 0;
      for (std::uint64_t i = 1; i <= b; ++i) total += f::visit_probability(i, p, b);
      EXPECT_NEAR(static_cast<double>(total), 1.0, 1e-12) << "b=" << b << " p=" << p;
      EXPECT_EQ(f::visit_probability(0, p, b), 0.0);
      EXPECT_EQ(f::visit_probability(b + 1, p, b), 0.0);
      // The printed form (e^{p/b} - 1)(e^{-p/b})^i of P(i), i < b, is correct.
      for (std::uint64_t i = 1; i < b && i < 50; ++i) {
        EXPECT_NEAR(f::visit_probability_as_printed(i, p, static_cast<double>(b)),
                    f::visit_probability(i, p, b), 1e-15 + 1e-12 * f::visit_probability(i, p, b));
      }
    }
  }
}

TEST(Formulas, ExpectedVisitsExactMatchesBruteForce) {
  for (std::uint64_t b : {1u, 2u, 3u, 10u, 81u, 1024u, 100000u}) {
    for (double p : {0.0, 1e-9, 1e-3, 0.5, 1.0, 3.0, 10.0, 81.0, 1e4, 1e7}) {
      // Brute force, independent of the library: sum_i i P(i) with P as in Eq. 9's text.
      const long double x = std::exp(-static_cast<long double>(p) / b);
      long double e = 0, xp = 1;  // xp = x^{i-1}
      for (std::uint64_t i = 1; i <= b; ++i) {
        e += static_cast<long double>(i) * (i < b ? xp * (1 - x) : xp);
        xp *= x;
      }
      const double exact = f::expected_visits_exact(p, static_cast<double>(b));
      EXPECT_LT(rel(exact, static_cast<double>(e)), 1e-9) << "b=" << b << " p=" << p;
      EXPECT_LT(rel(f::expected_visits_sum(p, b), exact), 1e-12) << "b=" << b << " p=" << p;
      EXPECT_GE(exact, 1.0 - 1e-12);
      EXPECT_LE(exact, static_cast<double>(b) * (1 + 1e-12));
    }
  }
  EXPECT_DOUBLE_EQ(f::expected_visits_exact(0.0, 17.0), 17.0);
  EXPECT_DOUBLE_EQ(f::expected_visits_exact(5.0, 1.0), 1.0);
  // Huge p/b: one amalgam is visited.
  EXPECT_DOUBLE_EQ(f::expected_visits_exact(1e6, 2.0), 1.0);
}

// Finding: the printed closed form of Eq. 9 EQUALS the exact expectation (1 - x^b)/(1 - x).
TEST(Formulas, Eq9AsPrintedIsCorrect) {
  for (double b : {1.0, 2.0, 3.0, 8.0, 81.0, 1024.0, 1e6}) {
    for (double mu : {0.05, 0.3, 1.0, 2.0, 5.0, 20.0, 100.0, 700.0}) {  // mu = p/b
      const double p = mu * b;
      EXPECT_LT(rel(f::expected_visits_eq9_as_printed(p, b), truncated_geometric_mean(p, b)), 1e-9)
          << "b=" << b << " p=" << p;
    }
  }
  // A few concrete numbers: b = 8, p = 8 (p/b = 1): E = (1 - e^{-8})/(1 - e^{-1}).
  EXPECT_NEAR(f::expected_visits_eq9_as_printed(8.0, 8.0), 1.5814460128059595, 1e-12);
  EXPECT_NEAR(f::expected_visits_exact(8.0, 8.0), (1 - std::exp(-8.0)) / (1 - std::exp(-1.0)),
              1e-15);
}

// Finding: Eq. 10 (Eq. 9 with b = p/n) is correct.
TEST(Formulas, Eq10AsPrintedIsCorrect) {
  for (int n = 1; n <= 5; ++n) {
    for (double b : {1.0, 2.0, 7.0, 64.0, 4096.0}) {
      const double p = n * b;
      EXPECT_LT(rel(f::eq10_traditional(n, p), f::expected_visits_exact(p, b)), 1e-9)
          << "n=" << n << " b=" << b;
      EXPECT_LT(rel(f::eq10_traditional(n, p), -std::expm1(-p) / -std::expm1(-double(n))), 1e-9);
    }
  }
}

// Finding: Eq. 12's printed value (1 - e^{-n}) is WRONG; the limit is 1/(1 - e^{-n}).
TEST(Formulas, Eq12AsPrintedIsWrong) {
  for (int n = 1; n <= 6; ++n) {
    const double correct = f::eq12_correct_limit(n);
    EXPECT_NEAR(correct, 1.0 / (1.0 - std::exp(-double(n))), 1e-15);
    // The printed left side is right ...
    EXPECT_LT(rel(f::eq12_lhs_as_printed(n), correct), 1e-12);
    // ... the printed right side is its reciprocal, below the minimum possible count of 1.
    EXPECT_LT(rel(f::eq12_limit(n), 1.0 - std::exp(-double(n))), 1e-12);
    EXPECT_LT(f::eq12_limit(n), 1.0);
    EXPECT_GT(correct, 1.0);
    EXPECT_GT(rel(f::eq12_limit(n), correct), 1e-3);
    // The exact expectation with p/b = n converges to the correct limit.
    for (double b : {1e3, 1e6}) {
      EXPECT_LT(rel(f::expected_visits_exact(n * b, b), correct), 1e-12);
      EXPECT_LT(rel(f::eq10_traditional(n, n * b), correct), 1e-12);
    }
  }
  EXPECT_NEAR(f::eq12_correct_limit(2), 1.1565176427496657, 1e-15);
  EXPECT_NEAR(f::eq12_limit(2), 0.8646647167633873, 1e-15);
  EXPECT_NEAR(f::eq12_correct_limit(1), 1.5819767068693265, 1e-15);
  EXPECT_NEAR(f::eq12_limit(1), 0.6321205588285577, 1e-15);
}

// Finding: Eq. 13 is correct (Eq. 9 rewritten), and tends to 1 for fixed b as p grows.
TEST(Formulas, Eq13AsPrintedIsCorrect) {
  for (double b : {1.0, 2.0, 4.0, 27.0, 1000.0}) {
    for (double mu : {0.05, 0.5, 1.0, 3.0, 10.0, 50.0}) {
      const double p = mu * b;
      EXPECT_LT(rel(f::eq13_scale_sensitive(p, b), truncated_geometric_mean(p, b)), 1e-9)
          << "b=" << b << " p=" << p;
    }
  }
  EXPECT_NEAR(f::eq13_scale_sensitive(1e4, 16.0), 1.0, 1e-12);
}

TEST(Formulas, ExpectedEq8CostMatchesDirectSum) {
  for (int n : {2, 3, 4}) {
    for (std::uint64_t b : {1u, 2u, 9u, 64u, 729u, 4096u}) {
      for (double p : {0.0, 0.5, 3.0, 40.0, 5000.0}) {
        // sum_i P(i) max(log_n b + i, i n/(n - 1)), P(i) = x^{i-1}(1 - x) (i < b), x^{b-1}.
        const long double x = std::exp(-static_cast<long double>(p) / b);
        const long double log_b = std::log(static_cast<long double>(b)) / std::log((long double)n);
        long double direct = 0, xp = 1;
        for (std::uint64_t i = 1; i <= b; ++i, xp *= x) {
          const long double prob = i < b ? xp * (1 - x) : xp;
          direct += prob * std::max<long double>(log_b + i, i * (n / (n - 1.0L)));
        }
        EXPECT_LT(rel(f::expected_eq8_cost(n, b, p), static_cast<double>(direct)), 1e-9)
            << "n=" << n << " b=" << b << " p=" << p;
      }
    }
  }
}

// --- Exact expected test counts vs. limits and Monte Carlo ---------------------------------

TEST(Formulas, ExpectedTestsLimits) {
  for (int n = 1; n <= 4; ++n) {
    for (int l = 0; l <= 6; ++l) {
      // p = 0: nothing is ever hit -> the worst case of Eq. 1.
      EXPECT_DOUBLE_EQ(f::expected_tests_sorted(n, l, 0.0), double(power_sum(n, l)));
      EXPECT_DOUBLE_EQ(f::expected_tests_sorted_lazy(n, l, 0.0), double(power_sum(n, l)));
      // p -> infinity: the first level-l1 node hits.
      EXPECT_NEAR(f::expected_tests_sorted(n, l, 1e12), 1.0 + n * l, 1e-9);
      EXPECT_NEAR(f::expected_tests_sorted_lazy(n, l, 1e12), 1.0 + l, 1e-9);
      if (n >= 2) {
        EXPECT_NEAR(f::expected_tests_sorted_lazy(n, l, 1e12), f::eq4_lower_bound(n, ipow(n, l), 1),
                    1e-9);
      }
      if (l >= 1) {
        EXPECT_DOUBLE_EQ(f::expected_tests_traditional(n, l, 0.0), double(power_sum(n, l)));
        for (double p : {0.0, 0.3, 2.0, 17.0, 1e3}) {
          EXPECT_LT(rel(f::expected_tests_traditional(n, l, p), f::expected_tests_sorted(n, l, p)),
                    1e-12);
        }
      }
    }
  }
  // Monotone: more primitives on the ray -> earlier stop -> fewer tests.
  double prev = f::expected_tests_sorted(3, 5, 0.0);
  for (double p = 0.5; p < 2000; p *= 2) {
    const double cur = f::expected_tests_sorted(3, 5, p);
    EXPECT_LT(cur, prev);
    prev = cur;
  }
  // Closed form 1 + n sum_{k<l1} prod_{j=1}^{k} G(n, p/n^j) for one case.
  const int n = 3, l1 = 4;
  const double p = 7.0;
  double total = 1, prod = 1;
  for (int k = 0; k < l1; ++k) {
    if (k > 0) {
      const double mu = p / ipow(n, k);
      prod *= (1 - std::exp(-n * mu)) / (1 - std::exp(-mu));
    }
    total += n * prod;
  }
  EXPECT_NEAR(f::expected_tests_sorted(n, l1, p), total, 1e-12 * total);
}

TEST(Formulas, ExpectedTestsSortedMatchesMonteCarlo) {
  std::mt19937_64 rng(0x5eed'1991'0101ull);
  const int samples = 200000;
  for (const Case& c : kMcCases) {
    for (bool lazy : {false, true}) {
      SortedTraversal sim(c.n, c.levels, c.p, lazy, rng);
      Moments tests, visits;
      for (int s = 0; s < samples; ++s) {
        const auto [t, v] = sim.run();
        tests.add(static_cast<double>(t));
        visits.add(static_cast<double>(v));
      }
      const double expect = lazy ? f::expected_tests_sorted_lazy(c.n, c.levels, c.p)
                                 : f::expected_tests_sorted(c.n, c.levels, c.p);
      EXPECT_LT(std::abs(static_cast<double>(tests.mean) - expect),
                4 * tests.standard_error() + 1e-9)
          << "n=" << c.n << " l1=" << c.levels << " p=" << c.p << " lazy=" << lazy
          << " mc=" << static_cast<double>(tests.mean) << " exact=" << expect;
      // The number of level-l1 nodes processed follows Eq. 9's distribution.
      const double ev = f::expected_visits_exact(c.p, ipow(c.n, c.levels));
      EXPECT_LT(std::abs(static_cast<double>(visits.mean) - ev), 4 * visits.standard_error() + 1e-9)
          << "n=" << c.n << " l1=" << c.levels << " p=" << c.p;
    }
  }
}

TEST(Formulas, ExpectedTestsTraditionalMatchesMonteCarlo) {
  std::mt19937_64 rng(0x7a11'0001ull);
  const int samples = 200000;
  for (const Case& c : kMcCases) {
    TraditionalTraversal sim(c.n, c.levels, c.p, rng);
    Moments tests;
    for (int s = 0; s < samples; ++s) tests.add(static_cast<double>(sim.run()));
    const double expect = f::expected_tests_traditional(c.n, c.levels, c.p);
    EXPECT_LT(std::abs(static_cast<double>(tests.mean) - expect), 4 * tests.standard_error() + 1e-9)
        << "n=" << c.n << " l_max=" << c.levels << " p=" << c.p
        << " mc=" << static_cast<double>(tests.mean) << " exact=" << expect;
  }
}

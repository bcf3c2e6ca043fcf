// The quick size of every experiment of issue 3, with its measured figures asserted against
// the paper's formulas: exactly where the scene makes the formula exact, within the stated
// statistical tolerance (4 standard errors) where the formula is an expectation.

#include "amalgam/analysis/experiments.h"

#include <gtest/gtest.h>

#include <cmath>

#include "amalgam/analysis/formulas.h"

namespace amalgam::experiments {
namespace {

ExperimentResult quick(const std::string& name) {
  Config c;
  c.quick = true;
  c.threads = 2;
  return run(name, c);
}

void expect_checks_pass(const ExperimentResult& r) {
  EXPECT_FALSE(r.checks.empty()) << r.name;
  for (const Check& c : r.checks)
    EXPECT_TRUE(c.passed()) << r.name << ": " << c.what << ": measured " << c.measured
                            << ", predicted " << c.predicted << ", tolerance " << c.tolerance;
  EXPECT_FALSE(r.table.rows.empty());
  for (const auto& row : r.table.rows) EXPECT_EQ(row.size(), r.table.columns.size()) << r.name;
  for (const Panel& p : r.panels)
    for (const Series& s : p.series) {
      EXPECT_NO_THROW(r.table.col(s.x)) << r.name << " plots unknown column " << s.x;
      EXPECT_NO_THROW(r.table.col(s.y)) << r.name << " plots unknown column " << s.y;
    }
}

TEST(Experiments, NamesAreTheNineOfIssue3) {
  EXPECT_EQ(names().size(), 9u);
  EXPECT_THROW(run("no-such-experiment", Config{}), std::invalid_argument);
}

TEST(Experiments, WorstTraditionalIsExactlyCt0) {
  const ExperimentResult r = quick("worst-traditional");
  expect_checks_pass(r);
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    const int n = int(r.table.at(i, "n")), l = int(r.table.at(i, "l_max"));
    EXPECT_EQ(r.table.at(i, "primary"), double(formulas::c_t0_exact(n, l)));
    EXPECT_EQ(r.table.at(i, "shadow"), double(formulas::c_t0_exact(n, l)));
  }
}

TEST(Experiments, WorstStochasticIsTwoCs0UpToATrillionPrimitives) {
  const ExperimentResult r = quick("worst-stochastic");
  expect_checks_pass(r);
  double pmax = 0;
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    EXPECT_EQ(r.table.at(i, "tests"), double(formulas::stochastic_total_exact(
                                          int(r.table.at(i, "n")), int(r.table.at(i, "l1")))));
    pmax = std::max(pmax, r.table.at(i, "p"));
  }
  EXPECT_GE(pmax, 1e12) << "Eq. 3 must be shown flat up to p >= 10^12";
}

TEST(Experiments, WorstDeterministicMatchesEqs1And2) {
  const ExperimentResult r = quick("worst-deterministic");
  expect_checks_pass(r);
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    EXPECT_EQ(r.table.at(i, "det_primary"),
              formulas::c_s0(int(r.table.at(i, "n")), int(r.table.at(i, "l1"))));
    EXPECT_LE(r.table.at(i, "det_total"), r.table.at(i, "eq1_plus_eq2"));
    EXPECT_EQ(r.table.at(i, "det_total"), r.table.at(i, "line_exact"));
  }
}

TEST(Experiments, ExpectedMatchesEq9AndRefutesPrintedEq12) {
  const ExperimentResult r = quick("expected");
  expect_checks_pass(r);
  EXPECT_EQ(r.verdict, Verdict::kHoldsWithCorrection);
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    const double se = r.table.at(i, "se_i"), rays = r.table.at(i, "rays");
    const double e = r.table.at(i, "eq9_exact");
    EXPECT_NEAR(r.table.at(i, "mean_i"), e, 4 * se + 5 * e / rays) << "row " << i;
    if (r.table.at(i, "sweep") == 0 && r.table.at(i, "p") >= 64) {
      EXPECT_GT(r.table.at(i, "mean_i"), r.table.at(i, "eq12_printed") + 10 * se)
          << "the printed Eq. 12 limit (1 - e^-n) is below every measurement";
    }
  }
}

TEST(Experiments, FailedTestsMatchCorrectedSecondLookSum) {
  const ExperimentResult r = quick("failed-tests");
  expect_checks_pass(r);
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    const int n = int(r.table.at(i, "n")), m = int(r.table.at(i, "m")),
              l1 = int(r.table.at(i, "l1"));
    EXPECT_EQ(r.table.at(i, "primary"), double(formulas::failed_tests_worst_exact(n, m, l1)));
  }
}

TEST(Experiments, LightsScaleLinearly) {
  expect_checks_pass(quick("lights"));
}

TEST(Experiments, NoiseFollowsOneOverSpp) {
  const ExperimentResult r = quick("noise");
  expect_checks_pass(r);
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    EXPECT_GT(r.table.at(i, "pixel_variance"), 0.0);
    EXPECT_GT(r.table.at(i, "tests_per_sample"), 0.0);
  }
}

TEST(Experiments, MoreLevelsLeaveScaleSensitiveCostUnchanged) {
  const ExperimentResult r = quick("more-levels");
  expect_checks_pass(r);
  for (std::size_t i = 1; i < r.table.rows.size(); ++i) {
    EXPECT_EQ(r.table.at(i, "ss_tests"), r.table.at(0, "ss_tests"));
    EXPECT_EQ(r.table.at(i, "ss_image_max_diff"), 0.0);
    EXPECT_GT(r.table.at(i, "trad_tests"), r.table.at(i - 1, "trad_tests"));
  }
}

TEST(Experiments, LinearCostSeparatesLogFromNonLog) {
  const ExperimentResult r = quick("linear-cost");
  expect_checks_pass(r);
  const std::size_t last = r.table.rows.size() - 1;
  // At the largest size the logarithmic searches are far cheaper than the others.
  EXPECT_LT(r.table.at(last, "pt2d_tile") * 2, r.table.at(last, "pt2d_overlap"));
  EXPECT_LT(r.table.at(last, "pt2d_tile") * 2, r.table.at(last, "ray2d_tile"));
}

TEST(Experiments, FitLineRecoversALine) {
  const LinearFit f = fit_line({0, 1, 2, 3}, {1, 3, 5, 7});
  EXPECT_DOUBLE_EQ(f.a, 1);
  EXPECT_DOUBLE_EQ(f.b, 2);
  EXPECT_NEAR(f.r2, 1, 1e-12);
}

}  // namespace
}  // namespace amalgam::experiments

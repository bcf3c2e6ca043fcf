/// \file Experiment traversed: Eqs. 4-8 counted as the paper counts, "objects traversed" --
/// children reached in sorted order until the first hit (Counters::traversed_of) -- beside
/// the renderer's intersection tests (all children of every entered node), on builtin:poisson
/// for n = 2, 3 and 8.

#include <algorithm>
#include <cmath>

#include "amalgam/analysis/experiments/common.h"
#include "amalgam/analysis/formulas.h"
#include "amalgam/builtin/tube.h"

namespace amalgam::experiments {
using namespace detail;

ExperimentResult traversed(const Config& c) {
  ExperimentResult r;
  r.title = "Eqs. 4-8 as the paper counts: objects traversed in sorted order";
  r.claim =
      "A traversal that stops after the i-th amalgam of level l1 costs at least l1 + i "
      "(Eq. 4: the left edge and the i amalgams); the objects above and within l1 cost "
      "C_b = n/(n - 1) per amalgam of l1, independent of l1 (Eqs. 5-7); overall the cost is "
      "max(log_n b + i, i C_b) (Eq. 8). The paper counts *objects traversed*: children reached "
      "in sorted order until the first hit.";
  r.prediction =
      "Objects traversed (`Counters::traversed_of`: nodes reached in sorted order plus "
      "primitives tested) against Eq. 4 per ray, against `formulas::expected_eq8_cost` "
      "(E[Eq. 8] under Eq. 9's distribution of i) and against its exact expectation "
      "`formulas::expected_tests_sorted_lazy`; the renderer's intersection tests (all n "
      "children of every entered node) against `formulas::expected_tests_sorted`. Eqs. 5-7: "
      "objects traversed when nothing is hit (p -> 0) divided by b, against "
      "`formulas::c_b_exact` and n/(n - 1).";
  r.table.columns = {"n",
                     "l1",
                     "b",
                     "p",
                     "p_over_b",
                     "rays",
                     "mean_i",
                     "mean_trav",
                     "se_trav",
                     "trav_exact",
                     "eq8",
                     "eq4_mean",
                     "min_slack",
                     "mean_tests",
                     "tests_exact",
                     "trav_over_eq8",
                     "tests_over_eq8"};
  struct Setup {
    int n, l1;
  };
  // b = n^l1 of a few hundred amalgams, so that i ranges widely when p/b is small.
  const std::vector<Setup> setups = {{2, 8}, {3, 5}, {8, 3}};
  const int rays = c.quick ? 800 : 20000;
  const int kstep = c.quick ? 3 : 1;
  std::vector<std::string> ratio_text;
  for (const Setup& s : setups) {
    const double b = std::pow(s.n, s.l1);
    double worst_ratio = 1, worst_tests_ratio = 1;
    for (int k = -6; k <= 6; k += kstep) {
      const double p = b * std::ldexp(1.0, k);
      const LoadedScene sc =
          scene("poisson", {{"n", str(s.n)}, {"depth", str(s.l1 + 1)}, {"p", str(p)}});
      Mean mi, mtrav, mtests;
      double min_slack = 1e300;
      for (int ray = 0; ray < rays; ++ray) {
        RenderOptions o = at_level(s.l1);
        o.seed = static_cast<std::uint64_t>(ray);
        const TraceOutput t = trace_centre(sc, o);
        const double i = t.hit.kind == TraceHit::Kind::kAmalgam
                             ? double(TubeHierarchy::index_of(t.hit.id) + 1)
                             : b;
        const double trav = u(t.counters.traversed_of(RayKind::kPrimary));
        mi.add(i);
        mtrav.add(trav);
        mtests.add(u(t.counters.tests_of(RayKind::kPrimary)));
        min_slack = std::min(
            min_slack, trav - predict(c, "eq4_lower_bound", formulas::eq4_lower_bound(s.n, b, i)));
      }
      const double trav_exact = formulas::expected_tests_sorted_lazy(s.n, s.l1, p);
      const double tests_exact = formulas::expected_tests_sorted(s.n, s.l1, p);
      const double eq8 =
          predict(c, "expected_eq8_cost", formulas::expected_eq8_cost(s.n, std::uint64_t(b), p));
      r.table.add({double(s.n), double(s.l1), b, p, p / b, double(rays), mi.mean(), mtrav.mean(),
                   mtrav.se(), trav_exact, eq8, s.l1 + mi.mean(), min_slack, mtests.mean(),
                   tests_exact, mtrav.mean() / eq8, mtests.mean() / eq8});
      const std::string where = "n=" + str(s.n) + " p/b=" + fmt(p / b);
      const double rare = 5.0 / rays;
      r.checks.push_back({where + ": objects traversed = exact expectation (4 s.e.)", mtrav.mean(),
                          trav_exact, 4 * mtrav.se() + rare * trav_exact, Role::kSupports,
                          "Eq. 8"});
      r.checks.push_back({where + ": intersection tests = exact expectation (4 s.e.)",
                          mtests.mean(), tests_exact, 4 * mtests.se() + rare * tests_exact,
                          Role::kSupports, "Eq. 8"});
      // Eq. 8 is a model: compared with the exact expectation of objects traversed (itself
      // checked against the measurement above), so that the comparison carries no noise.
      r.checks.push_back({where + ": E[objects traversed] within 15% of E[Eq. 8]", trav_exact / eq8,
                          1.0, 0.15, Role::kSupports, "Eq. 8"});
      // Slack tolerance: log_n b in floating point (log 243 / log 3 is 5 + 9e-16).
      r.checks.push_back({where + ": every ray traverses at least l1 + i objects (Eq. 4)",
                          std::min(min_slack, 0.0), 0.0, 1e-9, Role::kSupports, "Eq. 4"});
      worst_ratio = std::max(worst_ratio, std::fabs(trav_exact / eq8 - 1) + 1);
      worst_tests_ratio = std::max(worst_tests_ratio, mtests.mean() / eq8);
      if (k == 6)
        r.checks.push_back({"n=" + str(s.n) +
                                ": Eq. 4 is attained when the first amalgam stops "
                                "the ray (min slack 0 at p/b = 64)",
                            min_slack, 0.0, 1e-9, Role::kSupports, "Eq. 4"});
    }
    ratio_text.push_back("n = " + str(s.n) + " (b = " + fmt(b) +
                         "): expected objects traversed within " + fmt(100 * (worst_ratio - 1)) +
                         "% of E[Eq. 8] at the points measured; intersection tests up to " +
                         fmt(worst_tests_ratio) + " times E[Eq. 8]");
  }
  // Eqs. 5-7: with nothing hit (p tiny) every amalgam of l1 is traversed, so objects
  // traversed = C_{l1} (Eq. 5, the exact sum); per amalgam of l1 that is C_b (Eq. 6).
  r.table.columns.push_back("cb_measured");
  r.table.columns.push_back("cb_exact");
  for (auto& row : r.table.rows) row.push_back(NAN), row.push_back(NAN);
  std::string cb_text;
  for (const Setup& s : setups) {
    for (int l1 = 1; l1 <= s.l1; ++l1) {
      const double b = std::pow(s.n, l1);
      const LoadedScene sc =
          scene("poisson", {{"n", str(s.n)}, {"depth", str(l1 + 1)}, {"p", "1e-9"}});
      const TraceOutput t = trace_centre(sc, at_level(l1));
      const double trav = u(t.counters.traversed_of(RayKind::kPrimary));
      const double cb = trav / b;
      const double exact = predict(c, "c_b_exact", formulas::c_b_exact(s.n, l1));
      std::vector<double> row(r.table.columns.size(), NAN);
      row[0] = s.n, row[1] = l1, row[2] = b, row[5] = 1;  // p = 1e-9: "p -> 0"
      row[7] = trav;
      row[r.table.col("cb_measured")] = cb;
      row[r.table.col("cb_exact")] = exact;
      r.table.add(row);
      r.checks.push_back({"n=" + str(s.n) + " l1=" + str(l1) + ": C_{l1}/b = exact Eq. 6", cb,
                          exact, 1e-12, Role::kSupports, "Eqs. 5-7"});
      if (l1 == s.l1) {
        r.checks.push_back({"n=" + str(s.n) + " l1=" + str(l1) +
                                ": C_b within 1/((n-1) b) of n/(n-1), independent of l1",
                            cb, predict(c, "c_b", formulas::c_b(s.n)), 1.0 / ((s.n - 1) * b),
                            Role::kSupports, "Eqs. 5-7"});
        cb_text += "n = " + str(s.n) + ": C_b = " + fmt(cb) + " at l1 = " + str(l1) +
                   " (n/(n-1) = " + fmt(formulas::c_b(s.n)) + "); ";
      }
    }
  }
  r.summary_columns = {"n",          "p_over_b",    "mean_i",        "mean_trav",
                       "trav_exact", "eq8",         "eq4_mean",      "min_slack",
                       "mean_tests", "tests_exact", "trav_over_eq8", "tests_over_eq8"};
  for (std::size_t i = 0; i < r.table.rows.size(); ++i)
    if (r.table.rows[i][5] > 1) r.summary_rows.push_back(i);
  Panel pe{"Expected cost vs p/b (sorted traversal, level l1 rendered)",
           "p/b (expected hits per amalgam of l1)",
           "mean per primary ray",
           true,
           true,
           {}};
  for (const Setup& s : setups) {
    pe.series.push_back(
        {"p_over_b", "mean_trav", "objects traversed, n=" + str(s.n), false, "n", double(s.n)});
    pe.series.push_back({"p_over_b", "eq8", "E[Eq. 8], n=" + str(s.n), true, "n", double(s.n)});
    pe.series.push_back(
        {"p_over_b", "mean_tests", "intersection tests, n=" + str(s.n), false, "n", double(s.n)});
  }
  // cb_* are NaN outside the Eqs. 5-7 rows and p is NaN in them: gnuplot skips non-finite
  // points, so a filter on n alone selects the right rows for each panel.
  Panel pc{"Eqs. 5-7: C_{l1}/b with nothing hit", "l1", "objects traversed / b", false, false, {}};
  for (const Setup& s : setups) {
    pc.series.push_back({"l1", "cb_measured", "measured, n=" + str(s.n), false, "n", double(s.n)});
    pc.series.push_back({"l1", "cb_exact", "Eq. 6 exact, n=" + str(s.n), true, "n", double(s.n)});
  }
  r.panels = {pe, pc};
  std::string ratios;
  for (const auto& t : ratio_text) ratios += "* " + t + "\n";
  const auto v4 = verdict_of(r.checks, "Eq. 4");
  const auto v8 = verdict_of(r.checks, "Eq. 8");
  r.findings =
      "Measured over " + str(rays) +
      " rays per point (a new stochastic-opacity seed per ray), b = n^{l1} amalgams of a few "
      "hundred, p/b from 1/64 to 64.\n\n" +
      ratios +
      "\n**Eq. 8 is a counting convention, not an algebra error.** Counted as the paper "
      "counts (children reached in sorted order until the first hit) Eq. 8 " +
      std::string(v8 == Verdict::kHolds ? "holds as the estimate it is meant to be: E[Eq. 8] is "
                                          "within 15% of the expected objects traversed (which "
                                          "the measurement matches within 4 s.e.) for n = 2, 3 "
                                          "and 8 at every p/b, lowest around p/b ~ 1/8 where "
                                          "Eq. 8's max() switches branches and misses interior "
                                          "objects, and exact once the first amalgam stops the "
                                          "ray"
                                        : "does not hold (see the failed checks)") +
      ". Our renderer tests all n children of every node it enters before it sorts them, so "
      "its intersection tests exceed Eq. 8 (by up to the factor shown above, about n for "
      "p >> b: 1 + n l1 against l1 + 1); the asymptotics are the same. Eq. 4 " +
      std::string(v4 == Verdict::kHolds
                      ? "holds on every ray as a lower bound and is attained when the first "
                        "amalgam stops the ray"
                      : "does not hold (see the failed checks)") +
      ". Eqs. 5-7: " + cb_text +
      "the measured C_{l1}/b equals the exact (n^{l1+1} - 1)/((n - 1) n^{l1}) and tends to "
      "n/(n - 1) from below, independent of l1 (Figure 5's argument: past the first amalgam "
      "each further amalgam under the same parent adds one object).";
  return r;
}

}  // namespace amalgam::experiments

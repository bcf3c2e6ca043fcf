/// \file Experiment traversed: Eqs. 4-8 counted as the paper counts, "objects traversed" --
/// children reached in sorted order until the first hit (Counters::traversed_of) -- beside
/// the renderer's intersection tests (all children of every entered node), on builtin:poisson
/// for n = 2, 3 and 8.

#include <algorithm>
#include <cmath>
#include <map>

#include "amalgam/analysis/experiments/common.h"
#include "amalgam/analysis/formulas.h"
#include "amalgam/builtin/tube.h"

namespace amalgam::experiments {
using namespace detail;
// Named: a unity build compiles several experiments in one translation unit.
namespace traversed_parts {
namespace {

struct Setup {
  int n, l1;
};

/// The cost of a ray stopped by the i-th amalgam (the same for every such ray).
struct AtI {
  double trav, tests;
};

/// The rays of one setup, over all of its points: what Eq. 7's checks need.
struct RayLog {
  std::map<double, AtI> at_i;
  double model_diff = 0, tests_model_diff = 0;  ///< rays against the closed forms of cost(i)
  double eq7_excess = -1e300, eq7_tests_excess = -1e300;
};

/// One point of the sweep: `rays` rays of builtin:poisson with p expected hits, rendered at
/// level l1 (a new stochastic-opacity seed per ray); its row and the checks of Eqs. 4 and 8.
/// Returns |E[objects traversed]/E[Eq. 8] - 1| + 1 and E[tests]/E[Eq. 8] for the findings.
std::pair<double, double> point(const Config& c, ExperimentResult& r, const Setup& s, double p,
                                int rays, bool last, RayLog& log) {
  const double b = std::pow(s.n, s.l1);
  const LoadedScene sc =
      scene("poisson", {{"n", str(s.n)}, {"depth", str(s.l1 + 1)}, {"p", str(p)}});
  Mean mi, mtrav, mtests;
  double min_slack = 1e300;
  for (int ray = 0; ray < rays; ++ray) {
    RenderOptions o = at_level(s.l1);
    o.seed = static_cast<std::uint64_t>(ray);
    const TraceOutput t = trace_centre(sc, o);
    const double i =
        t.hit.kind == TraceHit::Kind::kAmalgam ? double(TubeHierarchy::index_of(t.hit.id) + 1) : b;
    const double trav = u(t.counters.traversed_of(RayKind::kPrimary));
    const double tests = u(t.counters.tests_of(RayKind::kPrimary));
    mi.add(i);
    mtrav.add(trav);
    mtests.add(tests);
    log.model_diff =
        std::max(log.model_diff, std::fabs(trav - formulas::objects_traversed_to(s.n, s.l1, i)));
    log.tests_model_diff =
        std::max(log.tests_model_diff, std::fabs(tests - formulas::tests_to(s.n, s.l1, i)));
    const double eq7 = predict(c, "eq7_linear_cost", formulas::eq7_linear_cost(s.n, i));
    log.eq7_excess = std::max(log.eq7_excess, std::fabs(trav - eq7) - (s.l1 + 1));
    log.eq7_tests_excess =
        std::max(log.eq7_tests_excess, std::fabs(tests - eq7) - (s.n * s.l1 + 1));
    log.at_i[i] = AtI{trav, tests};
    min_slack = std::min(
        min_slack, trav - predict(c, "eq4_lower_bound", formulas::eq4_lower_bound(s.n, b, i)));
  }
  const double trav_exact = formulas::expected_tests_sorted_lazy(s.n, s.l1, p);
  const double tests_exact = formulas::expected_tests_sorted(s.n, s.l1, p);
  const double eq8 =
      predict(c, "expected_eq8_cost", formulas::expected_eq8_cost(s.n, std::uint64_t(b), p));
  r.table.add({double(s.n), double(s.l1), b, p, p / b, double(rays), mi.mean(), mtrav.mean(),
               mtrav.se(), trav_exact, eq8, s.l1 + mi.mean(), min_slack, mtests.mean(), tests_exact,
               mtrav.mean() / eq8, mtests.mean() / eq8});
  const std::string where = "n=" + str(s.n) + " p/b=" + fmt(p / b);
  const double rare = 5.0 / rays;
  r.checks.push_back({where + ": objects traversed = exact expectation (4 s.e.)", mtrav.mean(),
                      trav_exact, 4 * mtrav.se() + rare * trav_exact, Role::kSupports, "Eq. 8"});
  r.checks.push_back({where + ": intersection tests = exact expectation (4 s.e.)", mtests.mean(),
                      tests_exact, 4 * mtests.se() + rare * tests_exact, Role::kSupports, "Eq. 8"});
  // Eq. 8 is a model: compared with the exact expectation of objects traversed (itself
  // checked against the measurement above), so that the comparison carries no noise.
  r.checks.push_back({where + ": E[objects traversed] within 15% of E[Eq. 8]", trav_exact / eq8,
                      1.0, 0.15, Role::kSupports, "Eq. 8"});
  // The same estimate counted as this renderer's intersection tests: the statement as a
  // count, then as an order (within the factor n of testing every child of a node).
  r.checks.push_back({where + ": E[intersection tests] within 15% of E[Eq. 8]", tests_exact / eq8,
                      1.0, 0.15, Role::kSupports, "Eq. 8, intersection tests"});
  r.checks.push_back({where + ": E[intersection tests] between 0.85 E[Eq. 8] and n E[Eq. 8]",
                      std::clamp(tests_exact / eq8, 0.85, double(s.n)), tests_exact / eq8, 0.0,
                      Role::kSupports, "Eq. 8, intersection tests"});
  // Slack tolerance: log_n b in floating point (log 243 / log 3 is 5 + 9e-16).
  r.checks.push_back({where + ": every ray traverses at least l1 + i objects (Eq. 4)",
                      std::min(min_slack, 0.0), 0.0, 1e-9, Role::kSupports, "Eq. 4"});
  if (last)
    r.checks.push_back({"n=" + str(s.n) +
                            ": Eq. 4 is attained when the first amalgam stops "
                            "the ray (min slack 0 at p/b = 64)",
                        min_slack, 0.0, 1e-9, Role::kSupports, "Eq. 4"});
  return {std::fabs(trav_exact / eq8 - 1) + 1, mtests.mean() / eq8};
}

/// Eq. 7's checks of one setup, from its rays; returns its line of the findings.
std::string eq7_checks(ExperimentResult& r, const Setup& s, const RayLog& log) {
  const double cb = formulas::c_b(s.n);
  const std::string setup = "n=" + str(s.n) + " l1=" + str(s.l1);
  r.checks.push_back({setup + ": every ray stopped by amalgam i traverses exactly "
                              "sum_k ceil(i / n^{l1-k}) objects",
                      log.model_diff, 0.0, 0.0, Role::kSupports, "Eq. 7"});
  r.checks.push_back({setup + ": every ray stopped by amalgam i makes exactly "
                              "1 + n sum_{k<l1} ceil(i / n^{l1-k}) intersection tests",
                      log.tests_model_diff, 0.0, 0.0, Role::kSupports, "Eq. 7"});
  r.checks.push_back({setup + ": objects traversed within l1 + 1 of i C_b on every ray "
                              "(Eq. 7's relative error below (l1 + 1)/(i C_b))",
                      std::max(log.eq7_excess, 0.0), 0.0, 0.0, Role::kSupports, "Eq. 7"});
  r.checks.push_back({setup + ": intersection tests within n l1 + 1 of i C_b on every ray "
                              "(Eq. 7 holds for i >> n l1 in this counting)",
                      std::max(log.eq7_tests_excess, 0.0), 0.0, 0.0, Role::kSupports, "Eq. 7"});
  // Figure 5: the first amalgam costs l1 + 1 (Eq. 4), more than Eq. 7's 1 C_b.
  const auto first = log.at_i.find(1.0);
  if (first != log.at_i.end())
    r.checks.push_back({setup + ": the first amalgam costs l1 + 1 > C_b (Figure 5: Eq. 7 "
                                "underestimates small i)",
                        first->second.trav / cb, (s.l1 + 1) / cb, 1e-12, Role::kSupports, "Eq. 7"});
  const auto last = log.at_i.rbegin();
  return "n = " + str(s.n) + ", l1 = " + str(s.l1) + ": i = 1 costs " +
         fmt(first != log.at_i.end() ? first->second.trav : NAN) +
         " objects against C_b = " + fmt(cb) + "; i = " + fmt(last->first) + " costs " +
         fmt(last->second.trav) + " against i C_b = " + fmt(last->first * cb) + " (" +
         fmt(100 * (last->second.trav / (last->first * cb) - 1)) + "%); " + "intersection tests " +
         fmt(last->second.tests) + " (" + fmt(100 * (last->second.tests / (last->first * cb) - 1)) +
         "%)";
}

/// Eqs. 5, 6: with nothing hit (p tiny) every amalgam of l1 is traversed, so objects
/// traversed = C_{l1} (Eq. 5: a count of the hierarchy's nodes, which this confirms the
/// traversal reaches); per amalgam of l1 that is C_b (Eq. 6). Returns the findings' text.
std::string eqs_5_6(const Config& c, ExperimentResult& r, const std::vector<Setup>& setups) {
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
      const std::string at = "n=" + str(s.n) + " l1=" + str(l1);
      r.checks.push_back({at + ": nothing hit, objects traversed = C_{l1} (Eq. 5)", trav,
                          predict(c, "c_l1", formulas::c_l1(s.n, l1)), 0.0, Role::kSupports,
                          "Eq. 5"});
      r.checks.push_back(
          {at + ": C_{l1}/b = exact Eq. 6", cb, exact, 1e-12, Role::kSupports, "Eq. 6"});
      if (l1 == s.l1) {
        r.checks.push_back({at + ": C_b within 1/((n-1) b) of n/(n-1), independent of l1", cb,
                            predict(c, "c_b", formulas::c_b(s.n)), 1.0 / ((s.n - 1) * b),
                            Role::kSupports, "Eq. 6"});
        cb_text += "n = " + str(s.n) + ": C_b = " + fmt(cb) + " at l1 = " + str(l1) +
                   " (n/(n-1) = " + fmt(formulas::c_b(s.n)) + "); ";
      }
    }
  }
  return cb_text;
}

/// Eq. 7's rows: the measured cost of the rays stopped by the i-th amalgam, at i = 1, 2, 3,
/// 4, 6, 8, 12, ... and the largest i reached.
void eq7_rows(ExperimentResult& r, const std::vector<Setup>& setups,
              const std::vector<RayLog>& logs) {
  for (std::size_t si = 0; si < setups.size(); ++si) {
    const Setup& s = setups[si];
    const double cb = formulas::c_b(s.n);
    for (const auto& [i, v] : logs[si].at_i) {
      const double lo = std::exp2(std::floor(std::log2(i)));
      if (i != lo && i != 1.5 * lo && &v != &logs[si].at_i.rbegin()->second) continue;
      std::vector<double> row(r.table.columns.size(), NAN);
      row[0] = s.n, row[1] = s.l1, row[2] = std::pow(s.n, s.l1);
      row[r.table.col("i")] = i;
      row[r.table.col("cost_i")] = v.trav;
      row[r.table.col("tests_i")] = v.tests;
      row[r.table.col("eq7_i")] = i * cb;
      row[r.table.col("cost_over_eq7")] = v.trav / (i * cb);
      row[r.table.col("tests_over_eq7")] = v.tests / (i * cb);
      r.table.add(row);
    }
  }
}

void add_panels(ExperimentResult& r, const std::vector<Setup>& setups) {
  Panel pe{"Expected cost vs p/b (sorted traversal, level l1 rendered)",
           "p/b (expected hits per amalgam of l1)",
           "mean per primary ray",
           Scale::kLog,
           Scale::kLog,
           {}};
  for (const Setup& s : setups) {
    pe.series.push_back({"p_over_b", "mean_trav", "objects traversed, n=" + str(s.n), Draw::kPoints,
                         "n", double(s.n)});
    pe.series.push_back(
        {"p_over_b", "eq8", "E[Eq. 8], n=" + str(s.n), Draw::kLine, "n", double(s.n)});
    pe.series.push_back({"p_over_b", "mean_tests", "intersection tests, n=" + str(s.n),
                         Draw::kPoints, "n", double(s.n)});
  }
  // cb_* are NaN outside the Eqs. 5, 6 rows, i outside the Eq. 7 rows and p is NaN in both:
  // gnuplot skips non-finite points, so a filter on n alone selects the right rows per panel.
  Panel pc{"Eqs. 5, 6: C_{l1}/b with nothing hit",
           "l1",
           "objects traversed / b",
           Scale::kLinear,
           Scale::kLinear,
           {}};
  for (const Setup& s : setups) {
    pc.series.push_back(
        {"l1", "cb_measured", "measured, n=" + str(s.n), Draw::kPoints, "n", double(s.n)});
    pc.series.push_back(
        {"l1", "cb_exact", "Eq. 6 exact, n=" + str(s.n), Draw::kLine, "n", double(s.n)});
  }
  Panel p7{"Eq. 7: cost of a ray stopped by the i-th amalgam, over i C_b",
           "i (amalgams of l1 reached)",
           "measured cost / (i C_b)",
           Scale::kLog,
           Scale::kLog,
           {}};
  for (const Setup& s : setups) {
    p7.series.push_back({"i", "cost_over_eq7", "objects traversed, n=" + str(s.n), Draw::kPoints,
                         "n", double(s.n)});
    p7.series.push_back({"i", "tests_over_eq7", "intersection tests, n=" + str(s.n), Draw::kPoints,
                         "n", double(s.n)});
  }
  r.panels = {pe, pc, p7};
}

/// Title, claim, prediction and the columns of the p/b sweep.
void describe(ExperimentResult& r) {
  r.title = "Eqs. 4-8 as the paper counts: objects traversed in sorted order";
  r.claim =
      "A traversal that stops after the i-th amalgam of level l1 costs at least l1 + i "
      "(Eq. 4: the left edge and the i amalgams); the objects above and within l1 cost "
      "C_b = n/(n - 1) per amalgam of l1, independent of l1 (Eqs. 5, 6), so reaching the "
      "first i amalgams costs about i C_b, more accurately as i grows (Eq. 7); overall the "
      "cost is max(log_n b + i, i C_b) (Eq. 8). The paper counts *objects traversed*: "
      "children reached in sorted order until the first hit.";
  r.prediction =
      "Objects traversed (`Counters::traversed_of`: nodes reached in sorted order plus "
      "primitives tested) against Eq. 4 per ray, against `formulas::expected_eq8_cost` "
      "(E[Eq. 8] under Eq. 9's distribution of i) and against its exact expectation "
      "`formulas::expected_tests_sorted_lazy`; the renderer's intersection tests (all n "
      "children of every entered node) against `formulas::expected_tests_sorted`. Eq. 7, "
      "ray by ray: the cost of a ray stopped by the i-th amalgam against i C_b, in both "
      "countings (exactly `formulas::objects_traversed_to` and `tests_to`: within l1 + 1 and "
      "n l1 + 1 of i C_b, so Eq. 7's relative error falls as 1/i). Eqs. 5, 6: objects "
      "traversed when nothing is hit (p -> 0), against C_{l1} and, divided by b, against "
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
}

/// The findings: each estimate with the counting it holds under.
std::string findings(const ExperimentResult& r, int rays, const std::string& ratios,
                     const std::string& eq7, const std::string& cb_text) {
  const auto v4 = verdict_of(r.checks, "Eq. 4");
  const auto v7 = verdict_of(r.checks, "Eq. 7");
  const auto v8 = verdict_of(r.checks, "Eq. 8");
  const auto v8t = verdict_of(r.checks, "Eq. 8, intersection tests");
  return "Measured over " + str(rays) +
         " rays per point (a new stochastic-opacity seed per ray), b = n^{l1} amalgams of a few "
         "hundred, p/b from 1/64 to 64.\n\n" +
         ratios +
         "\n**Each estimate holds under one counting, stated here.** Counted as the paper "
         "counts (objects traversed: children reached in sorted order until the first hit) "
         "Eq. 8 " +
         std::string(v8 == Verdict::kHolds ? "holds as the estimate it is meant to be: E[Eq. 8] is "
                                             "within 15% of the expected objects traversed (which "
                                             "the measurement matches within 4 s.e.) for n = 2, 3 "
                                             "and 8 at every p/b, lowest around p/b ~ 1/8 where "
                                             "Eq. 8's max() switches branches and misses interior "
                                             "objects, and exact once the first amalgam stops the "
                                             "ray"
                                           : "does not hold (see the failed checks)") +
         ". Counted as this renderer's intersection tests (all n children of every entered node, "
         "tested before they are sorted) Eq. 8 " +
         std::string(v8t == Verdict::kHolds
                         ? "also holds within 15%"
                         : "does not hold as a count: the tests exceed it by up to the factor "
                           "shown above, about n for p >> b (1 + n l1 against l1 + 1); they stay "
                           "within a factor n of it, so the order of growth is the same") +
         ". Eq. 4 " +
         std::string(v4 == Verdict::kHolds
                         ? "holds on every ray as a lower bound (in both countings, since every "
                           "object traversed is tested) and is attained when the first amalgam "
                           "stops the ray"
                         : "does not hold (see the failed checks)") +
         ".\n\n**Eq. 7 on its own**, ray by ray: a ray stopped by the i-th amalgam of l1 costs "
         "exactly sum_{k=0}^{l1} ceil(i / n^{l1-k}) objects traversed and 1 + n sum_{k<l1} "
         "ceil(i / n^{l1-k}) intersection tests (every ray measured agrees). Each ceiling adds "
         "less than one to i/n^{l1-k}, so the cost is i C_{l1}/b plus at most l1 + 1 (n l1 + 1 "
         "for tests): Eq. 7's i C_b is off by a bounded amount, a relative error that falls as "
         "1/i. Eq. 7 " +
         std::string(v7 == Verdict::kHolds
                         ? "holds in both countings, as the paper says for large i; for small i "
                           "it underestimates (the first amalgam costs l1 + 1, Figure 5's A):"
                         : "does not hold (see the failed checks):") +
         "\n\n" + eq7 +
         "\nEqs. 5, 6: with nothing hit the traversal reaches every object above and within l1, "
         "the C_{l1} of Eq. 5 (which counts the hierarchy: the check confirms the traversal "
         "reaches each node once). " +
         cb_text +
         "the measured C_{l1}/b equals the exact (n^{l1+1} - 1)/((n - 1) n^{l1}) and tends to "
         "n/(n - 1) from below, independent of l1 (Figure 5's argument: past the first amalgam "
         "each further amalgam under the same parent adds one object).";
}

}  // namespace
}  // namespace traversed_parts

ExperimentResult traversed(const Config& c) {
  using namespace traversed_parts;
  ExperimentResult r;
  describe(r);
  // b = n^l1 of a few hundred amalgams, so that i ranges widely when p/b is small.
  const std::vector<Setup> setups = {{2, 8}, {3, 5}, {8, 3}};
  const int rays = c.quick ? 800 : 20000;
  const int kstep = c.quick ? 3 : 1;
  std::string ratios, eq7;
  std::vector<RayLog> logs(setups.size());
  for (std::size_t si = 0; si < setups.size(); ++si) {
    const Setup& s = setups[si];
    double worst_ratio = 1, worst_tests_ratio = 1;
    for (int k = -6; k <= 6; k += kstep) {
      const double p = std::pow(s.n, s.l1) * std::ldexp(1.0, k);
      const auto [ratio, tests_ratio] = point(c, r, s, p, rays, k == 6, logs[si]);
      worst_ratio = std::max(worst_ratio, ratio);
      worst_tests_ratio = std::max(worst_tests_ratio, tests_ratio);
    }
    eq7 += "* " + eq7_checks(r, s, logs[si]) + "\n";
    ratios += "* n = " + str(s.n) + " (b = " + fmt(std::pow(s.n, s.l1)) +
              "): expected objects traversed within " + fmt(100 * (worst_ratio - 1)) +
              "% of E[Eq. 8] at the points measured; intersection tests up to " +
              fmt(worst_tests_ratio) + " times E[Eq. 8]\n";
  }
  for (const char* col : {"cb_measured", "cb_exact", "i", "cost_i", "tests_i", "eq7_i",
                          "cost_over_eq7", "tests_over_eq7"})
    r.table.columns.push_back(col);
  for (auto& row : r.table.rows) row.resize(r.table.columns.size(), NAN);
  const std::string cb_text = eqs_5_6(c, r, setups);
  eq7_rows(r, setups, logs);
  r.summary_columns = {"n",          "p_over_b",    "mean_i",        "mean_trav",
                       "trav_exact", "eq8",         "eq4_mean",      "min_slack",
                       "mean_tests", "tests_exact", "trav_over_eq8", "tests_over_eq8"};
  for (std::size_t i = 0; i < r.table.rows.size(); ++i)
    if (r.table.rows[i][5] > 1) r.summary_rows.push_back(i);  // the p sweep
  add_panels(r, setups);
  r.findings = findings(r, rays, ratios, eq7, cb_text);
  return r;
}

}  // namespace amalgam::experiments

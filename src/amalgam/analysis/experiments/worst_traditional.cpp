/// \file Experiment worst-traditional: the traditional renderer in the worst case on
/// builtin:line (the paper's Figure 3), C_t0 = O(p).

#include <cmath>

#include "amalgam/analysis/experiments/common.h"
#include "amalgam/analysis/formulas.h"

namespace amalgam::experiments {
using namespace detail;

ExperimentResult worst_traditional(const Config& c) {
  ExperimentResult r;
  r.title = "Worst case, traditional renderer (C_t0 = O(p))";
  r.claim =
      "In the worst case (Figure 3: everything on the primary ray, only the last primitive "
      "hit) the traditional renderer examines every object of the hierarchy, "
      "C_t0 = sum_{i=0}^{l_max} n^i = O(p), and its one shadow ray costs as much again.";
  r.prediction = "`formulas::c_t0(n, l_max)` for the primary ray and for the shadow ray.";
  r.table.columns = {"n", "l_max", "p", "primary", "shadow", "c_t0", "primary_over_p"};
  struct Sweep {
    int n, max_depth;
  };
  const std::vector<Sweep> sweeps = c.quick ? std::vector<Sweep>{{2, 10}, {3, 6}, {8, 3}}
                                            : std::vector<Sweep>{{2, 21}, {3, 12}, {8, 7}};
  for (const Sweep& s : sweeps) {
    for (int d = 1; d <= s.max_depth; ++d) {
      const LoadedScene sc = scene("line", {{"n", str(s.n)}, {"depth", str(d)}});
      const TraceOutput t = trace_centre(sc, traditional());
      const double p = std::pow(s.n, d);
      const double prim = u(t.counters.tests_of(RayKind::kPrimary));
      const double pred = predict(c, "c_t0", formulas::c_t0(s.n, d));
      r.table.add({double(s.n), double(d), p, prim, u(t.counters.tests_of(RayKind::kShadow)), pred,
                   prim / p});
      r.checks.push_back({"n=" + str(s.n) + " l_max=" + str(d) + " primary = C_t0", prim, pred, 0});
      r.checks.push_back({"n=" + str(s.n) + " l_max=" + str(d) + " shadow = C_t0",
                          r.table.rows.back()[4], pred, 0});
    }
  }
  // Growth: slope of log(tests) against log(p) over the largest half of each sweep.
  std::string slopes;
  for (const Sweep& s : sweeps) {
    std::vector<double> x, y;
    for (const auto& row : r.table.rows)
      if (row[0] == s.n && row[1] > s.max_depth / 2) {
        x.push_back(std::log(row[2]));
        y.push_back(std::log(row[3]));
      }
    const LinearFit f = fit_line(x, y);
    slopes += "n=" + str(s.n) + ": " + fmt(f.b) + "; ";
    r.checks.push_back(
        {"n=" + str(s.n) + " log-log slope of tests vs p ~ 1 (O(p))", f.b, 1.0, 0.05});
  }
  r.summary_columns = {"n", "l_max", "p", "primary", "shadow", "c_t0", "primary_over_p"};
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    const auto& row = r.table.rows[i];
    const int n = int(row[0]);
    const int maxd = n == 2   ? sweeps[0].max_depth
                     : n == 3 ? sweeps[1].max_depth
                              : sweeps[2].max_depth;
    if (int(row[1]) == maxd || int(row[1]) == 1 || int(row[1]) == maxd / 2)
      r.summary_rows.push_back(i);
  }
  r.panels.push_back({"Traditional renderer on builtin:line",
                      "p = n^{l_max} (primitives on the ray)",
                      "intersection tests per ray",
                      Scale::kLog,
                      Scale::kLog,
                      {{"p", "primary", "primary ray, n=2", Draw::kPoints, "n", 2},
                       {"p", "shadow", "shadow ray, n=2", Draw::kPoints, "n", 2},
                       {"p", "primary", "primary ray, n=3", Draw::kPoints, "n", 3},
                       {"p", "primary", "primary ray, n=8", Draw::kPoints, "n", 8},
                       {"p", "c_t0", "C_t0, n=2", Draw::kLine, "n", 2},
                       {"p", "c_t0", "C_t0, n=3", Draw::kLine, "n", 3},
                       {"p", "c_t0", "C_t0, n=8", Draw::kLine, "n", 8}}});
  tag(r, "C_t0");
  r.findings =
      "Primary and shadow ray each cost exactly C_t0 for every (n, l_max) measured "
      "(largest: p = " +
      fmt(r.table.rows[sweeps[0].max_depth - 1][2]) + ", " +
      fmt(r.table.rows[sweeps[0].max_depth - 1][3]) +
      " tests per ray for n=2). Tests/p tends to n/(n-1) (2, 1.5, 1.14): linear in p. "
      "Log-log slopes of tests against p: " +
      slopes + "i.e. O(p).";
  return r;
}

}  // namespace amalgam::experiments

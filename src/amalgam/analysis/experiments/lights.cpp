/// \file Experiment lights: multiple light sources on builtin:line (Figure 3).

#include <cmath>

#include "amalgam/analysis/experiments/common.h"
#include "amalgam/analysis/formulas.h"

namespace amalgam::experiments {
using namespace detail;

ExperimentResult lights(const Config& c) {
  ExperimentResult r;
  r.title = "Multiple light sources";
  r.claim =
      "Each light adds one shadow ray per shaded point, of the same cost as the primary ray: "
      "cost scales linearly with the number of lights for the traditional and stochastic "
      "renderers; with deterministic opacity the renderer spawns one shadow ray per light "
      "and per rendered amalgam, which again only scales Eq. 2.";
  r.prediction =
      "traditional (1 + L) C_t0; stochastic (1 + L) C_s0; deterministic C_s0 + L C_sd1 "
      "(bound), with L n^{l1} shadow rays (exact count for builtin:line: C_s0 + L x shadow "
      "sum).";
  r.table.columns = {"lights",    "trad_total", "trad_pred", "stoch_total",     "stoch_pred",
                     "det_total", "det_bound",  "det_exact", "det_shadow_rays", "det_rays_pred"};
  const int n = 3, depth = c.quick ? 6 : 10, l1 = c.quick ? 3 : 5;
  for (int L = 1; L <= 8; ++L) {
    const LoadedScene s0 =
        scene("line", {{"n", str(n)}, {"depth", str(depth)}, {"lights", str(L)}});
    const LoadedScene sa =
        scene("line", {{"n", str(n)}, {"depth", str(depth)}, {"lights", str(L)}, {"alpha", "0.5"}});
    const double tr = u(trace_centre(s0, traditional()).counters.total());
    const double st = u(trace_centre(s0, at_level(l1)).counters.total());
    const TraceOutput dt = trace_centre(sa, at_level(l1, OpacityKind::kDeterministic));
    const double cs0 = formulas::c_s0(n, l1);
    const double det_exact = cs0 + L * line_deterministic_shadow(n, l1);
    r.table.add({double(L), tr, (1 + L) * formulas::c_t0(n, depth), st, (1 + L) * cs0,
                 u(dt.counters.total()), cs0 + L * formulas::c_sd1(n, l1), det_exact,
                 u(dt.counters.rays[1]), L * std::pow(n, l1)});
    const auto& row = r.table.rows.back();
    r.checks.push_back({"L=" + str(L) + " traditional = (1+L) C_t0", row[1], row[2], 0});
    r.checks.push_back({"L=" + str(L) + " stochastic = (1+L) C_s0", row[3], row[4], 0});
    r.checks.push_back({"L=" + str(L) + " deterministic = exact", row[5], row[7], 0});
    r.checks.push_back({"L=" + str(L) + " deterministic shadow rays = L n^l1", row[8], row[9], 0});
  }
  r.summary_columns = r.table.columns;
  r.panels.push_back(
      {"Cost vs number of lights (builtin:line n=3, l_max=" + str(depth) + ", l1=" + str(l1) + ")",
       "lights",
       "tests per primary ray (all rays)",
       Scale::kLinear,
       Scale::kLog,
       {{"lights", "trad_total", "traditional", Draw::kPoints},
        {"lights", "trad_pred", "(1+L) C_t0", Draw::kLine},
        {"lights", "stoch_total", "stochastic", Draw::kPoints},
        {"lights", "stoch_pred", "(1+L) C_s0", Draw::kLine},
        {"lights", "det_total", "deterministic", Draw::kPoints},
        {"lights", "det_bound", "C_s0 + L C_sd1", Draw::kLine}}});
  tag(r, "Lights");
  r.findings =
      "All three renderers scale exactly linearly in the number of lights L: "
      "traditional (1+L) C_t0 = " +
      fmt(r.table.rows[0][1]) + " -> " + fmt(r.table.rows[7][1]) +
      " tests; stochastic (1+L) C_s0 = " + fmt(r.table.rows[0][3]) + " -> " +
      fmt(r.table.rows[7][3]) + "; deterministic spawns exactly L n^{l1} shadow rays (" +
      fmt(r.table.rows[7][8]) + " at L=8) and its cost " + fmt(r.table.rows[0][5]) + " -> " +
      fmt(r.table.rows[7][5]) + " stays below the scaled Eq. 2 bound.";
  return r;
}

}  // namespace amalgam::experiments

/// \file Experiment worst-deterministic: the scale-sensitive renderer with deterministic
/// opacity in the worst case on builtin:line (Figure 3, Eqs. 1, 2) and the 2 l1 = l_max
/// crossover.

#include <algorithm>
#include <cmath>

#include "amalgam/analysis/experiments/common.h"
#include "amalgam/analysis/formulas.h"

namespace amalgam::experiments {
using namespace detail;
// Named: a unity build compiles several experiments in one translation unit.
namespace worst_deterministic_parts {
namespace {

constexpr int n = 2;
constexpr double alpha = 0.5;  ///< the opacity of the translucent amalgams

/// What the parts share: the sweep's bounds, the traditional totals (2 C_t0 by l_max) and
/// the largest l1 at which deterministic opacity is still faster, by l_max.
struct Sweep {
  int max_lmax, max_l1;
  std::vector<double> trad;
  std::vector<int> crossover;
};

/// Title, claim, prediction and columns.
void describe(ExperimentResult& r) {
  r.title = "Worst case, deterministic opacity (Eqs. 1, 2) and the 2 l1 = l_max crossover";
  r.claim =
      "With deterministic opacity every one of the n^{l1} translucent amalgams on level l1 "
      "spawns a shadow ray: C_s0 + C_sd1 = O(n^{2 l1}) (Eqs. 1, 2). The scale-sensitive "
      "renderer beats the traditional one (O(n^{l_max})) only while 2 l1 < l_max; the "
      "efficiently renderable fraction of the database is alpha sqrt(1/p) (as printed).";
  r.prediction =
      "`formulas::c_s0`, `c_sd1`, `deterministic_total` (upper bound); for builtin:line the "
      "exact count b + n sum_{m<l1} (b(n^m+1)/2 - n^m) (a shadow ray crosses half the line on "
      "average); `formulas::c_t0` for the traditional renderer; "
      "`formulas::efficient_fraction(p)` = sqrt(1/p) and `efficient_fraction_exact(n, "
      "l_max)` (the alphas cancel; the printed alpha sqrt(1/p) is "
      "`efficient_fraction_as_printed`).";
  r.table.columns = {"n",           "l1",         "l_max",        "det_primary",
                     "det_shadow",  "det_total",  "eq1_plus_eq2", "line_exact",
                     "shadow_rays", "trad_total", "det_faster",   "growth_per_level"};
}

/// The traditional renderer's total on builtin:line for every l_max: 2 C_t0.
void traditional_totals(const Config& c, ExperimentResult& r, Sweep& w) {
  const int max_lmax = w.max_lmax;
  w.trad.assign(max_lmax + 1, 0);
  std::vector<double>& trad = w.trad;
  for (int lm = 1; lm <= max_lmax; ++lm) {
    const LoadedScene sc = scene("line", {{"n", str(n)}, {"depth", str(lm)}});
    trad[lm] = u(trace_centre(sc, traditional()).counters.total());
    r.checks.push_back({"traditional total l_max=" + str(lm) + " = 2 C_t0", trad[lm],
                        2 * predict(c, "c_t0", formulas::c_t0(n, lm)), 0});
  }
  tag(r, "C_t0");
}

/// Deterministic opacity at every (l1, l_max): its row, Eqs. 1 and 2 at l_max = l1 + 1,
/// and the crossover with the traditional renderer.
void deterministic_grid(const Config& c, ExperimentResult& r, Sweep& w) {
  const int max_lmax = w.max_lmax, max_l1 = w.max_l1;
  const std::vector<double>& trad = w.trad;
  w.crossover.assign(max_lmax + 1, -1);  // largest l1 where deterministic is faster
  std::vector<int>& crossover = w.crossover;
  for (int l1 = 0; l1 <= max_l1; ++l1) {
    for (int lm = l1 + 1; lm <= max_lmax; ++lm) {
      const LoadedScene sc =
          scene("line", {{"n", str(n)}, {"depth", str(lm)}, {"alpha", str(alpha)}});
      const TraceOutput t = trace_centre(sc, at_level(l1, OpacityKind::kDeterministic));
      const double prim = u(t.counters.tests_of(RayKind::kPrimary));
      const double sh = u(t.counters.tests_of(RayKind::kShadow));
      const double exact = formulas::c_s0(n, l1) + line_deterministic_shadow(n, l1);
      const bool faster = prim + sh < trad[lm];
      if (faster) crossover[lm] = std::max(crossover[lm], l1);
      r.table.add({double(n), double(l1), double(lm), prim, sh, prim + sh,
                   formulas::deterministic_total(n, l1), exact, u(t.counters.rays[1]), trad[lm],
                   faster ? 1.0 : 0.0, 0.0});
      if (lm == l1 + 1) {
        r.checks.push_back({"l1=" + str(l1) + " primary = C_s0 (Eq. 1)", prim,
                            predict(c, "c_s0", formulas::c_s0(n, l1)), 0, Role::kSupports,
                            "Eq. 1"});
        r.checks.push_back({"l1=" + str(l1) + " total = exact line count", prim + sh, exact, 0});
        r.checks.push_back(
            {"l1=" + str(l1) + " shadow rays = n^l1", u(t.counters.rays[1]), std::pow(n, l1), 0});
        r.checks.push_back({"l1=" + str(l1) + " total <= Eq. 1 + Eq. 2 (bound holds)",
                            std::min(prim + sh, predict(c, "deterministic_total",
                                                        formulas::deterministic_total(n, l1))),
                            prim + sh, 0});
      }
    }
  }
}

/// Growth per level of the deterministic total (first row of each l1), -> n^2.
double growth(ExperimentResult& r, int max_l1) {
  std::vector<double> first_total(max_l1 + 1, 0);
  for (auto& row : r.table.rows)
    if (row[2] == row[1] + 1) first_total[int(row[1])] = row[5];
  for (auto& row : r.table.rows) {
    const int l1 = int(row[1]);
    if (l1 > 0 && first_total[l1 - 1] > 0) row[11] = row[5] / first_total[l1 - 1];
  }
  r.checks.push_back({"growth per level of C_s0+C_sd1 at largest l1 ~ n^2 = 4",
                      first_total[max_l1] / first_total[max_l1 - 1], 4.0, 0.25});
  tag(r, "Eq. 2");
  return first_total[max_l1] / first_total[max_l1 - 1];
}

/// The crossover, by the paper's bound and as measured, for the findings.
struct Crossover {
  std::string table, bound_misses, measured_misses;
  int bound_ok = 0, bound_n = 0, measured_ok = 0, measured_n = 0;
};

Crossover crossover(ExperimentResult& r, const Sweep& w) {
  const int max_lmax = w.max_lmax, max_l1 = w.max_l1;
  const std::vector<int>& crossover = w.crossover;
  Crossover x;
  int& bound_ok = x.bound_ok;
  int& bound_n = x.bound_n;
  std::string& bound_misses = x.bound_misses;
  // The crossover by the paper's own bound: the largest l1 with C_s0 + C_sd1 < 2 C_t0 (worst
  // case of both renderers), from the exact sums, for n = 2, 3 and 8. For n = 2 it is
  // floor(l_max / 2): (2^{l1+1} - 1)(2^{l1} + 1) < 2 (2^{l_max+1} - 1) holds for 2 l1 <= l_max
  // and fails for 2 l1 >= l_max + 1.
  const int bound_ns[] = {2, 3, 8};
  for (int bn : bound_ns)
    for (int lm = 2; lm <= max_lmax; ++lm, ++bound_n) {
      int cross_at = -1;
      for (int l1 = 0; l1 < lm; ++l1)
        if (formulas::deterministic_total(bn, l1) < 2 * formulas::c_t0(bn, lm)) cross_at = l1;
      if (cross_at == lm / 2)
        ++bound_ok;
      else
        bound_misses += " n=" + str(bn) + " l_max=" + str(lm) + ": " + str(cross_at) + ";";
    }
  // Crossover table: l1* (largest l1 still faster) vs l_max / 2, where the grid of l1 decides
  // it (l1* below the largest l1 rendered). Checked exactly, l_max by l_max.
  std::string& cross = x.table;
  std::string& measured_misses = x.measured_misses;
  int& measured_ok = x.measured_ok;
  int& measured_n = x.measured_n;
  for (int lm = 2; lm <= max_lmax; ++lm) {
    if (crossover[lm] < 0 || crossover[lm] >= max_l1) continue;
    cross += "| " + str(lm) + " | " + fmt(lm / 2.0) + " | " + str(crossover[lm]) + " | " +
             fmt(formulas::efficient_fraction(std::pow(n, lm))) + " | " +
             fmt(std::pow(n, crossover[lm]) / std::pow(n, lm)) + " |\n";
    ++measured_n;
    if (crossover[lm] == (lm + 1) / 2)
      ++measured_ok;
    else
      measured_misses += " l_max=" + str(lm) + ": " + str(crossover[lm]) + ";";
  }
  r.checks.push_back({"measured crossover l1* = ceil(l_max/2) for each of the " + str(measured_n) +
                          " l_max the grid decides",
                      double(measured_ok), double(measured_n), 0});
  r.checks.push_back(
      {"paper's own bound (Eq. 1 + Eq. 2 vs 2 C_t0, exact sums): crossover at floor(l_max/2) "
       "for every l_max, n = 2, 3, 8",
       double(bound_ok), double(bound_n), 0});
  tag(r, "2 l1 < l_max");
  return x;
}

/// The efficient fraction, measured and as the exact sums give it.
struct Fraction {
  int lm = 0;
  double ratio = 0, exact = 0, other_ratio = 0, other_alpha = 0;
};

Fraction efficient_fraction(const Config& c, ExperimentResult& r, const Sweep& w) {
  const std::vector<double>& trad = w.trad;
  // The efficient fraction from measured counts: objects examined down to l1 = l_max / 2
  // (C_s0, the primary cost at that level) over all objects (C_t0, a traditional primary ray),
  // for even l_max, against sqrt(1/p) = n^{-l_max/2}.
  double frac_ratio = 0;
  int frac_lm = 0;
  for (const auto& row : r.table.rows) {
    const int l1 = int(row[1]), lm = int(row[2]);
    if (2 * l1 != lm || lm < frac_lm) continue;
    frac_lm = lm;
    frac_ratio = (row[3] / (trad[lm] / 2)) / std::pow(n, -lm / 2.0);
  }
  // The fraction's constant: the alphas cancel, the measured ratio tends to n/(n-1) / (n/(n-1))
  // = 1 (exactly (n^{L/2+1} - 1)/(n^{L+1} - 1) n^{L/2} -> 1), not to alpha.
  const double frac_exact = formulas::efficient_fraction_exact(n, frac_lm) /
                            formulas::efficient_fraction(std::pow(n, frac_lm));
  r.checks.push_back(
      {"efficient fraction / sqrt(1/p) at l1 = l_max/2 = (n^{L/2+1}-1) n^{L/2}/(n^{L+1}-1) "
       "(-> 1: the alphas cancel)",
       frac_ratio, predict(c, "efficient_fraction_constant", frac_exact), 1e-9, Role::kSupports,
       "Efficient fraction"});
  // The printed alpha sqrt(1/p) scales with alpha; the measured fraction does not: the same
  // scene at another opacity gives the same counts, so the printed form can hold for at most
  // one alpha (1, by the check above), whichever alpha is tried.
  const double other_alpha = alpha / 2;
  const LoadedScene other =
      scene("line", {{"n", str(n)}, {"depth", str(frac_lm)}, {"alpha", str(other_alpha)}});
  const double other_ratio =
      u(trace_centre(other, at_level(frac_lm / 2, OpacityKind::kDeterministic))
            .counters.tests_of(RayKind::kPrimary)) /
      (trad[frac_lm] / 2) / std::pow(n, -frac_lm / 2.0);
  const double printed_change =
      formulas::efficient_fraction_as_printed(alpha, std::pow(n, frac_lm)) /
      formulas::efficient_fraction_as_printed(other_alpha, std::pow(n, frac_lm));
  r.checks.push_back({"printed alpha sqrt(1/p) changes by alpha/alpha' = " + fmt(printed_change) +
                          " from alpha' = " + fmt(other_alpha) + " to alpha = " + fmt(alpha) +
                          "; the measured fraction by (differs by > 10%)",
                      std::min(std::fabs(frac_ratio / other_ratio / printed_change - 1), 0.1), 0.1,
                      0, Role::kRefutesPrinted, "Efficient fraction"});
  return {frac_lm, frac_ratio, frac_exact, other_ratio, other_alpha};
}

void add_panels(ExperimentResult& r, int max_lmax, int max_l1) {
  r.summary_columns = {"l1",           "l_max",      "det_primary", "det_shadow",      "det_total",
                       "eq1_plus_eq2", "line_exact", "shadow_rays", "growth_per_level"};
  for (std::size_t i = 0; i < r.table.rows.size(); ++i)
    if (r.table.rows[i][2] == r.table.rows[i][1] + 1) r.summary_rows.push_back(i);
  r.panels.push_back(
      {"Deterministic opacity, builtin:line n=2, alpha=0.5",
       "l1 (rendered level)",
       "intersection tests per primary ray (all rays)",
       Scale::kLinear,
       Scale::kLog,
       {{"l1", "det_total", "measured C_s0 + shadows", Draw::kPoints, "l_max", double(max_lmax)},
        {"l1", "eq1_plus_eq2", "Eq. 1 + Eq. 2 (bound)", Draw::kLine, "l_max", double(max_lmax)},
        {"l1", "line_exact", "exact count for this scene", Draw::kLine, "l_max",
         double(max_lmax)}}});
  Panel cp{"Crossover: deterministic vs traditional (n=2)",
           "l_max",
           "tests per primary ray",
           Scale::kLinear,
           Scale::kLog,
           {}};
  for (int l1 : {2, 4, max_l1 - 1})
    cp.series.push_back(
        {"l_max", "det_total", "deterministic, l1=" + str(l1), Draw::kPoints, "l1", double(l1)});
  cp.series.push_back({"l_max", "trad_total", "traditional (2 C_t0)", Draw::kLine, "l1", 0});
  r.panels.push_back(cp);
}

std::string findings(double grew, const Crossover& x, const Fraction& f) {
  return "Primary cost is exactly C_s0 and there is exactly one shadow ray per rendered amalgam "
         "(n^{l1}). The measured total equals the exact count for this scene and stays below the "
         "bound C_s0 + C_sd1 (ratio -> 1/2: each shadow ray crosses on average half of the line, "
         "not all of it); it grows by a factor " +
         fmt(grew) +
         " per level (n^2 = 4): O(n^{2 l1}) as Eq. 2 says.\n\n"
         "Crossover (largest l1 at which deterministic still beats the traditional renderer, "
         "measured over the (l1, l_max) grid):\n\n"
         "| l_max | l_max/2 | measured l1* | sqrt(1/p) | n^{l1*}/n^{l_max} |\n"
         "|---|---|---|---|---|\n" +
         x.table + "\nMeasured on builtin:line (n = 2): l1* = ceil(l_max / 2) for " +
         str(x.measured_ok) + " of " + str(x.measured_n) + " l_max" +
         (x.measured_misses.empty() ? std::string() : " (otherwise:" + x.measured_misses + ")") +
         ", one level past the paper's own bound: by Eq. 1 + Eq. 2 against 2 C_t0, with the exact "
         "sums, the crossover is floor(l_max / 2) for " +
         str(x.bound_ok) + " of " + str(x.bound_n) + " (n, l_max) with n = 2, 3, 8" +
         (x.bound_misses.empty() ? std::string() : " (otherwise:" + x.bound_misses + ")") +
         ". On this scene a shadow ray crosses on average only half of the line, so the measured "
         "deterministic cost is about half the bound. **The paper's strict 2 l1 < l_max holds "
         "only asymptotically**: with the exact sums the deterministic renderer still beats "
         "2 C_t0 at 2 l1 = l_max (the bound gives floor(l_max / 2), not floor((l_max - 1) / 2)), "
         "and on the measured scene one level further.\n\n"
         "**The efficient fraction has no free constant.** As printed, alpha n^{l_max/2} / "
         "(alpha n^{l_max}) = alpha n^{-l_max/2} keeps an alpha that cancels. Both counts are "
         "the same kind of sum, (n^{k+1} - 1)/(n - 1), so the fraction is "
         "(n^{l_max/2+1} - 1)/(n^{l_max+1} - 1) -> n^{-l_max/2} = sqrt(1/p) exactly: measured "
         "(C_s0 at l1 = l_max/2 over C_t0, l_max = " +
         str(f.lm) + "), fraction / sqrt(1/p) = " + fmt(f.ratio) + " = " + fmt(f.exact) +
         " by the exact sums (-> 1 as l_max grows). It depends on p alone (and on n only through "
         "the "
         "rounding of l_max/2 when l_max is "
         "odd: l1 = floor or ceil of l_max/2 gives sqrt(1/(n p)) or sqrt(n/p)). The printed "
         "alpha sqrt(1/p) is refuted for every alpha other than 1: halving the scene's alpha "
         "(" +
         fmt(alpha) + " -> " + fmt(f.other_alpha) + ") leaves the measured fraction at " +
         fmt(f.other_ratio) + " sqrt(1/p), where the printed form would halve it.";
}

}  // namespace
}  // namespace worst_deterministic_parts

ExperimentResult worst_deterministic(const Config& c) {
  using namespace worst_deterministic_parts;
  ExperimentResult r;
  describe(r);
  Sweep w{c.quick ? 10 : 20, c.quick ? 6 : 10, {}, {}};
  traditional_totals(c, r, w);
  deterministic_grid(c, r, w);
  const double grew = growth(r, w.max_l1);
  const Crossover x = crossover(r, w);
  const Fraction f = efficient_fraction(c, r, w);
  add_panels(r, w.max_lmax, w.max_l1);
  r.findings = findings(grew, x, f);
  return r;
}

}  // namespace amalgam::experiments

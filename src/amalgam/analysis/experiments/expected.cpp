/// \file Experiment expected: the expected case on builtin:poisson, sorted traversal
/// (Eqs. 8-13).

#include <cmath>
#include <functional>
#include <limits>

#include "amalgam/analysis/experiments/common.h"
#include "amalgam/analysis/formulas.h"
#include "amalgam/builtin/tube.h"

namespace amalgam::experiments {
using namespace detail;

// Named: a unity build compiles several experiments in one translation unit.
namespace expected_parts {
namespace {

double safe(const std::function<double()>& f) {
  try {
    const double v = f();
    return std::isfinite(v) ? v : std::numeric_limits<double>::quiet_NaN();
  } catch (const std::exception&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

constexpr int n = 2;  // children per node in every sweep

/// Title, claim, prediction and columns.
void describe(ExperimentResult& r) {
  r.title = "Expected case: the Poisson model, sorted traversal (Eqs. 8-13)";
  r.claim =
      "With hits along the ray a Poisson process and a sorted traversal, the number of "
      "amalgams visited on level l1 has the mean of Eq. 9. For the traditional renderer "
      "(l1 = l_max - 1, p/b = n) this is Eq. 10, whose large-p limit Eq. 12 states as "
      "(1 - e^{-n}) = O(1); for the scale-sensitive renderer with b fixed it is Eq. 13, "
      "O(1). The overall cost (Eq. 8) is dominated by the logarithmic term: O(log p) for "
      "the traditional renderer and O(log b) for the scale-sensitive one.";
  r.prediction =
      "E[i]: `formulas::expected_visits_exact` (= Eq. 9, 10, 13 as printed, which "
      "`expected_visits_eq9_as_printed`, `eq10_traditional`, `eq13_scale_sensitive` evaluate "
      "literally); `eq12_limit` (printed) vs `eq12_correct_limit`; tests per primary ray: "
      "`expected_tests_sorted` / `expected_tests_traditional` (exact for this traversal) and "
      "`expected_eq8_cost` (the paper's Eq. 8 model).";
  r.table.columns = {"sweep",
                     "n",
                     "l1",
                     "l_max",
                     "p",
                     "b",
                     "rays",
                     "mean_i",
                     "se_i",
                     "eq9_exact",
                     "eq9_printed",
                     "eq10_or_13_printed",
                     "eq12_printed",
                     "eq12_correct",
                     "mean_tests",
                     "se_tests",
                     "tests_exact",
                     "eq8_expected",
                     "log2_p",
                     "log2_b"};
}

/// One point of a sweep (0: traditional, p/b = n, Eq. 10; 1: scale-sensitive, b fixed, Eq. 13;
/// 2: p fixed, Eq. 9): its row and the checks of E[i] and of the tests per primary ray.
void add_row(const Config& c, ExperimentResult& r, int sweep, int l1, int lm, double p,
             const Mean& mi, const Mean& mt, double tests_exact) {
  const double b = std::pow(n, l1);
  const double e = predict(c, "expected_visits_exact", formulas::expected_visits_exact(p, b));
  const double printed = safe([&] { return formulas::expected_visits_eq9_as_printed(p, b); });
  const double eq1013 = sweep == 0 ? safe([&] { return formulas::eq10_traditional(n, p); })
                                   : safe([&] { return formulas::eq13_scale_sensitive(p, b); });
  r.table.add({double(sweep),
               double(n),
               double(l1),
               double(lm),
               p,
               b,
               double(mi.count),
               mi.mean(),
               mi.se(),
               e,
               printed,
               eq1013,
               predict(c, "eq12_limit", formulas::eq12_limit(n)),
               predict(c, "eq12_correct_limit", formulas::eq12_correct_limit(n)),
               mt.mean(),
               mt.se(),
               tests_exact,
               formulas::expected_eq8_cost(n, static_cast<std::uint64_t>(b), p),
               std::log2(p),
               double(l1)});
  const std::string where = "sweep " + str(sweep) + " l1=" + str(l1) + " p=" + fmt(p);
  // Tolerance: 4 standard errors, plus 5/rays of the prediction for outcomes too rare to
  // be seen at all in `rays` draws (then the sample variance is 0).
  const double rare = 5.0 / mi.count;
  // Sweep 0 is Eq. 10 (p/b = n), sweep 1 Eq. 13 (b fixed), sweep 2 Eq. 9 in general.
  const std::string eq = sweep == 0 ? "Eq. 10" : sweep == 1 ? "Eq. 13" : "Eq. 9";
  r.checks.push_back({where + ": mean visits on level l1 = E[i] (4 s.e.)", mi.mean(), e,
                      4 * mi.se() + rare * e, Role::kSupports, eq});
  // The printed closed form (Eq. 9, or its substitution Eq. 10 / 13) where it can be
  // evaluated in floating point: it must be the same number.
  const double closed = sweep == 0 ? eq1013 : sweep == 1 ? eq1013 : printed;
  if (!std::isnan(closed))
    r.checks.push_back({where + ": " + eq + " as printed = E[i] (1e-6 relative)", closed, e,
                        1e-6 * e, Role::kSupports, eq});
  r.checks.push_back({where + ": mean primary tests = exact expectation (4 s.e.)", mt.mean(),
                      tests_exact, 4 * mt.se() + rare * tests_exact, Role::kSupports,
                      "O(log p) / O(log b)"});
}

/// Sweep 0: traditional renderer, l1 = l_max - 1, p = n^l_max (p/b = n); quick: l_max =
/// 2..10 and the deepest, 20. Appends each point's mean shadow tests to `shadow`.
void sweep_traditional(const Config& c, ExperimentResult& r, int rays,
                       std::vector<double>& shadow) {
  const int max_lmax = 20;
  for (int lm = 2; lm <= max_lmax; lm += c.quick && lm >= 10 ? 10 : 1) {
    const double p = std::pow(n, lm);
    const int l1 = lm - 1;
    Mean mi, mt, ms;
    for (int k = 0; k < rays; ++k) {
      const LoadedScene s =
          scene("poisson", {{"n", str(n)}, {"depth", str(lm)}, {"p", str(p)}, {"seed", str(k)}});
      const TraceOutput t = trace_centre(s, traditional());
      const double b = std::pow(n, l1);
      mi.add(t.hit.kind == TraceHit::Kind::kPrimitive ? double(t.hit.id / n + 1) : b);
      mt.add(u(t.counters.tests_of(RayKind::kPrimary)));
      ms.add(u(t.counters.tests_of(RayKind::kShadow)));
    }
    add_row(c, r, 0, l1, lm, p, mi, mt, formulas::expected_tests_traditional(n, lm, p));
    shadow.push_back(ms.mean());
  }
}

/// Sweep 1: scale-sensitive, b = n^4 fixed, p swept.
void sweep_fixed_b(const Config& c, ExperimentResult& r, int rays, std::vector<double>& shadow) {
  const int l1f = 4, depth1 = c.quick ? 16 : 30;
  for (int k2 = -2; k2 <= (c.quick ? 12 : 24); k2 += c.quick ? 2 : 1) {
    const double p = std::ldexp(1.0, k2);
    const LoadedScene s = scene("poisson", {{"n", str(n)}, {"depth", str(depth1)}, {"p", str(p)}});
    Mean mi, mt, ms;
    for (int k = 0; k < rays; ++k) {
      RenderOptions o = at_level(l1f);
      o.seed = static_cast<std::uint64_t>(k);
      const TraceOutput t = trace_centre(s, o);
      const double b = std::pow(n, l1f);
      mi.add(t.hit.kind == TraceHit::Kind::kAmalgam ? double(TubeHierarchy::index_of(t.hit.id) + 1)
                                                    : b);
      mt.add(u(t.counters.tests_of(RayKind::kPrimary)));
      ms.add(u(t.counters.tests_of(RayKind::kShadow)));
    }
    add_row(c, r, 1, l1f, depth1, p, mi, mt, formulas::expected_tests_sorted(n, l1f, p));
    shadow.push_back(ms.mean());
  }
}

/// Sweep 2: scale-sensitive, p = n^depth2 fixed, l1 (so b = n^l1) swept.
void sweep_fixed_p(const Config& c, ExperimentResult& r, int rays, int depth2,
                   std::vector<double>& shadow) {
  const double p2 = std::pow(n, depth2);
  for (int l1 = 1; l1 < depth2 - 1; l1 += c.quick ? 2 : 1) {
    const LoadedScene s = scene("poisson", {{"n", str(n)}, {"depth", str(depth2)}, {"p", str(p2)}});
    Mean mi, mt, ms;
    for (int k = 0; k < rays; ++k) {
      RenderOptions o = at_level(l1);
      o.seed = static_cast<std::uint64_t>(k);
      const TraceOutput t = trace_centre(s, o);
      mi.add(t.hit.kind == TraceHit::Kind::kAmalgam ? double(TubeHierarchy::index_of(t.hit.id) + 1)
                                                    : std::pow(n, l1));
      mt.add(u(t.counters.tests_of(RayKind::kPrimary)));
      ms.add(u(t.counters.tests_of(RayKind::kShadow)));
    }
    add_row(c, r, 2, l1, depth2, p2, mi, mt, formulas::expected_tests_sorted(n, l1, p2));
    shadow.push_back(ms.mean());
  }
}

/// The fits of the findings.
struct Fits {
  LinearFit shadow_trad, shadow_ss, trad_log, ss_b, ss_p;
};

/// Secondary rays and the asymptotic fits: the one shadow ray (the light is at the camera)
/// crosses, back towards the light, what the primary ray passed. The paper: "the expected
/// times for secondary rays should have the same asymptotic behavior".
Fits fit_sweeps(ExperimentResult& r, const std::vector<double>& shadow) {
  Fits f;
  r.table.columns.push_back("mean_shadow");
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) r.table.rows[i].push_back(shadow[i]);
  {
    std::vector<double> x0, y0, x1, y1;
    for (const auto& row : r.table.rows) {
      if (row[0] == 0) x0.push_back(row[18]), y0.push_back(row.back());
      if (row[0] == 1 && row[4] >= 64) x1.push_back(row[18]), y1.push_back(row.back());
    }
    f.shadow_trad = fit_line(x0, y0);
    f.shadow_ss = fit_line(x1, y1);
    r.checks.push_back({"traditional shadow tests linear in log p (r^2)", f.shadow_trad.r2, 1.0,
                        0.01, Role::kSupports, "Secondary rays (expected)"});
    r.checks.push_back({"scale-sensitive shadow tests flat in p for p >> b (slope per doubling)",
                        f.shadow_ss.b, 0.0, 0.25, Role::kSupports, "Secondary rays (expected)"});
  }
  // Fits: traditional tests against log2 p; scale-sensitive against log2 b and against p.
  auto fit_of = [&](int sweep, const std::string& xcol, bool log_y = false) {
    std::vector<double> x, y;
    for (const auto& row : r.table.rows)
      if (row[0] == sweep && (sweep != 1 || row[4] >= 64)) {
        x.push_back(row[r.table.col(xcol)]);
        y.push_back(log_y ? std::log(row[14]) : row[14]);
      }
    return fit_line(x, y);
  };
  f.trad_log = fit_of(0, "log2_p");
  f.ss_b = fit_of(2, "log2_b");
  f.ss_p = fit_of(1, "log2_p");
  r.checks.push_back({"traditional tests linear in log p (r^2)", f.trad_log.r2, 1.0, 0.01});
  r.checks.push_back({"scale-sensitive tests linear in log b (r^2)", f.ss_b.r2, 1.0, 0.01});
  r.checks.push_back({"scale-sensitive tests flat in p for p >> b (slope per doubling of p)",
                      f.ss_p.b, 0.0, 0.25});
  tag(r, "O(log p) / O(log b)");
  return f;
}

/// The summary rows and the three panels.
void add_panels(ExperimentResult& r, int depth2) {
  r.summary_columns = {
      "sweep",        "l1",           "p",          "b",           "mean_i",      "eq9_exact",
      "eq12_printed", "eq12_correct", "mean_tests", "tests_exact", "eq8_expected"};
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    const auto& row = r.table.rows[i];
    const bool last_of_sweep = i + 1 == r.table.rows.size() || r.table.rows[i + 1][0] != row[0];
    if (i == 0 || last_of_sweep || (i > 0 && r.table.rows[i - 1][0] != row[0]) ||
        (row[0] == 0 && int(row[3]) % 4 == 0))
      r.summary_rows.push_back(i);
  }
  r.panels.push_back(
      {"Amalgams visited on level l1 (n=2)",
       "p (expected hits on the ray)",
       "mean number visited, E[i]",
       Scale::kLog,
       Scale::kLog,
       {{"p", "mean_i", "traditional (b = p/n), measured", Draw::kPoints, "sweep", 0},
        {"p", "eq9_exact", "Eq. 9/10", Draw::kLine, "sweep", 0},
        {"p", "eq12_printed", "Eq. 12 as printed (1-e^{-n})", Draw::kLine, "sweep", 0},
        {"p", "eq12_correct", "Eq. 12 corrected 1/(1-e^{-n})", Draw::kLine, "sweep", 0},
        {"p", "mean_i", "scale-sensitive b=16, measured", Draw::kPoints, "sweep", 1},
        {"p", "eq9_exact", "Eq. 9/13, b=16", Draw::kLine, "sweep", 1}}});
  r.panels.push_back(
      {"Tests per primary ray (n=2)",
       "p",
       "mean intersection tests per primary ray",
       Scale::kLog,
       Scale::kLinear,
       {{"p", "mean_tests", "traditional, measured", Draw::kPoints, "sweep", 0},
        {"p", "tests_exact", "traditional, exact expectation", Draw::kLine, "sweep", 0},
        {"p", "eq8_expected", "traditional, Eq. 8 model", Draw::kLine, "sweep", 0},
        {"p", "mean_tests", "scale-sensitive b=16, measured", Draw::kPoints, "sweep", 1},
        {"p", "tests_exact", "scale-sensitive, exact expectation", Draw::kLine, "sweep", 1},
        {"p", "eq8_expected", "scale-sensitive, Eq. 8 model", Draw::kLine, "sweep", 1}}});
  r.panels.push_back({"Scale-sensitive, p = 2^{" + str(depth2) + "} fixed, b = n^{l1} varied",
                      "log_2 b = l1",
                      "mean tests per primary ray",
                      Scale::kLinear,
                      Scale::kLinear,
                      {{"log2_b", "mean_tests", "measured", Draw::kPoints, "sweep", 2},
                       {"log2_b", "tests_exact", "exact expectation", Draw::kLine, "sweep", 2},
                       {"log2_b", "eq8_expected", "Eq. 8 model", Draw::kLine, "sweep", 2}}});
}

/// The findings, which follow the checks (a wrong formula injected through Config::perturb
/// must change them as it changes the verdict).
std::string findings(const ExperimentResult& r, int rays, const Fits& f,
                     const std::vector<double>& lt, double z_printed, double z_correct) {
  const auto held = [&](const char* id) { return verdict_of(r.checks, id) == Verdict::kHolds; };
  const bool eq9_holds = held("Eq. 9") && held("Eq. 10") && held("Eq. 13");
  const auto v12 = verdict_of(r.checks, "Eq. 12");
  const std::string eq12_head =
      v12 == Verdict::kHoldsWithCorrection ? "* **Eq. 12 is wrong as printed**: "
      : v12 == Verdict::kHolds ? "* **Eq. 12 as printed was not refuted** (see the checks): "
                               : "* **Eq. 12: the measurement matches neither the printed nor "
                                 "the corrected limit** (see the checks): ";
  return "Measured over " + str(rays) +
         " rays per point (traditional: a new Poisson realisation per ray; scale-sensitive: a new "
         "stochastic-opacity seed per ray). The Poisson model makes each amalgam pass the ray "
         "with probability e^{-p/b} independently of all others: uncorrelated, exponential "
         "transmittance along the ray, as in a homogeneous medium. builtin:poisson is built to "
         "follow it; real scenes are correlated (a wall stops every ray that reaches it, an empty "
         "region passes them all), so there Eq. 9 is a model, not a prediction.\n\n" +
         std::string(eq9_holds ? "* **Eq. 9, 10, 13 hold** "
                               : "* **Eq. 9, 10, 13 do not all hold (see the failed checks)** ") +
         "(they are algebraically the truncated-geometric mean "
         "(1 - e^{-p})/(1 - e^{-p/b})); every measured mean of visits on level l1 is within 4 "
         "standard errors of it. The printed closed forms overflow/cancel numerically for large "
         "p/b (nan in the CSV) but are exact where they can be evaluated.\n" +
         eq12_head +
         "its left-hand side e^{-n}(e^n - 1)(e^{-n} - 1)^{-2} equals "
         "1/(1 - e^{-n}), but the paper prints (1 - e^{-n}), the reciprocal. At the largest p "
         "(p = " +
         fmt(lt[4]) + ") the measured mean is " + fmt(lt[7]) + " +- " + fmt(lt[8]) +
         "; the corrected limit 1/(1 - e^{-2}) = " + fmt(lt[13]) + " (z = " + fmt(z_correct) +
         "), the printed 1 - e^{-2} = " + fmt(lt[12]) + " (z = " + fmt(z_printed) +
         "). A mean number of visited amalgams below 1 is impossible. The conclusion O(1) "
         "stands.\n"
         "* **O(log p) vs O(log b)**: traditional tests per primary ray fit a + c log2 p with "
         "c = " +
         fmt(f.trad_log.b) + ", r^2 = " + fmt(f.trad_log.r2) +
         " (O(log p)); scale-sensitive with b fixed is flat in p (slope " + fmt(f.ss_p.b) +
         " tests per doubling of p for p >= 64) and, with p fixed, linear in log2 b (slope " +
         fmt(f.ss_b.b) + ", r^2 = " + fmt(f.ss_b.r2) +
         "). Measured tests match the exact expectation of this sorted traversal "
         "(`expected_tests_sorted`) within statistical error. Eq. 8's max(log_n b + i, i C_b) "
         "model is below these intersection tests by about a factor n because this traversal "
         "tests all n children of each entered node while the paper counts objects traversed "
         "(children reached in sorted order until the first hit): a counting convention, a "
         "constant factor that leaves the asymptotics unchanged. Counted the paper's way, Eq. 8 "
         "is checked in [traversed](#traversed).\n"
         "* **Secondary rays**: the shadow ray (light at the camera, so it crosses back over what "
         "the primary ray passed) costs on average a + c log2 p with c = " +
         fmt(f.shadow_trad.b) + " (r^2 = " + fmt(f.shadow_trad.r2) +
         ") for the traditional renderer and is flat in p for the scale-sensitive one (slope " +
         fmt(f.shadow_ss.b) +
         " tests per doubling of p): the same asymptotics as the primary ray, as the paper says. "
         "At the deepest point (l_max = " +
         fmt(lt[3]) + ", p = " + fmt(lt[4]) + ") the traditional shadow ray makes " +
         fmt(lt.back()) + " tests per primary ray on average and the primary ray " + fmt(lt[14]) +
         (lt.back() == lt[14] ? std::string(": the same cells crossed back to the light.")
                              : std::string(": not the same (see the failed check)."));
}

}  // namespace
}  // namespace expected_parts

ExperimentResult expected(const Config& c) {
  using namespace expected_parts;
  ExperimentResult r;
  describe(r);
  const int rays = c.quick ? 1500 : 40000;
  const int depth2 = c.quick ? 12 : 18;
  std::vector<double> shadow;  // mean shadow-ray tests per primary ray, one per row
  sweep_traditional(c, r, rays, shadow);
  sweep_fixed_b(c, r, rays, shadow);
  sweep_fixed_p(c, r, rays, depth2, shadow);
  const Fits f = fit_sweeps(r, shadow);
  // Eq. 12: at the largest p, the measured mean vs the printed and the corrected limit.
  std::size_t last_trad = 0;
  for (std::size_t i = 0; i < r.table.rows.size(); ++i)
    if (r.table.rows[i][0] == 0) last_trad = i;
  const auto& lt = r.table.rows[last_trad];
  const double z_printed = (lt[7] - lt[12]) / lt[8];
  const double z_correct = (lt[7] - lt[13]) / lt[8];
  r.checks.push_back({"traditional E[i] at largest p = corrected Eq. 12 limit 1/(1-e^-n)", lt[7],
                      lt[13], 4 * lt[8], Role::kSupports, "Eq. 12"});
  r.checks.push_back({"printed Eq. 12 (1-e^-n) is below the measurement by > 10 s.e.",
                      std::min(z_printed, 10.0), 10.0, 0.0, Role::kRefutesPrinted, "Eq. 12"});
  // At the largest p every ray hits, and its shadow ray (light at the camera) crosses back
  // over exactly the cells the primary ray entered: the same tests, ray by ray.
  r.checks.push_back({"traditional shadow tests = primary tests at l_max = " + fmt(lt[3]) +
                          " (mean over rays, exact)",
                      lt.back(), lt[14], 0.0, Role::kSupports, "Secondary rays (expected)"});

  add_panels(r, depth2);
  r.findings = findings(r, rays, f, lt, z_printed, z_correct);
  return r;
}

}  // namespace amalgam::experiments

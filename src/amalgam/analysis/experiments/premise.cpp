/// \file Experiment premise: the paper measures cost in intersection tests ("the costs of
/// performing ray/object intersection tests overwhelms the costs of other operations"). How far
/// does wall time follow the test counts of this renderer? Renders of the builtin scenes and of
/// two baked scenes (Wuson mesh, the field; loaded through Config::load), traditional and
/// scale-sensitive; time fitted against the total tests alone and against the tests by kind.
/// Also the conclusions' "in any case, the scale-sensitive technique is no slower".

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <thread>

#include "amalgam/analysis/experiments/common.h"

namespace amalgam::experiments {
using namespace detail;

namespace {

/// Least squares through the origin, y ~ X c, by the normal equations (Gaussian elimination
/// with partial pivoting on columns scaled to a maximum of 1). A column that is all zero
/// gets coefficient 0.
std::vector<double> least_squares(const std::vector<std::vector<double>>& X,
                                  const std::vector<double>& y) {
  const std::size_t k = X.empty() ? 0 : X[0].size();
  std::vector<double> scale(k, 0);
  for (const auto& row : X)
    for (std::size_t j = 0; j < k; ++j) scale[j] = std::max(scale[j], std::fabs(row[j]));
  std::vector<std::vector<double>> A(k, std::vector<double>(k + 1, 0));
  for (std::size_t i = 0; i < X.size(); ++i)
    for (std::size_t a = 0; a < k; ++a) {
      if (scale[a] == 0) continue;
      for (std::size_t b = 0; b < k; ++b)
        if (scale[b] > 0) A[a][b] += X[i][a] / scale[a] * X[i][b] / scale[b];
      A[a][k] += X[i][a] / scale[a] * y[i];
    }
  for (std::size_t a = 0; a < k; ++a)
    if (scale[a] == 0) A[a][a] = 1;  // coefficient 0
  for (std::size_t col = 0; col < k; ++col) {
    std::size_t piv = col;
    for (std::size_t rr = col + 1; rr < k; ++rr)
      if (std::fabs(A[rr][col]) > std::fabs(A[piv][col])) piv = rr;
    std::swap(A[col], A[piv]);
    if (std::fabs(A[col][col]) < 1e-300) continue;
    for (std::size_t rr = 0; rr < k; ++rr) {
      if (rr == col) continue;
      const double f = A[rr][col] / A[col][col];
      for (std::size_t cc = col; cc <= k; ++cc) A[rr][cc] -= f * A[col][cc];
    }
  }
  std::vector<double> c(k, 0);
  for (std::size_t a = 0; a < k; ++a)
    if (scale[a] > 0 && std::fabs(A[a][a]) > 1e-300) c[a] = A[a][k] / A[a][a] / scale[a];
  return c;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// The distribution-free interval of the median of `v` (TimeRatio): [x(k), x(n+1-k)] with
/// coverage 1 - 2 P(Bin(n, 1/2) <= k - 1), k as large as keeps it at least 95%, else k = 1.
struct MedianInterval {
  double lo, hi, coverage;
};
MedianInterval median_interval(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  // P(Bin(n, 1/2) <= j) for j = 0, 1, ...: the chance that fewer than j + 1 runs fall below
  // the median.
  double term = std::ldexp(1.0, -int(n)), tail = term;  // j = 0
  std::size_t k = 1;
  double coverage = 1 - 2 * tail;
  for (std::size_t j = 1; 2 * j < n; ++j) {
    term *= double(n - j + 1) / double(j);
    if (1 - 2 * (tail + term) < 0.95) break;
    tail += term, k = j + 1, coverage = 1 - 2 * tail;
  }
  return {v[k - 1], v[n - k], coverage};
}

}  // namespace

TimeRatio time_ratio(const std::vector<double>& seconds, const std::vector<double>& reference) {
  if (seconds.empty() || reference.empty())
    throw std::invalid_argument("time_ratio: no runs to compare");
  const MedianInterval s = median_interval(seconds), ref = median_interval(reference);
  TimeRatio t;
  t.median = median(seconds) / median(reference);
  t.lo = s.lo / ref.hi;
  t.hi = s.hi / ref.lo;
  t.coverage = std::min(s.coverage, ref.coverage);
  t.order = t.lo > 1 ? 1 : t.hi < 1 ? -1 : 0;
  return t;
}

std::vector<Check> no_slower_checks(const std::string& label, double tests_ratio,
                                    const TimeRatio& time) {
  const std::string judged = time.order > 0 ? "slower" : time.order < 0 ? "faster" : "a tie";
  return {{label + ": scale-sensitive makes no more tests than traditional",
           std::max(tests_ratio, 1.0), 1.0, 0, Role::kSupports, "No slower"},
          {label + ": scale-sensitive no slower in wall time than traditional (time ratio " +
               fmt(time.median) + ", interval [" + fmt(time.lo) + ", " + fmt(time.hi) +
               "]: " + judged + ")",
           time.order > 0 ? time.lo : 1.0, 1.0, 0, Role::kSupports, "No slower"}};
}

// Named: a unity build compiles several experiments in one translation unit.
namespace premise_parts {
namespace {

/// A scene and its scale-sensitive configurations.
struct Spec {
  std::string label, spec;
  bool file;
  std::vector<int> levels;  ///< scale-sensitive levels (-1: footprint 1 pixel)
};
const std::vector<Spec>& specs() {
  static const std::vector<Spec> s = {
      {"builtin:prisms corner", "corner", false, {3, 5, -1}},
      {"builtin:prisms front", "front", false, {2, 4, -1}},
      {"Wuson mesh", "/usr/share/assimp/models/PLY/Wuson.ply", true, {3, 6, -1}},
      {"the field", "scenes/field.json", true, {4, 8, -1}}};
  return s;
}

/// Title, claim, prediction and columns.
void describe(ExperimentResult& r) {
  r.title =
      "The premise: cost = intersection tests; \"the scale-sensitive technique is no slower\"";
  r.claim =
      "\"The costs of performing ray/object intersection tests overwhelms the costs of other "
      "operations ... the analysis below will measure time costs in the number of "
      "intersection tests.\" Conclusions: \"In any case, the scale-sensitive technique is no "
      "slower.\"";
  r.prediction =
      "Wall time of whole renders fitted (least squares through 0) against the total tests "
      "alone, and against the tests by kind: node tests of the explicit (baked, SIMD-tested) "
      "hierarchies, node tests of the implicit builtin scenes (one at a time), primitive "
      "tests, primary rays (shading) and shadow rays. The scale-sensitive renderer makes no "
      "more tests than the traditional one on the same scene.";
  r.table.columns = {"scene",         "config",        "level",        "seconds",
                     "node_simd",     "node_scalar",   "prim_tests",   "primary_rays",
                     "shadow_rays",   "tests",         "fit_tests",    "fit_kinds",
                     "err_tests_pct", "err_kinds_pct", "time_vs_trad", "tests_vs_trad",
                     "seconds_min",   "seconds_max",   "time_lo",      "time_hi",
                     "time_order"};
}

/// The renders of one scene: traditional, then each configuration of `sp`; each timed
/// `reps` times after an untimed warm-up, the runs interleaved (forward, then backward
/// through the configurations) so that a change of the machine's load falls on all of them
/// alike. Adds a row and the "no slower" checks per render; returns the coverage of the
/// time ratios' intervals.
double measure_scene(const Config& c, ExperimentResult& r, std::size_t si, const Spec& sp,
                     const LoadedScene& scene_, int size, int reps) {
  double coverage = 0;
  std::vector<int> configs = {-2};  // -2: traditional
  for (int l : sp.levels) configs.push_back(l);
  std::vector<RenderOptions> opts;
  for (int cfg : configs) {
    RenderOptions o = cfg == -2 ? traditional() : cfg == -1 ? RenderOptions{} : at_level(cfg);
    if (cfg == -1) o.lod = ByFootprint{1.0f};
    o.width = o.height = size;
    o.spp = 1;
    o.threads = c.threads;
    opts.push_back(o);
  }
  std::vector<RenderOutput> out(configs.size());
  std::vector<std::vector<double>> seconds(configs.size());
  for (std::size_t j = 0; j < configs.size(); ++j) out[j] = render(scene_, opts[j]);  // warm-up
  for (int k = 0; k < reps; ++k)
    for (std::size_t jj = 0; jj < configs.size(); ++jj) {
      const std::size_t j = k % 2 ? configs.size() - 1 - jj : jj;
      out[j] = render(scene_, opts[j]);
      seconds[j].push_back(out[j].seconds);
    }
  const double trad_tests = u(out[0].counters.total());
  for (std::size_t j = 0; j < configs.size(); ++j) {
    const int cfg = configs[j];
    const Counters& k = out[j].counters;
    const double nodes =
        u(k.tests_of(ObjectKind::kBoundingVolume) + k.tests_of(ObjectKind::kAmalgam));
    const double tests = u(k.total());
    const TimeRatio t = time_ratio(seconds[j], seconds[0]);
    coverage = t.coverage;
    const auto [lo, hi] = std::minmax_element(seconds[j].begin(), seconds[j].end());
    r.table.add({double(si),
                 double(cfg == -2   ? 0
                        : cfg == -1 ? 2
                                    : 1),
                 double(cfg),
                 median(seconds[j]),
                 sp.file ? nodes : 0,
                 sp.file ? 0 : nodes,
                 u(k.tests_of(ObjectKind::kPrimitive)),
                 u(k.rays[0]),
                 u(k.rays[1]),
                 tests,
                 0,
                 0,
                 0,
                 0,
                 t.median,
                 tests / trad_tests,
                 *lo,
                 *hi,
                 t.lo,
                 t.hi,
                 double(t.order)});
    if (cfg != -2)
      for (Check& ch :
           no_slower_checks(sp.label + (cfg == -1 ? ", footprint 1" : ", level " + str(cfg)),
                            tests / trad_tests, t))
        r.checks.push_back(std::move(ch));
  }
  return coverage;
}

/// The fits of time against tests, alone and by kind, for the findings.
struct Fits {
  std::vector<double> c1, c5;
  std::string kinds_text, dropped_text, worst_label;
  double r2_1 = 1, r2_5 = 1, worst1 = 0, worst5 = 0;
};

/// Time fitted against the total tests and against the tests by kind (non-negative least
/// squares through 0); fills each row's fitted times and errors.
Fits fit_renders(ExperimentResult& r) {
  Fits f;
  std::vector<std::vector<double>> X1, X5;
  std::vector<double> y;
  for (const auto& row : r.table.rows) {
    X1.push_back({row[9]});
    X5.push_back({row[4], row[5], row[6], row[7], row[8]});
    y.push_back(row[3]);
  }
  const std::vector<double> c1 = least_squares(X1, y);
  // By kind: a cost per kind cannot be negative; a kind whose fitted coefficient comes out
  // negative (not separable from the others on these renders) is dropped and the fit redone.
  std::vector<double> c5;
  std::vector<bool> dropped(5, false);
  for (int round = 0; round < 5; ++round) {
    std::vector<std::vector<double>> Xk = X5;
    for (auto& row : Xk)
      for (std::size_t j = 0; j < 5; ++j)
        if (dropped[j]) row[j] = 0;
    c5 = least_squares(Xk, y);
    std::size_t worst = 5;
    for (std::size_t j = 0; j < 5; ++j)
      if (c5[j] < 0 && (worst == 5 || c5[j] < c5[worst])) worst = j;
    if (worst == 5) break;
    dropped[worst] = true;
  }
  const char* kind_names[5] = {"explicit node test", "builtin node test", "primitive test",
                               "primary ray", "shadow ray"};
  std::string kinds_text, dropped_text;
  for (std::size_t j = 0; j < 5; ++j) {
    if (dropped[j]) {
      dropped_text += std::string(dropped_text.empty() ? "" : ", ") + kind_names[j];
      continue;
    }
    kinds_text +=
        std::string(kinds_text.empty() ? "" : ", ") + kind_names[j] + " " + fmt(c5[j] * 1e9);
  }
  double ss_tot = 0, ss1 = 0, ss5 = 0, ymean = 0, worst1 = 0, worst5 = 0;
  for (double v : y) ymean += v / double(y.size());
  std::string worst_label;
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) {
    auto& row = r.table.rows[i];
    row[10] = c1[0] * row[9];
    row[11] = c5[0] * row[4] + c5[1] * row[5] + c5[2] * row[6] + c5[3] * row[7] + c5[4] * row[8];
    row[12] = 100 * (row[10] / row[3] - 1);
    row[13] = 100 * (row[11] / row[3] - 1);
    ss_tot += (row[3] - ymean) * (row[3] - ymean);
    ss1 += (row[3] - row[10]) * (row[3] - row[10]);
    ss5 += (row[3] - row[11]) * (row[3] - row[11]);
    if (std::fabs(row[12]) > worst1) {
      worst1 = std::fabs(row[12]);
      worst_label = specs()[std::size_t(row[0])].label + " " +
                    (row[1] == 0   ? std::string("traditional")
                     : row[1] == 2 ? std::string("footprint 1")
                                   : "level " + fmt(row[2]));
    }
    worst5 = std::max(worst5, std::fabs(row[13]));
  }
  const double r2_1 = ss_tot > 0 ? 1 - ss1 / ss_tot : 1, r2_5 = ss_tot > 0 ? 1 - ss5 / ss_tot : 1;
  f.c1 = c1, f.c5 = c5, f.kinds_text = kinds_text, f.dropped_text = dropped_text;
  f.worst_label = worst_label, f.r2_1 = r2_1, f.r2_5 = r2_5, f.worst1 = worst1, f.worst5 = worst5;
  return f;
}

/// "No slower" in each currency, for the findings.
struct NoSlower {
  const std::vector<double>* slowest = nullptr;
  double most_tests = 0;
  int n_ss = 0, n_faster = 0, n_ties = 0, n_slower = 0;
  std::string slower_list, tie_list;
  double slower = 0, slowest_tests = 0;
  std::string slower_label;
};

std::string label_of(const std::vector<double>& row) {
  return specs()[std::size_t(row[0])].label + (row[1] == 0   ? std::string(" traditional")
                                               : row[1] == 2 ? std::string(", footprint 1")
                                                             : ", level " + fmt(row[2]));
}

NoSlower no_slower(const ExperimentResult& r) {
  NoSlower v;
  // "No slower" in each currency: tests (never more than traditional) and wall time (slower
  // only where the whole range of the time ratio lies above 1; a tie otherwise).
  const std::vector<double>* slowest = nullptr;
  double most_tests = 0;
  int n_ss = 0, n_faster = 0, n_ties = 0, n_slower = 0;
  std::string slower_list, tie_list;
  for (const auto& row : r.table.rows) {
    if (row[1] == 0) continue;  // traditional
    ++n_ss;
    if (!slowest || row[14] > (*slowest)[14]) slowest = &row;
    most_tests = std::max(most_tests, row[15]);
    const std::string item = label_of(row) + " " + fmt(row[14]) + " [" + fmt(row[18]) + ", " +
                             fmt(row[19]) + "] with " + fmt(row[15]) + " times the tests";
    if (row[20] > 0) ++n_slower, slower_list += (slower_list.empty() ? "" : "; ") + item;
    if (row[20] == 0) ++n_ties, tie_list += (tie_list.empty() ? "" : "; ") + item;
    if (row[20] < 0) ++n_faster;
  }
  const double slower = slowest ? (*slowest)[14] : 0.0;
  const double slowest_tests = slowest ? (*slowest)[15] : 0.0;
  const std::string slower_label = slowest ? label_of(*slowest) : std::string("none");
  v.slowest = slowest, v.most_tests = most_tests, v.n_ss = n_ss, v.n_faster = n_faster;
  v.n_ties = n_ties, v.n_slower = n_slower, v.slower_list = slower_list, v.tie_list = tie_list;
  v.slower = slower, v.slowest_tests = slowest_tests, v.slower_label = slower_label;
  return v;
}

void add_panels(ExperimentResult& r, int size, int reps) {
  r.summary_columns = {"scene",         "config",        "level",        "seconds",
                       "tests",         "fit_tests",     "fit_kinds",    "err_tests_pct",
                       "err_kinds_pct", "tests_vs_trad", "time_vs_trad", "time_lo",
                       "time_hi"};
  for (std::size_t i = 0; i < r.table.rows.size(); ++i) r.summary_rows.push_back(i);
  r.panels.push_back(
      {"Render time against intersection tests",
       "intersection tests (all rays)",
       "seconds (" + str(size) + "^2 px, 1 spp, median of " + str(reps) + ")",
       Scale::kLog,
       Scale::kLog,
       {{"tests", "seconds", "traditional", Draw::kPoints, "config", 0},
        {"tests", "seconds", "scale-sensitive, fixed level", Draw::kPoints, "config", 1},
        {"tests", "seconds", "scale-sensitive, footprint 1", Draw::kPoints, "config", 2},
        {"tests", "fit_tests", "fit: c x tests", Draw::kPoints, "config", 0}}});
  r.panels.push_back(
      {"Scale-sensitive against traditional, same scene",
       "tests relative to traditional",
       "time relative to traditional",
       Scale::kLog,
       Scale::kLog,
       {{"tests_vs_trad", "time_vs_trad", "fixed level", Draw::kPoints, "config", 1},
        {"tests_vs_trad", "time_vs_trad", "footprint 1", Draw::kPoints, "config", 2}}});
}

std::string findings(const Config& c, const ExperimentResult& r, int size, int reps,
                     const std::string& unavailable, double coverage, const Fits& f,
                     const NoSlower& v) {
  const Verdict v_no_slower = verdict_of(r.checks, "No slower").value_or(Verdict::kNotMeasured);
  const bool tests_hold = v.most_tests <= 1;
  return "Renders of " + str(size) + "^2 pixels, 1 spp, " + str(c.threads) +
         " threads (0: all cores); each render timed " + str(reps) +
         " times after an untimed warm-up, the runs of a scene's renders interleaved; seconds: "
         "the median (config 0 traditional, 1 fixed level, 2 footprint 1 pixel).\n\n" +
         unavailable + "* **Tests alone**: time = " + fmt(f.c1[0] * 1e9) +
         " ns x tests, R^2 = " + fmt(f.r2_1) + "; worst render " + fmt(f.worst1) + "% off (" +
         f.worst_label +
         ").\n"
         "* **Tests by kind** (ns each, non-negative least squares): " +
         f.kinds_text +
         (f.dropped_text.empty() ? std::string()
                                 : "; not separable from the others on these renders (fitted "
                                   "negative, dropped): " +
                                       f.dropped_text) +
         "; R^2 = " + fmt(f.r2_5) + ", worst render " + fmt(f.worst5) + "% off.\n" +
         "* **No slower: " + to_string(v_no_slower) +
         "**. In test counts the scale-sensitive "
         "renderer made at most " +
         fmt(v.most_tests) + " times the traditional renderer's tests on the same scene (" +
         (tests_hold ? std::string("never more: holds in test counts")
                     : std::string("more somewhere: does not hold in test counts")) +
         "). In wall time (time_vs_trad: the ratio of the medians; [time_lo, time_hi]: its "
         "interval, from a distribution-free confidence interval of each median, the order "
         "statistics of its runs that cover it with probability " +
         fmt(100 * coverage) +
         "%; slower only when the whole interval lies above 1, a tie when it holds 1) " +
         str(v.n_faster) + " of the " + str(v.n_ss) + " scale-sensitive renders were faster, " +
         str(v.n_ties) + " tied and " + str(v.n_slower) + " slower" +
         (v.n_slower ? " (" + v.slower_list + ")" : std::string()) +
         (v.n_ties ? "; the ties: " + v.tie_list : std::string()) + ": " +
         (v.n_slower ? std::string("does not hold in wall time")
                     : std::string("holds in wall time")) +
         ". The largest ratio of medians: it took at most " + fmt(v.slower) + " times as long (" +
         v.slower_label + ", which made " + fmt(v.slowest_tests) +
         " times the traditional renderer's tests" +
         (v.slower > 1 && v.slowest_tests < 1    ? ": slower in time although it made fewer tests"
          : v.slower > 1 && v.slowest_tests == 1 ? ": slower in time with the same number of tests"
                                                 : "") +
         "). Wall time is measured on this machine (" +
         str(int(std::thread::hardware_concurrency())) +
         " hardware threads, not reserved for this run): the verdict in time is this machine's, "
         "at the time of the run.\n\n"
         "Counting tests predicts render time to the extent these R^2 say; one price per test "
         "is off by up to " +
         fmt(f.worst1) + "% for a single render (" + f.worst_label +
         "): explicit node tests (SIMD, several boxes at once), builtin node tests (one box, "
         "children computed on the fly), primitive tests and the per-ray work (camera ray, "
         "shading, shadow-ray set-up) do not cost the same.";
}

}  // namespace
}  // namespace premise_parts

ExperimentResult premise(const Config& c) {
  using namespace premise_parts;
  ExperimentResult r;
  describe(r);
  const int size = c.quick ? 24 : 256;
  const int reps = c.quick ? 3 : 9;  // timed runs per render
  std::string unavailable;
  double coverage = 0;  // of each median's interval (TimeRatio)
  for (std::size_t si = 0; si < specs().size(); ++si) {
    const Spec& sp = specs()[si];
    std::optional<LoadedScene> s;
    try {
      if (!sp.file)
        s.emplace(scene("prisms", {{"depth", "8"}, {"view", sp.spec}}));
      else if (c.load)
        s.emplace(c.load(sp.spec));
      else
        throw std::runtime_error("no scene loader given (Config::load)");
    } catch (const std::exception& e) {
      unavailable += "* " + sp.label + ": not measured: " + e.what() + "\n";
      r.not_measured.push_back(sp.label + ": " + e.what());
      continue;
    }
    coverage = measure_scene(c, r, si, sp, *s, size, reps);
  }
  const Fits f = fit_renders(r);
  const NoSlower v = no_slower(r);
  add_panels(r, size, reps);
  tag(r, "Premise");
  r.findings = findings(c, r, size, reps, unavailable, coverage, f, v);
  return r;
}

}  // namespace amalgam::experiments

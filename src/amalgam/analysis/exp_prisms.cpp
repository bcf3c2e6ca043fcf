/// \file Experiments on builtin:prisms (the paper's Figure 2): failed-tests, noise and
/// more-levels.

#include <algorithm>
#include <cmath>

#include "amalgam/analysis/exp_common.h"
#include "amalgam/analysis/formulas.h"

namespace amalgam::experiments {
using namespace detail;

ExperimentResult failed_tests(const Config& c) {
  ExperimentResult r;
  r.title = "\"A Second Look\": failed intersection tests";
  r.claim =
      "With object-grouping hierarchies the renderer tests all children of a traversed "
      "amalgam, n that the ray meets plus m 'failed' ones; this scales the cost by about "
      "(1 + m/n) and leaves the asymptotics O(n^{l1}) unchanged.";
  r.prediction =
      "`formulas::failed_tests_worst(n, m, l1)` = 1 + (1 + m/n) sum_{i=1}^{l1} n^i (the "
      "printed summand n^{l1} + m n^{l1-1} is a typo for n^i + m n^{i-1}; "
      "`failed_tests_worst_as_printed` shows the difference); without failed tests C_s0 (Eq. 1).";
  r.table.columns = {"split",
                     "n",
                     "m",
                     "l1",
                     "primary",
                     "pred_corrected",
                     "pred_as_printed",
                     "line_cs0",
                     "ratio",
                     "one_plus_m_over_n",
                     "growth"};
  struct Sweep {
    int split, max_l1;
  };
  const std::vector<Sweep> sweeps = c.quick ? std::vector<Sweep>{{2, 6}, {3, 4}, {4, 3}}
                                            : std::vector<Sweep>{{2, 12}, {3, 7}, {4, 5}};
  for (const Sweep& s : sweeps) {
    const int n = s.split, m = s.split * s.split * s.split - s.split;
    double prev = 0;
    for (int l1 = 1; l1 <= s.max_l1; ++l1) {
      // Deterministic opacity (fill^2 = 0.64 < 1): the primary ray passes every rendered
      // amalgam, so it traverses all n^l1 of them -- the worst case of the paper's sum.
      const LoadedScene sc = scene("prisms", {{"split", str(s.split)}, {"depth", str(l1 + 1)}});
      const TraceOutput t = trace_centre(sc, at_level(l1, OpacityKind::kDeterministic));
      const double prim = u(t.counters.tests_of(RayKind::kPrimary));
      const LoadedScene ln = scene("line", {{"n", str(n)}, {"depth", str(l1 + 1)}});
      const double cs0 = u(trace_centre(ln, at_level(l1)).counters.tests_of(RayKind::kPrimary));
      r.table.add({double(s.split), double(n), double(m), double(l1), prim,
                   formulas::failed_tests_worst(n, m, l1),
                   formulas::failed_tests_worst_as_printed(n, m, l1), cs0, prim / cs0,
                   1.0 + double(m) / n, prev > 0 ? prim / prev : 0.0});
      prev = prim;
      r.checks.push_back(
          {"split=" + str(s.split) + " l1=" + str(l1) + " primary = corrected Second-Look sum",
           prim, formulas::failed_tests_worst(n, m, l1), 0});
    }
    const auto& last = r.table.rows.back();
    r.checks.push_back({"split=" + str(s.split) + " cost ratio -> 1 + m/n (within 5%)", last[8],
                        last[9], 0.05 * last[9]});
    r.checks.push_back({"split=" + str(s.split) + " growth per level -> n (within 5%)", last[10],
                        double(n), 0.05 * n});
  }
  r.summary_columns = r.table.columns;
  for (std::size_t i = 0; i < r.table.rows.size(); ++i)
    if (int(r.table.rows[i][3]) % 2 == 1 || i + 1 == r.table.rows.size() ||
        r.table.rows[i + 1][0] != r.table.rows[i][0])
      r.summary_rows.push_back(i);
  Panel p{"Primary-ray tests with failed tests (builtin:prisms, front view)",
          "l1",
          "intersection tests, primary ray",
          false,
          true,
          {}};
  for (const Sweep& s : sweeps) {
    const double sp = s.split;
    p.series.push_back({"l1", "primary", "measured, split=" + str(sp), false, "split", sp});
    p.series.push_back(
        {"l1", "pred_corrected", "corrected sum, split=" + str(sp), true, "split", sp});
    p.series.push_back(
        {"l1", "line_cs0", "C_s0 (no failed tests), n=" + str(sp), true, "split", sp});
  }
  p.series.push_back({"l1", "pred_as_printed", "sum as printed (typo), split=2", true, "split", 2});
  r.panels.push_back(p);
  r.verdict = Verdict::kHoldsWithCorrection;
  std::string ratios;
  for (std::size_t i = 0; i < r.table.rows.size(); ++i)
    if (i + 1 == r.table.rows.size() || r.table.rows[i + 1][0] != r.table.rows[i][0])
      ratios += "split " + fmt(r.table.rows[i][0]) + " (n=" + fmt(r.table.rows[i][1]) +
                ", m=" + fmt(r.table.rows[i][2]) + "): " + fmt(r.table.rows[i][8]) + " vs " +
                fmt(r.table.rows[i][9]) + "; ";
  r.findings =
      "The face-orthogonal centre ray tests exactly 1 + sum_{i=1}^{l1} (n^i + m n^{i-1}) "
      "objects for every split and l1 measured: the corrected sum. The sum as printed "
      "(summand n^{l1} + m n^{l1-1}, independent of i) overcounts by a factor ~l1/(1 - 1/n) "
      "and would be O(l1 n^{l1}); it is a typo. Measured cost relative to C_s0 (the count "
      "without failed tests, measured on builtin:line): " +
      ratios +
      "the factor tends to 1 + m/n and the growth per level stays n, so the asymptotics are "
      "unchanged, as the paper says.";
  return r;
}

namespace {

double luma(const Vec3& v) {
  return 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
}

struct NoisePoint {
  double variance = 0;  ///< mean over pixels of the variance across seeds
  double tests_per_sample = 0;
};

NoisePoint measure_noise(const LoadedScene& s, RenderOptions o, int seeds) {
  std::vector<double> sum, sum2;
  double tests = 0;
  for (int k = 0; k < seeds; ++k) {
    o.seed = 1000 + static_cast<std::uint64_t>(k);
    const RenderOutput out = render(s, o);
    if (sum.empty()) sum.assign(out.image.size(), 0), sum2.assign(out.image.size(), 0);
    for (std::size_t i = 0; i < out.image.size(); ++i) {
      const double l = luma(out.image[i]);
      sum[i] += l;
      sum2[i] += l * l;
    }
    tests += u(out.counters.total());
  }
  NoisePoint p;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double m = sum[i] / seeds;
    p.variance += std::max(0.0, (sum2[i] / seeds - m * m)) * seeds / (seeds - 1);
  }
  p.variance /= static_cast<double>(sum.size());
  p.tests_per_sample = tests / (double(seeds) * o.width * o.height * o.spp);
  return p;
}

}  // namespace

ExperimentResult noise(const Config& c) {
  ExperimentResult r;
  r.title = "Noise from stochastic opacity";
  r.claim =
      "Stochastic opacity adds noise, so the scale-sensitive renderer must sample more; but "
      "an amalgam has the same shading wherever a ray meets it, while a traditional bounding "
      "volume shows widely varying contents, so the amalgam has lower variance in the image "
      "and needs less sampling: the scale-sensitive renderer should still be cheaper.";
  r.prediction =
      "Qualitative: per-pixel variance (stochastic amalgams) < per-pixel variance "
      "(traditional) at equal spp; variance of a pixel mean falls as 1/spp for both.";
  r.table.columns = {"config",
                     "level",
                     "spp",
                     "seeds",
                     "pixel_variance",
                     "tests_per_sample",
                     "sigma2_per_sample",
                     "samples_to_target",
                     "tests_to_target"};
  const int depth = c.quick ? 6 : 8;
  const int size = c.quick ? 24 : 96;
  const int seeds = c.quick ? 5 : 16;
  const std::vector<int> spps = c.quick ? std::vector<int>{1, 4} : std::vector<int>{1, 4, 16};
  std::vector<int> levels;
  for (int l = 2; l < depth; ++l) levels.push_back(l);
  const LoadedScene s = scene("prisms", {{"depth", str(depth)}, {"view", "front"}});
  // config 0: traditional; config l >= 1: scale-sensitive stochastic at level l.
  std::vector<int> configs = {0};
  for (int l : levels) configs.push_back(l);
  std::vector<double> sigma2(configs.size(), 0), tps(configs.size(), 0);
  std::vector<std::size_t> first_row(configs.size());
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    first_row[ci] = r.table.rows.size();
    for (int spp : spps) {
      RenderOptions o = configs[ci] == 0 ? traditional() : at_level(configs[ci]);
      o.width = o.height = size;
      o.spp = spp;
      o.threads = c.threads;
      const NoisePoint np = measure_noise(s, o, seeds);
      r.table.add({double(ci), double(configs[ci]), double(spp), double(seeds), np.variance,
                   np.tests_per_sample, np.variance * spp, 0, 0});
      sigma2[ci] += np.variance * spp / spps.size();
      tps[ci] += np.tests_per_sample / spps.size();
    }
  }
  // Target: the noise the traditional renderer reaches at its largest spp.
  const double target = r.table.rows[spps.size() - 1][4];
  for (std::size_t ci = 0; ci < configs.size(); ++ci)
    for (std::size_t k = 0; k < spps.size(); ++k) {
      auto& row = r.table.rows[first_row[ci] + k];
      row[7] = sigma2[ci] / target;
      row[8] = row[7] * tps[ci];
    }
  // 1/spp law for each configuration.
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    const auto& a = r.table.rows[first_row[ci]];
    const auto& b = r.table.rows[first_row[ci] + spps.size() - 1];
    if (a[4] > 0)
      r.checks.push_back(
          {"config level " + str(configs[ci]) + ": variance x spp constant (1/spp law, 35%)",
           b[4] * b[2], a[4] * a[2], 0.35 * a[4] * a[2]});
  }
  std::string lines;
  int better = 0, cheaper = 0;
  double vmin = 1e300, vmax = 0, cmin = 1e300, cmax = 0;
  for (std::size_t ci = 1; ci < configs.size(); ++ci) {
    const double vr = sigma2[ci] / sigma2[0];
    const double cr = (sigma2[ci] * tps[ci]) / (sigma2[0] * tps[0]);
    vmin = std::min(vmin, vr), vmax = std::max(vmax, vr);
    cmin = std::min(cmin, cr), cmax = std::max(cmax, cr);
    if (vr < 1) ++better;
    if (cr < 1) ++cheaper;
    const double cell = 2.0 / std::pow(2.0, configs[ci]);
    lines += "| " + str(configs[ci]) + " | " +
             fmt(cell / (2.0 * 4.0 * std::tan(20.0 * M_PI / 180.0) / size)) + " | " +
             fmt(sigma2[ci]) + " | " + fmt(vr) + " | " + fmt(tps[ci]) + " | " +
             fmt(sigma2[ci] / target) + " | " + fmt(sigma2[ci] / target * tps[ci]) + " | " +
             fmt(cr) + " |\n";
  }
  r.summary_columns = r.table.columns;
  Panel pv{"Per-pixel variance vs samples per pixel (prisms, front, " + str(size) + "^2 px)",
           "samples per pixel",
           "mean per-pixel variance of luminance",
           true,
           true,
           {}};
  Panel pc{"Variance vs cost",
           "intersection tests per pixel",
           "mean per-pixel variance",
           true,
           true,
           {}};
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    const std::string t =
        configs[ci] == 0 ? "traditional" : "stochastic, level " + str(configs[ci]);
    pv.series.push_back({"spp", "pixel_variance", t, false, "config", double(ci)});
  }
  // tests per pixel = tests_per_sample * spp: gnuplot expression column.
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    const std::string t =
        configs[ci] == 0 ? "traditional" : "stochastic, level " + str(configs[ci]);
    pc.series.push_back({"tests_per_pixel", "pixel_variance", t, false, "config", double(ci)});
  }
  r.table.columns.push_back("tests_per_pixel");
  for (auto& row : r.table.rows) row.push_back(row[5] * row[2]);
  r.panels = {pv, pc};
  r.checks.push_back({"stochastic amalgams at some level have lower per-sample variance",
                      better > 0 ? 1.0 : 0.0, 1.0, 0});
  const int nl = int(levels.size());
  // The claim has two parts, lower variance and lower cost at equal noise.
  r.verdict = better == nl && cheaper == nl ? Verdict::kHolds
              : cheaper > 0                 ? Verdict::kHoldsWithCorrection
                                            : Verdict::kDoesNotHold;
  r.findings =
      "Per-sample variance sigma^2 (mean over pixels of the variance across " + str(seeds) +
      " seeds, times spp) of the traditional renderer: " + fmt(sigma2[0]) + " at " + fmt(tps[0]) +
      " tests per sample. Target noise = the traditional renderer's variance at " +
      str(spps.back()) + " spp (" + fmt(target) +
      "). For the scale-sensitive stochastic renderer at each level:\n\n"
      "| level | amalgam size (pixels) | sigma^2 per sample | vs traditional | tests/sample | "
      "samples to target | tests to target | cost vs traditional |\n"
      "|---|---|---|---|---|---|---|---|\n" +
      lines +
      "\nPer-sample variance of the stochastic renderer relative to the traditional one "
      "ranges from " +
      fmt(vmin) + " to " + fmt(vmax) + " (lower at " + str(better) + " of " + str(nl) +
      " levels); the total tests needed to reach the target noise range from " + fmt(cmin) +
      " to " + fmt(cmax) + " of the traditional renderer's (cheaper at " + str(cheaper) + " of " +
      str(nl) +
      " levels). So the paper's *conclusion* (stochastic amalgams remain cheaper after the "
      "extra sampling) holds here, but its *mechanism* (an amalgam has lower image variance "
      "than the bounding volume it replaces) is not what carries it: where an amalgam covers "
      "several pixels its colour is constant across the pixel, but the binary opacity "
      "decision (a ray sees through an amalgam with probability 1 - fill^2 = 0.36) brings "
      "back about as much variance as the sub-pixel detail it removes. The saving comes from "
      "the cheaper samples. Note that the two renderers converge to different images (the "
      "amalgams' appearance is an average), so this compares noise, not error.";
  return r;
}

ExperimentResult more_levels(const Config& c) {
  ExperimentResult r;
  r.title = "Adding levels below the rendered amalgams";
  r.claim =
      "If the database gets k more levels (many more primitives) below the amalgams the "
      "scale-sensitive renderer renders, its execution time is unchanged; a traditional "
      "renderer must examine many of the new objects and takes longer.";
  r.prediction =
      "Scale-sensitive tests and image identical for every k (Eq. 3: independent of "
      "p); traditional tests growing with k.";
  r.table.columns = {
      "k",          "depth",        "primitives",        "ss_tests",         "ss_seconds",
      "trad_tests", "trad_seconds", "ss_image_max_diff", "ss_tests_per_ray", "trad_tests_per_ray"};
  const int l1 = 3;
  const int K = c.quick ? 4 : 14;
  const int size = c.quick ? 32 : 128;
  std::vector<Vec3> ref;
  double ref_tests = 0;
  for (int k = 0; k <= K; ++k) {
    const int depth = l1 + 1 + k;
    const LoadedScene s = scene("prisms", {{"depth", str(depth)}, {"view", "corner"}});
    RenderOptions so = at_level(l1), to = traditional();
    for (RenderOptions* o : {&so, &to}) {
      o->width = o->height = size;
      o->spp = 1;
      o->threads = c.threads;
    }
    const RenderOutput a = render(s, so);
    const RenderOutput b = render(s, to);
    double diff = 0;
    if (ref.empty()) ref = a.image, ref_tests = u(a.counters.total());
    for (std::size_t i = 0; i < ref.size(); ++i) {
      const Vec3 d = a.image[i] - ref[i];
      diff =
          std::max({diff, double(std::fabs(d.x)), double(std::fabs(d.y)), double(std::fabs(d.z))});
    }
    const double rays = double(size) * size;
    r.table.add({double(k), double(depth), s.info().primitives, u(a.counters.total()), a.seconds,
                 u(b.counters.total()), b.seconds, diff, u(a.counters.total()) / rays,
                 u(b.counters.total()) / rays});
    r.checks.push_back(
        {"k=" + str(k) + " scale-sensitive tests unchanged", u(a.counters.total()), ref_tests, 0});
    r.checks.push_back({"k=" + str(k) + " scale-sensitive image unchanged", diff, 0, 0});
  }
  const auto& first = r.table.rows.front();
  const auto& last = r.table.rows.back();
  r.checks.push_back({"traditional tests grow with k (last/first > 2)",
                      std::min(last[5] / first[5], 2.0), 2.0, 0});
  r.summary_columns = r.table.columns;
  r.panels.push_back({"Tests per primary ray vs added levels k (prisms corner, l1=3)",
                      "k (levels added below l1)",
                      "tests per primary ray (incl. shadow rays)",
                      false,
                      true,
                      {{"k", "ss_tests_per_ray", "scale-sensitive, level 3", false},
                       {"k", "trad_tests_per_ray", "traditional", false}}});
  r.panels.push_back({"Wall time vs k",
                      "k",
                      "render seconds (" + str(size) + "^2 px, 1 spp)",
                      false,
                      true,
                      {{"k", "ss_seconds", "scale-sensitive, level 3", false},
                       {"k", "trad_seconds", "traditional", false}}});
  r.verdict = Verdict::kHolds;
  r.findings = "From k = 0 to k = " + str(K) + " (primitives " + fmt(first[2]) + " -> " +
               fmt(last[2]) + "), the scale-sensitive render made exactly the same " +
               fmt(first[3]) + " tests and an identical image (max pixel difference " +
               fmt(last[7]) + "); its time went " + fmt(first[4]) + " s -> " + fmt(last[4]) +
               " s. The traditional render grew from " + fmt(first[9]) + " to " + fmt(last[9]) +
               " tests per ray (time " + fmt(first[6]) + " s -> " + fmt(last[6]) +
               " s): it grows with every added level (roughly linearly in k here, because the "
               "first hit is found early in this dense scene: the expected case, O(log p)).";
  return r;
}

}  // namespace amalgam::experiments

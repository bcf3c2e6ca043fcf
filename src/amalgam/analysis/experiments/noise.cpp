/// \file Experiment noise: the noise that stochastic opacity adds, on builtin:prisms
/// (Figure 2).

#include <algorithm>
#include <cmath>

#include "amalgam/analysis/experiments/common.h"
#include "amalgam/analysis/experiments/noise_stats.h"

namespace amalgam::experiments {
using namespace detail;

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
                     "tests_to_target",
                     "footprint"};
  const int depth = c.quick ? 6 : 8;
  const int size = c.quick ? 24 : 96;
  const int seeds = c.quick ? 5 : 16;
  const std::vector<int> spps = c.quick ? std::vector<int>{1, 4} : std::vector<int>{1, 4, 16};
  // builtin:prisms' default fill, given explicitly so that the findings can quote it.
  const double fill = 0.8;
  const LoadedScene s =
      scene("prisms", {{"depth", str(depth)}, {"view", "front"}, {"fill", fmt(fill)}});
  // Config 0: traditional; then the scale-sensitive stochastic renderer on each fixed level,
  // then choosing by footprint (the renderer's default way, --footprint K).
  struct NoiseConfig {
    int level = 0;         ///< the level rendered, or 0
    double footprint = 0;  ///< K, or 0
    std::string label;
    RenderOptions options;
  };
  std::vector<NoiseConfig> configs = {{0, 0, "traditional", traditional()}};
  for (int l = 2; l < depth; ++l)
    configs.push_back({l, 0, "stochastic, level " + str(l), at_level(l)});
  for (double k : {1.0, 2.0}) {
    RenderOptions o;
    o.lod = ByFootprint{static_cast<float>(k)};
    configs.push_back({0, k, "stochastic, footprint " + fmt(k), o});
  }
  std::vector<VarianceEstimate> est(configs.size());
  std::vector<std::size_t> first_row(configs.size());
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    first_row[ci] = r.table.rows.size();
    std::vector<VarianceEstimate> per_spp;
    for (int spp : spps) {
      RenderOptions o = configs[ci].options;
      o.width = o.height = size;
      o.spp = spp;
      o.threads = c.threads;
      const VarianceEstimate e = variance_across_seeds(s, o, seeds, 1000);
      r.table.add({double(ci), double(configs[ci].level), double(spp), double(seeds),
                   e.sigma2 / spp, e.tests_per_sample, e.sigma2, 0, 0, configs[ci].footprint});
      per_spp.push_back(e);
    }
    est[ci] = mean_of(per_spp);
  }
  // Target: the noise the traditional renderer reaches at its largest spp.
  const double target = r.table.rows[spps.size() - 1][4];
  for (std::size_t ci = 0; ci < configs.size(); ++ci)
    for (std::size_t k = 0; k < spps.size(); ++k) {
      auto& row = r.table.rows[first_row[ci] + k];
      row[7] = est[ci].sigma2 / target;
      row[8] = row[7] * est[ci].tests_per_sample;
    }
  // 1/spp law for each configuration.
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    const auto& a = r.table.rows[first_row[ci]];
    const auto& b = r.table.rows[first_row[ci] + spps.size() - 1];
    if (a[4] > 0)
      r.checks.push_back({configs[ci].label + ": variance x spp constant (1/spp law, 35%)",
                          b[4] * b[2], a[4] * a[2], 0.35 * a[4] * a[2], Role::kHarness});
  }
  // Each ratio with its 95 % interval: below 1, above 1, or a tie (the interval holds 1). A
  // tie is reported as such and is evidence neither way, so it makes no check.
  std::string lines, ties;
  int lower = 0, higher = 0, cheaper = 0, dearer = 0;
  const std::size_t nc = configs.size() - 1;
  for (std::size_t ci = 1; ci < configs.size(); ++ci) {
    const CostRatio vr = cost_ratio(est[ci], est[0], false);
    const CostRatio cr = cost_ratio(est[ci], est[0]);
    lower += vr.order<0, higher += vr.order> 0;
    cheaper += cr.order<0, dearer += cr.order> 0;
    const auto judged = [](int o) { return o < 0 ? "lower" : o > 0 ? "higher" : "tie"; };
    std::string size_px = "-";
    if (configs[ci].level > 0) {
      // Pixel size on the front face: the camera is at z = 4, the cube's front face at z = 1
      // (distance 3), vertical field of view 40 degrees over `size` pixels.
      const double cell = 2.0 / std::pow(2.0, configs[ci].level);
      size_px = fmt(cell / (2.0 * 3.0 * std::tan(20.0 * M_PI / 180.0) / size));
    }
    lines += "| " + configs[ci].label + " | " + size_px + " | " + fmt(est[ci].sigma2) + " | " +
             with_interval(vr) + " (" + judged(vr.order) + ") | " + fmt(est[ci].tests_per_sample) +
             " | " + fmt(est[ci].sigma2 / target) + " | " + with_interval(cr) + " (" +
             judged(cr.order) + ") |\n";
    if (cr.order == 0) ties += (ties.empty() ? "" : ", ") + configs[ci].label;
    if (cr.order != 0)
      r.checks.push_back({configs[ci].label +
                              ": tests to reach the target noise below the traditional "
                              "renderer's (95 % interval of the ratio below 1)",
                          cr.order < 0 ? 1.0 : 0.0, 1.0, 0});
  }
  r.summary_columns = r.table.columns;
  Panel pv{"Per-pixel variance vs samples per pixel (prisms, front, " + str(size) + "^2 px)",
           "samples per pixel",
           "mean per-pixel variance of luminance",
           Scale::kLog,
           Scale::kLog,
           {}};
  Panel pc{"Variance vs cost",
           "intersection tests per pixel",
           "mean per-pixel variance",
           Scale::kLog,
           Scale::kLog,
           {}};
  for (std::size_t ci = 0; ci < configs.size(); ++ci)
    pv.series.push_back(
        {"spp", "pixel_variance", configs[ci].label, Draw::kPoints, "config", double(ci)});
  // tests per pixel = tests_per_sample * spp: gnuplot expression column.
  for (std::size_t ci = 0; ci < configs.size(); ++ci)
    pc.series.push_back({"tests_per_pixel", "pixel_variance", configs[ci].label, Draw::kPoints,
                         "config", double(ci)});
  r.table.columns.push_back("tests_per_pixel");
  for (auto& row : r.table.rows) row.push_back(row[5] * row[2]);
  r.panels = {pv, pc};
  // The claim has two parts. Its conclusion (cheaper at equal noise) is checked for each
  // configuration above; its mechanism (lower per-sample variance than the traditional
  // renderer) is a printed claim: refuted where a variance is higher beyond its interval,
  // supported where every one is lower, undecided (no check) otherwise.
  if (higher > 0)
    r.checks.push_back(
        {"mechanism: per-sample variance higher than traditional's (interval "
         "above 1) for some configuration",
         1.0, 1.0, 0, Role::kRefutesPrinted});
  else if (lower == static_cast<int>(nc))
    r.checks.push_back(
        {"mechanism: per-sample variance lower than traditional's for every configuration", 1.0,
         1.0, 0});
  tag(r, "Noise");
  r.findings =
      "Per-sample variance sigma^2 (mean over pixels of the variance across " + str(seeds) +
      " seeds, times spp, averaged over spp " + str(spps.front()) + " to " + str(spps.back()) +
      ") of the traditional renderer: " + fmt(est[0].sigma2) + " +- " + fmt(est[0].se) +
      " (standard error) at " + fmt(est[0].tests_per_sample) +
      " tests per sample. Target noise = the traditional renderer's variance at " +
      str(spps.back()) + " spp (" + fmt(target) +
      "). Ratios to the traditional renderer with their 95 % intervals (two standard errors of "
      "the logarithm; a tie when the interval holds 1), for the scale-sensitive stochastic "
      "renderer on each fixed level and choosing by footprint:\n\n"
      "| configuration | amalgam size (pixels) | sigma^2 per sample | variance vs traditional | "
      "tests/sample | samples to target | tests to target vs traditional |\n"
      "|---|---|---|---|---|---|---|\n" +
      lines + "\nOf " + str(nc) +
      " configurations, the tests to reach the target noise are "
      "lower than the traditional renderer's at " +
      str(cheaper) + ", higher at " + str(dearer) + " and a tie at " +
      str(int(nc) - cheaper - dearer) + (ties.empty() ? std::string() : " (" + ties + ")") +
      "; the per-sample variance is lower at " + str(lower) + ", higher at " + str(higher) + ". " +
      std::string(dearer == 0 ? "So the paper's *conclusion* (stochastic amalgams remain cheaper "
                                "after the extra sampling) is not refuted here"
                              : "So the paper's *conclusion* (stochastic amalgams remain cheaper "
                                "after the extra sampling) fails where the ratio is above 1") +
      (higher == 0
           ? (lower == static_cast<int>(nc)
                  ? "; its *mechanism* (lower image variance than the bounding volume) holds for "
                    "every configuration. "
                  : "; its *mechanism* (lower image variance than the bounding volume) is "
                    "neither shown nor refuted: the variances that are not lower are ties. ")
           : ", and its *mechanism* (an amalgam has lower image variance than the bounding "
             "volume it replaces) is not what carries it: where an amalgam covers several pixels "
             "its colour is constant across the pixel, but the binary opacity decision (a ray "
             "sees through an amalgam with probability 1 - fill^2 = " +
                 fmt(1 - fill * fill) +
                 ") brings back about as much variance as the sub-pixel detail it removes. The "
                 "saving comes from the cheaper samples. ") +
      "This scene sets every amalgam's opacity to exactly its geometric coverage (fill^2), so "
      "it cannot show the mechanism at its best; scenes whose amalgams are baked from their "
      "contents (a mesh, the field) are measured in [noise-baked](#noise-baked). Note that the two "
      "renderers converge to different images (the amalgams' appearance is an average), so this "
      "compares noise, not error.";
  return r;
}

}  // namespace amalgam::experiments

/// \file Experiment noise: the noise that stochastic opacity adds, on builtin:prisms
/// (Figure 2).

#include <algorithm>
#include <cmath>

#include "amalgam/analysis/experiments/common.h"

namespace amalgam::experiments {
using namespace detail;

namespace {

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
  // builtin:prisms' default fill, given explicitly so that the findings can quote it.
  const double fill = 0.8;
  const LoadedScene s =
      scene("prisms", {{"depth", str(depth)}, {"view", "front"}, {"fill", fmt(fill)}});
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
           b[4] * b[2], a[4] * a[2], 0.35 * a[4] * a[2], Role::kHarness});
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
    // Pixel size on the front face: the camera is at z = 4, the cube's front face at z = 1
    // (distance 3), vertical field of view 40 degrees over `size` pixels.
    lines += "| " + str(configs[ci]) + " | " +
             fmt(cell / (2.0 * 3.0 * std::tan(20.0 * M_PI / 180.0) / size)) + " | " +
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
  const int nl = int(levels.size());
  // The claim has two parts. Its conclusion (cheaper at equal noise) must hold at every level;
  // its mechanism (lower per-sample variance than the traditional renderer) is checked as a
  // printed claim that the measurement may refute.
  for (std::size_t ci = 1; ci < configs.size(); ++ci) {
    const double cr = (sigma2[ci] * tps[ci]) / (sigma2[0] * tps[0]);
    r.checks.push_back({"level " + str(configs[ci]) +
                            ": tests to reach the target noise below the traditional renderer's",
                        cr < 1 ? 1.0 : 0.0, 1.0, 0});
  }
  r.checks.push_back({"mechanism: per-sample variance not lower than traditional at some level",
                      better < nl ? 1.0 : 0.0, 1.0, 0, Role::kRefutesPrinted});
  tag(r, "Noise");
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
      str(nl) + " levels). " +
      std::string(cheaper == nl ? "So the paper's *conclusion* (stochastic amalgams remain "
                                  "cheaper after the extra sampling) holds at every level here"
                                : "So the paper's *conclusion* (stochastic amalgams remain "
                                  "cheaper after the extra sampling) fails at " +
                                      str(nl - cheaper) + " of " + str(nl) + " levels") +
      (better == nl
           ? "; its *mechanism* (lower image variance than the bounding volume) holds at every "
             "level too. "
           : ", but its *mechanism* (an amalgam has lower image variance than the bounding "
             "volume it replaces) is not what carries it: where an amalgam covers several pixels "
             "its colour is constant across the pixel, but the binary opacity decision (a ray "
             "sees through an amalgam with probability 1 - fill^2 = " +
                 fmt(1 - fill * fill) +
                 ") brings back about as "
                 "much variance as the sub-pixel detail it removes. The saving comes from the "
                 "cheaper samples. ") +
      "This scene sets every amalgam's opacity to exactly its geometric coverage (fill^2), so "
      "it cannot show the mechanism at its best; scenes whose amalgams are baked from their "
      "contents (a mesh, the field) are measured in [noise-baked](#noise-baked). Note that the two "
      "renderers "
      "converge to different images (the amalgams' appearance is an average), so this compares "
      "noise, not error.";
  return r;
}

}  // namespace amalgam::experiments

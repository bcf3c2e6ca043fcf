/// \file Experiment noise-baked: the paper's noise mechanism on scenes whose amalgams are baked
/// from their contents (hierarchy/bake: opacity = the chance a line through the box hits the
/// contents, colour = the mean of what those lines see) -- a mesh (Wuson) and the field of
/// instanced Wusons -- at every level, against the traditional renderer, which sees the plain
/// bounding volumes' contents. builtin:prisms (experiment noise) sets opacity to exactly the
/// geometric coverage instead.
///
/// The scenes are files, which the analysis layer cannot load: Config::load (set by the CLI and
/// the tests) loads them; a scene that cannot be loaded is reported, not measured.

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "amalgam/analysis/experiments/common.h"
#include "amalgam/analysis/experiments/noise_stats.h"

namespace amalgam::experiments {
using namespace detail;

ExperimentResult noise_baked(const Config& c) {
  ExperimentResult r;
  r.title = "Noise from stochastic opacity, amalgams baked from their contents";
  r.claim =
      "An amalgam has the same shading wherever a ray meets it, while a traditional bounding "
      "volume shows widely varying contents, so the amalgam has lower variance in the image "
      "and needs less sampling; the scale-sensitive renderer should still be cheaper.";
  r.prediction =
      "At every level L of a baked hierarchy: per-sample variance sigma^2 of the "
      "scale-sensitive renderer rendering the amalgams of L (stochastic opacity) below that "
      "of the traditional renderer (the same pixels, the bounding volumes' contents); and "
      "the tests needed to reach equal noise, sigma^2 x tests per sample, below the "
      "traditional renderer's.";
  r.table.columns = {"scene",          "level",      "sigma2",        "tests_per_sample",
                     "variance_ratio", "cost_ratio", "cost_ratio_lo", "cost_ratio_hi",
                     "footprint"};
  struct Spec {
    std::string label, path;
  };
  const std::vector<Spec> specs = {{"Wuson mesh", "/usr/share/assimp/models/PLY/Wuson.ply"},
                                   {"the field", "scenes/field.json"}};
  const int size = c.quick ? 16 : 48;
  const int seeds = c.quick ? 4 : 8;
  const int spp = 2;
  std::string text, unavailable;
  bool any_higher = false, any_dearer = false;
  for (std::size_t si = 0; si < specs.size(); ++si) {
    const Spec& sp = specs[si];
    std::optional<LoadedScene> loaded;
    try {
      if (!c.load) throw std::runtime_error("no scene loader given (Config::load)");
      loaded.emplace(c.load(sp.path));
    } catch (const std::exception& e) {
      unavailable += "* " + sp.label + " (`" + sp.path + "`): not measured: " + e.what() + "\n";
      r.not_measured.push_back(sp.label + ": " + e.what());
      continue;
    }
    const LoadedScene& s = *loaded;
    const int levels = static_cast<int>(s.info().levels);
    RenderOptions t = traditional();
    t.width = t.height = size;
    t.spp = spp;
    t.threads = c.threads;
    const VarianceEstimate te = variance_across_seeds(s, t, seeds, 2000);
    const double st = te.sigma2, tt = te.tests_per_sample;
    r.table.add({double(si), -1, st, tt, 1, 1, 1, 1, 0});
    int lower = 0, higher = 0, cheaper = 0, dearer = 0, n = 0, vacuous = 0;
    std::string lower_at, higher_at, cheaper_at, tie_at;
    // Each fixed level, then choosing by footprint (K = 1, the renderer's default).
    std::vector<std::pair<int, RenderOptions>> runs;
    for (int L = 1; L + 1 < levels; ++L) runs.push_back({L, at_level(L)});
    RenderOptions by_footprint;
    by_footprint.lod = ByFootprint{1.0f};
    runs.push_back({0, by_footprint});
    for (auto& [L, o] : runs) {
      const std::string name = L > 0 ? "level " + str(L) : "footprint 1";
      o.width = o.height = size;
      o.spp = spp;
      o.threads = c.threads;
      const VarianceEstimate e = variance_across_seeds(s, o, seeds, 2000);
      const CostRatio vr = cost_ratio(e, te, false), cr = cost_ratio(e, te);
      r.table.add({double(si), L > 0 ? double(L) : -2.0, e.sigma2, e.tests_per_sample, vr.value,
                   cr.value, cr.lo, cr.hi, L > 0 ? 0.0 : 1.0});
      // Below the deepest amalgams the rays see (every ray reaches its primitives first) the
      // render is the traditional one, bit for bit: nothing to compare.
      if (e.sigma2 == st && e.tests_per_sample == tt) {
        ++vacuous;
        continue;
      }
      ++n;
      const auto add = [](std::string& list, const std::string& x) {
        list += list.empty() ? x : ", " + x;
      };
      lower += vr.order<0, higher += vr.order> 0;
      if (vr.order < 0) add(lower_at, name);
      if (vr.order > 0) add(higher_at, name);
      cheaper += cr.order<0, dearer += cr.order> 0;
      if (cr.order < 0) add(cheaper_at, name);
      // A tie (the ratio's 95 % interval holds 1) is reported and makes no check.
      if (cr.order == 0) add(tie_at, name + " " + with_interval(cr));
      if (cr.order != 0)
        r.checks.push_back({sp.label + ", " + name +
                                ": tests to reach equal noise below the traditional renderer's "
                                "(95 % interval of the ratio below 1)",
                            cr.order < 0 ? 1.0 : 0.0, 1.0, 0});
    }
    // The mechanism (lower variance than the bounding volume): refuted where a variance is
    // higher beyond its interval, supported where every one is lower, else undecided (no check).
    if (higher > 0)
      r.checks.push_back({sp.label + ": mechanism: per-sample variance higher than "
                                     "traditional's (interval above 1) somewhere",
                          1.0, 1.0, 0, Role::kRefutesPrinted});
    else if (lower == n && n > 0)
      r.checks.push_back(
          {sp.label + ": mechanism: per-sample variance lower than traditional's everywhere", 1.0,
           1.0, 0});
    text += "* **" + sp.label + "** (" + str(levels) + " levels, traditional sigma^2 = " + fmt(st) +
            " +- " + fmt(te.se) + " at " + fmt(tt) +
            " tests per sample; 95 % intervals): " + "amalgam variance lower at " + str(lower) +
            " of " + str(n) + " (" + (lower_at.empty() ? "none" : lower_at) + "), higher at " +
            str(higher) + " (" + (higher_at.empty() ? "none" : higher_at) +
            "); cheaper at equal noise at " + str(cheaper) + " (" +
            (cheaper_at.empty() ? "none" : cheaper_at) + "), dearer at " + str(dearer) +
            ", a tie at " + str(n - cheaper - dearer) +
            (tie_at.empty() ? std::string() : " (" + tie_at + ")") +
            (vacuous > 0 ? " (" + str(vacuous) +
                               " deeper levels render exactly the traditional "
                               "image: not compared)"
                         : std::string()) +
            ".\n";
    any_higher |= higher > 0;
    any_dearer |= dearer > 0;
  }
  tag(r, "Noise");
  r.summary_columns = r.table.columns;
  Panel pv{"Per-sample variance relative to the traditional renderer",
           "level L rendered (stochastic opacity)",
           "sigma^2 (amalgams at L) / sigma^2 (traditional)",
           Scale::kLinear,
           Scale::kLog,
           {}};
  Panel pc{"Tests to reach equal noise relative to the traditional renderer",
           "level L rendered",
           "sigma^2 x tests per sample, ratio",
           Scale::kLinear,
           Scale::kLog,
           {}};
  for (std::size_t si = 0; si < specs.size(); ++si) {
    pv.series.push_back(
        {"level", "variance_ratio", specs[si].label, Draw::kPoints, "scene", double(si)});
    pc.series.push_back(
        {"level", "cost_ratio", specs[si].label, Draw::kPoints, "scene", double(si)});
  }
  r.panels = {pv, pc};
  r.findings =
      "Per-sample variance sigma^2 = mean over " + str(size) +
      "^2 pixels of the variance of "
      "the pixel across " +
      str(seeds) + " seeds, times spp (" + str(spp) +
      "); rows with level -1 are the traditional renderer, level -2 the scale-sensitive "
      "renderer choosing by footprint (K = 1).\n\n" +
      text + unavailable +
      "\nWhere the amalgams of L are smaller than a pixel, a sample sees a different amalgam "
      "(and passes or stops at random) at every position in the pixel, as the traditional "
      "renderer sees different contents; where they cover several pixels their colour is "
      "constant across the pixel, but the binary stochastic-opacity decision adds a variance "
      "alpha (1 - alpha) (c - c_behind)^2 that a surface seen directly does not have. Which "
      "wins is a property of the scene and the level, as the rows above show. " +
      std::string(any_higher ? "The mechanism (lower variance than the bounding volume) does "
                               "not hold at every level. "
                             : "The mechanism holds at every level measured. ") +
      (any_dearer ? "The conclusion (cheaper at equal noise) holds only at the levels listed "
                    "above: a level whose amalgams cover several pixels with a strong contrast "
                    "against what lies behind them (a single mesh against the background) pays "
                    "more in variance than it saves in tests, and the deepest levels, far below "
                    "a pixel, cost nearly the traditional renderer's tests while still adding "
                    "the stochastic decision's noise."
                  : "No level is dearer at equal noise beyond its interval (cheaper where listed, "
                    "the rest ties): the conclusion is not refuted here.");
  return r;
}

}  // namespace amalgam::experiments

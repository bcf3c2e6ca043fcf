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

namespace amalgam::experiments {
using namespace detail;

namespace {

/// Per-sample variance (mean over pixels of the variance of the pixel across seeds, times
/// spp) and intersection tests per sample.
std::pair<double, double> per_sample(const LoadedScene& s, RenderOptions o, int seeds) {
  std::vector<double> sum, sum2;
  double tests = 0;
  for (int k = 0; k < seeds; ++k) {
    o.seed = 2000 + static_cast<std::uint64_t>(k);
    const RenderOutput out = render(s, o);
    if (sum.empty()) sum.assign(out.image.size(), 0), sum2.assign(out.image.size(), 0);
    for (std::size_t i = 0; i < out.image.size(); ++i) {
      const double l = luma(out.image[i]);
      sum[i] += l, sum2[i] += l * l;
    }
    tests += u(out.counters.total());
  }
  double var = 0;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double m = sum[i] / seeds;
    var += std::max(0.0, sum2[i] / seeds - m * m) * seeds / (seeds - 1);
  }
  var /= double(sum.size());
  return {var * o.spp, tests / (double(seeds) * o.width * o.height * o.spp)};
}

}  // namespace

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
  r.table.columns = {"scene",          "level",     "sigma2", "tests_per_sample",
                     "variance_ratio", "cost_ratio"};
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
    const auto [st, tt] = per_sample(s, t, seeds);
    r.table.add({double(si), -1, st, tt, 1, 1});
    int lower = 0, cheaper = 0, n = 0, vacuous = 0;
    std::string lower_at, higher_at, cheaper_at;
    for (int L = 1; L + 1 < levels; ++L) {
      RenderOptions o = at_level(L);
      o.width = o.height = size;
      o.spp = spp;
      o.threads = c.threads;
      const auto [sa, ta] = per_sample(s, o, seeds);
      const double vr = sa / st, cr = (sa * ta) / (st * tt);
      r.table.add({double(si), double(L), sa, ta, vr, cr});
      // Below the deepest amalgams the rays see (every ray reaches its primitives first) the
      // render is the traditional one, bit for bit: nothing to compare.
      if (sa == st && ta == tt) {
        ++vacuous;
        continue;
      }
      ++n;
      lower += vr < 1;
      cheaper += cr < 1;
      (vr < 1 ? lower_at : higher_at) +=
          (vr < 1 ? lower_at : higher_at).empty() ? str(L) : ", " + str(L);
      if (cr < 1) cheaper_at += cheaper_at.empty() ? str(L) : ", " + str(L);
      r.checks.push_back({sp.label + ", level " + str(L) +
                              ": tests to reach equal noise below the traditional renderer's",
                          cr < 1 ? 1.0 : 0.0, 1.0, 0});
    }
    r.checks.push_back({sp.label + ": mechanism: per-sample variance not lower than traditional "
                                   "at some level",
                        lower < n ? 1.0 : 0.0, 1.0, 0, Role::kRefutesPrinted});
    text += "* **" + sp.label + "** (" + str(levels) + " levels, traditional sigma^2 = " + fmt(st) +
            " at " + fmt(tt) + " tests per sample): amalgam variance lower at " + str(lower) +
            " of " + str(n) + " levels (" + (lower_at.empty() ? "none" : lower_at) +
            "), not lower at " + (higher_at.empty() ? "none" : higher_at) +
            "; cheaper at equal noise at " + str(cheaper) + " of " + str(n) + " levels (" +
            (cheaper_at.empty() ? "none" : cheaper_at) + ")" +
            (vacuous > 0 ? " (" + str(vacuous) +
                               " deeper levels render exactly the traditional "
                               "image: not compared)"
                         : std::string()) +
            ".\n";
    any_higher |= lower < n;
    any_dearer |= cheaper < n;
  }
  tag(r, "Noise");
  r.summary_columns = r.table.columns;
  Panel pv{"Per-sample variance relative to the traditional renderer",
           "level L rendered (stochastic opacity)",
           "sigma^2 (amalgams at L) / sigma^2 (traditional)",
           false,
           true,
           {}};
  Panel pc{"Tests to reach equal noise relative to the traditional renderer",
           "level L rendered",
           "sigma^2 x tests per sample, ratio",
           false,
           true,
           {}};
  for (std::size_t si = 0; si < specs.size(); ++si) {
    pv.series.push_back({"level", "variance_ratio", specs[si].label, false, "scene", double(si)});
    pc.series.push_back({"level", "cost_ratio", specs[si].label, false, "scene", double(si)});
  }
  r.panels = {pv, pc};
  r.findings =
      "Per-sample variance sigma^2 = mean over " + str(size) +
      "^2 pixels of the variance of "
      "the pixel across " +
      str(seeds) + " seeds, times spp (" + str(spp) +
      "); rows with level -1 are the traditional renderer.\n\n" + text + unavailable +
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
                  : "The conclusion (cheaper at equal noise) holds at every level measured.");
  return r;
}

}  // namespace amalgam::experiments

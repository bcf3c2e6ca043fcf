// `amalgam advise`'s measurement, table and verdict (advise.h).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "advise.h"
#include "amalgam/render/tracer.h"
#include "amalgam/util/atomic_file.h"
#include "render_setup.h"

namespace amalgam::cli::advise {
namespace {

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

/// A ratio as the table prints it: two decimals, or two significant digits below 0.1.
std::string ratio(double v) {
  if (v >= 0.1) return fixed(v, 2);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g", v);
  return buf;
}

double mse(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double d = static_cast<double>(a[i][k]) - b[i][k];
      s += d * d;
    }
  return s / (3.0 * static_cast<double>(a.size()));
}

/// Student's t at 97.5 % for `df` degrees of freedom (a two-sided 95 % interval).
double t975(int df) {
  static constexpr std::array<double, 10> kT = {12.706, 4.303, 3.182, 2.776, 2.571,
                                                2.447,  2.365, 2.306, 2.262, 2.228};
  if (df < 1) return 0.0;
  if (df <= 10) return kT[static_cast<std::size_t>(df - 1)];
  return df <= 20 ? 2.086 : df <= 30 ? 2.042 : 1.96;
}

/// exp of the mean of `logs` with its 95 % interval.
Ratio ratio_of(const std::vector<double>& logs) {
  const double n = static_cast<double>(logs.size());
  double mean = 0;
  for (double l : logs) mean += l / n;
  double var = 0;
  for (double l : logs) var += (l - mean) * (l - mean);
  const double half =
      logs.size() > 1 ? t975(static_cast<int>(logs.size()) - 1) * std::sqrt(var / (n - 1) / n) : 0;
  return {std::exp(mean), std::exp(mean - half), std::exp(mean + half)};
}

/// log(MSE x time) of each repeat.
std::vector<double> log_costs(const Measured& m) {
  std::vector<double> out;
  for (const Run& r : m.runs) out.push_back(std::log(std::max(r.mse * r.seconds, 1e-300)));
  return out;
}

/// The per-repeat log ratio of `a`'s cost over `b`'s: above 0, `b` is better.
std::vector<double> log_ratio(const Measured& a, const Measured& b) {
  const std::vector<double> x = log_costs(a), y = log_costs(b);
  std::vector<double> out;
  for (std::size_t r = 0; r < std::min(x.size(), y.size()); ++r) out.push_back(x[r] - y[r]);
  return out;
}

/// Render seconds per sample of `tracer` at `o`'s size: the mean of an 8-sample render (half
/// the default budget for full detail: shorter pilots misjudge by 20-30 % at 320x240).
double seconds_per_sample(const Tracer& tracer, RenderOptions o) {
  o.spp = 8;
  return tracer.render(o).seconds / 8;
}

std::string mib(double bytes) {
  return fixed(bytes / (1024.0 * 1024.0), 0);
}

}  // namespace

double Measured::rmse() const {
  double s = 0;
  for (const Run& r : runs) s += r.mse / static_cast<double>(runs.size());
  return std::sqrt(s);
}

double Measured::seconds() const {
  double s = 0;
  for (const Run& r : runs) s += r.seconds / static_cast<double>(runs.size());
  return s;
}

std::vector<Candidate> candidates(const RenderOptions& base) {
  std::vector<Candidate> out;
  RenderOptions o = base;
  o.lod = FullDetail{};
  out.push_back({"full detail", "traditional", o, false});
  if (have_embree()) {
    o.tracer = TracerKind::kEmbree;
    out.push_back({"Embree, full detail", "embree", o, false});
    o.tracer = TracerKind::kAmalgam;
  }
  for (float k : {1.0f, 4.0f}) {
    o.lod = ByFootprint{k};
    o.opacity = OpacityKind::kStochastic;
    out.push_back({"amalgams K=" + fixed(k, 0) + ", stochastic",
                   "scale-sensitive-k" + fixed(k, 0) + "-stochastic", o, true});
  }
  o.lod = ByFootprint{1.0f};
  o.opacity = OpacityKind::kComposite;
  out.push_back({"amalgams K=1, composite", "scale-sensitive-k1-composite", o, true});
  o.lod = VolumetricCells{};
  o.opacity = OpacityKind::kStochastic;
  out.push_back({"volumetric cells", "volumetric", o, true});
  return out;
}

std::vector<Measured> measure(const Scenes& s, const RenderOptions& base, const RenderOutput& ref,
                              double budget, int repeats) {
  std::vector<Measured> ms;
  std::vector<std::unique_ptr<Tracer>> tracers;
  for (const Candidate& c : candidates(base)) {
    const bool volumetric = c.options.renderer() == RendererKind::kVolumetric;
    if (volumetric && !s.objects) continue;
    const LoadedScene& scene = volumetric ? *s.objects : *s.scene;
    set_activity("setting up " + c.name);
    const double before = amalgam::resident_bytes();
    tracers.push_back(make_tracer(scene, c.options));
    Measured m{c, {}, {}, 0, 0, {}};
    m.setup_bytes =
        std::max(0.0, amalgam::resident_bytes() - before) + (volumetric ? s.objects_bytes : 0);
    m.setup_s = scene.build_seconds + tracers.back()->build_seconds() +
                (c.options.renderer() == RendererKind::kScaleSensitive ? scene.bake_seconds : 0.0) +
                (volumetric ? scene.volume_seconds : 0.0);
    const double per_sample = seconds_per_sample(*tracers.back(), c.options);
    m.c.options.spp =
        static_cast<int>(std::clamp(std::floor(budget / std::max(per_sample, 1e-9)), 1.0, 65536.0));
    ms.push_back(std::move(m));
  }
  // Rounds over the renderers, so that a slow spell of the machine falls on all of them.
  for (int r = 0; r < repeats; ++r) {
    for (std::size_t i = 0; i < ms.size(); ++i) {
      Measured& m = ms[i];
      set_activity("rendering with " + m.c.name);
      RenderOptions o = m.c.options;
      o.seed = base.seed + static_cast<std::uint64_t>(r);
      RenderOutput out = tracers[i]->render(o);
      m.runs.push_back({o.seed, mse(out.image, ref.image), out.seconds});
      if (r == 0) m.out = std::move(out);
    }
  }
  for (Measured& m : ms) m.vs_full = ratio_of(log_ratio(ms[0], m));
  return ms;
}

Verdict judge(const std::vector<Measured>& ms) {
  Verdict v;
  auto better = [&](std::size_t a, std::size_t b) {
    return ms[a].vs_full.value > ms[b].vs_full.value;
  };
  bool have_lod = false;
  for (std::size_t i = 0; i < ms.size(); ++i) {
    if (better(i, v.best)) v.best = i;
    if (ms[i].c.level_of_detail) {
      if (!have_lod || better(i, v.best_lod)) v.best_lod = i;
      have_lod = true;
    } else if (better(i, v.best_full)) {
      v.best_full = i;
    }
  }
  // Tied: the interval of the ratio of the best's error per time over theirs reaches 1.
  for (std::size_t i = 0; i < ms.size(); ++i)
    if (i != v.best && ratio_of(log_ratio(ms[i], ms[v.best])).low <= 1.0) v.tied.push_back(i);
  v.lod_vs_full = ratio_of(log_ratio(ms[v.best_full], ms[v.best_lod]));
  const bool one = ms[0].runs.size() < 2;
  const Ratio& q = v.lod_vs_full;
  v.outcome = (one ? q.value > 1.1 : q.low > 1.0)    ? "pays off"
              : (one ? q.value < 0.9 : q.high < 1.0) ? "does not pay off"
                                                     : "undecided";
  return v;
}

void report(std::ostream& log, const std::vector<Measured>& ms, const Verdict& v, double budget,
            int repeats, const AdviseOptions& a) {
  log << "time per render: " << fixed(budget, 3) << " s, " << repeats << " repeats each; "
      << a.width << "x" << a.height << ", stratified\n";
  if (budget < 0.1)
    log << "(renders under 0.1 s: their times are noisy, the intervals say how much)\n";
  log << "\n";
  char row[320];
  std::snprintf(row, sizeof row, "%-26s %6s %9s %8s %9s %9s %9s %20s\n", "renderer", "spp",
                "render s", "setup s", "setup MiB", "tests/ray", "RMSE", "vs full det. (95 %)");
  log << row;
  for (const Measured& m : ms) {
    const std::string tests = m.c.options.tracer == TracerKind::kAmalgam
                                  ? fixed(m.out.per_primary.mean(), 1)
                                  : std::string("-");
    const std::string interval =
        repeats > 1 ? " (" + ratio(m.vs_full.low) + "-" + ratio(m.vs_full.high) + ")" : "";
    std::snprintf(row, sizeof row, "%-26s %6d %9.3f %8.3f %9s %9s %9.5f %7sx%-15s\n",
                  m.c.name.c_str(), m.out.spp, m.seconds(), m.setup_s, mib(m.setup_bytes).c_str(),
                  tests.c_str(), m.rmse(), ratio(m.vs_full.value).c_str(), interval.c_str());
    log << row;
  }
  log << "\n\"vs full det.\": full detail's MSE x time over this renderer's (above 1: lower "
         "error in the same time).\n";
  const Measured& best = ms[v.best];
  log << "Best error per time on this view: " << best.c.name << " (" << ratio(best.vs_full.value)
      << "x)";
  for (std::size_t i = 0; i < v.tied.size(); ++i)
    log << (i == 0 ? "; tied within the intervals: " : ", ") << ms[v.tied[i]].c.name;
  log << ".\n";
  const Measured &lod = ms[v.best_lod], &full = ms[v.best_full];
  const Ratio& q = v.lod_vs_full;
  const std::string against = lod.c.name + " against " + full.c.name + ": " + ratio(q.value) + "x" +
                              (repeats > 1 ? " (" + ratio(q.low) + "-" + ratio(q.high) + ")"
                                           : std::string(" (one repeat: no interval)"));
  if (v.outcome == "pays off")
    log << "Amalgams pay off on this view: " << against << ".\n";
  else if (v.outcome == "does not pay off")
    log << "Amalgams do not pay off on this view: " << against << ".\n";
  else
    log << "Amalgams and full detail cannot be told apart on this view: " << against
        << "; a longer --time or more --repeats narrow the interval.\n";
  for (const Measured* m : {&best, &lod})
    if (m->setup_s > m->seconds())
      log << m->c.name << " sets up in " << fixed(m->setup_s, 2) << " s, longer than its render ("
          << fixed(m->seconds(), 2) << " s): for one image, the set-up decides.\n";
}

void write_json(const AdviseOptions& a, const std::string& scene, double budget, int repeats,
                const RenderOutput& ref, const std::vector<Measured>& ms, const Verdict& v,
                double scene_bytes) {
  nlohmann::ordered_json j;
  j["scene"] = scene;
  j["width"] = a.width, j["height"] = a.height;
  j["render_seconds_each"] = budget;
  j["repeats"] = repeats;
  j["reference"] = {{"spp", a.reference_spp}, {"seconds", ref.seconds}};
  j["scene_bytes"] = scene_bytes;
  for (const Measured& m : ms) {
    nlohmann::ordered_json r;
    r["name"] = m.c.name;
    r["key"] = m.c.key;
    r["spp"] = m.out.spp;
    r["render_seconds"] = m.seconds();
    r["setup_seconds"] = m.setup_s;
    r["setup_bytes"] = m.setup_bytes;
    if (m.c.options.tracer == TracerKind::kAmalgam)
      r["tests_per_primary_ray"] = m.out.per_primary.mean();
    r["rmse"] = m.rmse();
    r["vs_full_detail"] = m.vs_full.value;
    r["vs_full_detail_low"] = m.vs_full.low;
    r["vs_full_detail_high"] = m.vs_full.high;
    for (const Run& run : m.runs)
      r["runs"].push_back(
          {{"seed", run.seed}, {"rmse", std::sqrt(run.mse)}, {"render_seconds", run.seconds}});
    j["renderers"].push_back(r);
  }
  j["best"] = ms[v.best].c.key;
  for (std::size_t i : v.tied) j["tied_with_best"].push_back(ms[i].c.key);
  j["best_level_of_detail"] = ms[v.best_lod].c.key;
  j["best_full_detail"] = ms[v.best_full].c.key;
  j["level_of_detail_vs_full_detail"] = {
      {"value", v.lod_vs_full.value}, {"low", v.lod_vs_full.low}, {"high", v.lod_vs_full.high}};
  j["verdict"] = v.outcome;
  j["peak_bytes"] = peak_memory_bytes();
  if (a.json == "-")
    std::cout << j.dump(2) << "\n";
  else
    write_file_atomic(a.json, j.dump(2) + "\n");
}

}  // namespace amalgam::cli::advise

// The yardstick (issue 13, step 1): image error against time to image, for every renderer, on
// one scene and view, measured so that it cannot be fooled.
//
//   build/bench/amalgam_quality_bench --view street --out build/yardstick/street
//   build/bench/amalgam_quality_bench --quick --out /tmp/q          (smoke run, seconds)
//   scripts/yardstick.sh                                            (both field views + docs)
//
// - Reference: amalgam's traditional renderer (full detail), stratified pixel sampling, in
//   --ref-batches independent batches (own seeds) whose spp doubles until the mean per-pixel
//   standard error (from the spread of the batch means) is below --ref-se or the total reaches
//   --ref-max-spp. Cached on disk (--cache) by the scene's content hash (geometry, lights,
//   camera), the image size and these settings: reruns are cheap.
// - Renderers, all with stratified pixel sampling: amalgam traditional; Intel Embree 3 at full
//   detail in its default configuration (RTC_BUILD_QUALITY_MEDIUM, no scene flags, the same
//   pass loop, sampling and shading: make_tracer); amalgam scale-sensitive (stochastic
//   opacity) at each footprint K of --footprints. Each at each spp of --spps, --runs times
//   with different seeds.
// - Time to image: everything from the scene file to the finished image, per run. amalgam:
//   reading + build + bake + render. Embree: reading + Embree's build + render (amalgam's own
//   build and bake, which only hand Embree its triangles, is not counted). Median over runs.
// - Error against the reference (linear RGB, all channels, no filtering of either side): RMSE
//   (root of the mean of the runs' MSEs), split into bias (mean image of the runs vs reference,
//   with the runs' variance's share and the reference's own variance removed) and standard
//   deviation (spread between runs);
//   relative MSE (squared error / (reference^2 + 0.01)); per-tile bias: mean luminance of
//   every 32x32 tile of the runs' mean image relative to the reference's, worst tile and the
//   fraction within 3 %.
// - The oracle bound (oracle.h) at each K of --oracle-footprints: error only.
// - Speed-up at equal error: each curve's time to reach the RMSE that the traditional renderer
//   has at 16 spp (log-log interpolation between the measured spp), traditional's time (and
//   Embree's) divided by it.
// Output: results.json, results.csv, reference.png and a few images in --out.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "amalgam/io/image.h"
#include "amalgam/util/atomic_file.h"
#include "quality_measure.h"

namespace amalgam {
namespace {

using namespace quality;
using nlohmann::json;

std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

std::vector<int> parse_ints(const std::string& s) {
  std::vector<int> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stoi(item));
  return out;
}
std::vector<float> parse_floats(const std::string& s) {
  std::vector<float> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stof(item));
  return out;
}

/// Time at which a curve (points sorted by spp) reaches `err`: log-log interpolation between
/// the two measured points that bracket it. `bound`: "<=" when even its first point is below
/// `err` (its first time is an upper bound), "" when interpolated; NaN when never reached.
double time_at(const std::vector<std::pair<double, double>>& pts, double err, std::string& bound) {
  bound.clear();
  if (pts.empty()) return NAN;
  if (pts.front().first <= err) {
    bound = "<=";
    return pts.front().second;
  }
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const auto [e0, t0] = pts[i - 1];
    const auto [e1, t1] = pts[i];
    if (e1 <= err) {
      const double w = std::log(err / e0) / std::log(e1 / e0);
      return std::exp(std::log(t0) + w * std::log(t1 / t0));
    }
  }
  return NAN;
}

json num(double x) {
  return std::isfinite(x) ? json(x) : json(nullptr);
}

struct Curve {
  std::string kind;
  float k;
};

std::string label(const Curve& c) {
  std::ostringstream s;
  s << c.kind;
  if (c.kind == "scale-sensitive") s << " K=" << c.k;
  return s.str();
}

/// The command line into `a` (--quick's sizes applied). Returns the exit status when the run
/// ends here (--help, a parse error), else nothing.
std::optional<int> parse_args(int argc, char** argv, Args& a) {
  CLI::App app{"the yardstick: error vs time to image, with the oracle bound (issue 13)"};
  app.add_option("--scene", a.scene, "scene file (instanced; default scenes/field.json)");
  app.add_option("--view", a.view, "street (the scene's camera) or aerial");
  app.add_option("--out", a.out, "folder for results.json, results.csv and images");
  app.add_option("--cache", a.cache, "folder of cached references");
  app.add_option("--width", a.width);
  app.add_option("--height", a.height);
  app.add_option("--threads", a.threads, "threads (default 2)");
  app.add_option("--runs", a.runs, "runs (seeds) per point: median time, bias/variance split");
  app.add_option("--spps", a.spps, "samples per pixel of the curves");
  app.add_option("--footprints", a.ks, "footprints K of the scale-sensitive curves");
  app.add_option("--opacity", a.opacity, "opacity model of the scale-sensitive curves")
      ->check(CLI::IsMember({"stochastic", "deterministic", "prefiltered", "composite"}));
  app.add_option("--light-samples", a.light_samples,
                 "shadow rays per sized light in every measured curve (default: the scene's; "
                 "the reference keeps the scene's)")
      ->check(CLI::Range(0, 4096));
  app.add_option("--oracle-footprints", a.oracle_ks,
                 "footprints K of the oracle (none or empty: no oracle)");
  app.add_option("--oracle-rays", a.oracle_rays, "full-detail rays per oracle estimate");
  app.add_option("--oracle-spp", a.oracle_spp, "samples per pixel of the oracle renders");
  app.add_option("--oracle-runs", a.oracle_runs, "runs (seeds) of each oracle render");
  app.add_option("--ref-max-spp", a.ref_max_spp, "most samples per pixel of the reference");
  app.add_option("--ref-se", a.ref_se, "reference: stop at this mean standard error");
  app.add_option("--ref-batches", a.ref_batches, "reference: independent batches (>= 2)");
  app.add_flag("--oracle-box", a.oracle_box,
               "also the oracle whose disc is the amalgam's box diagonal (default: K footprints)");
  app.add_flag("--no-embree", a.no_embree, "leave out the Embree curve");
  app.add_flag("--quick", a.quick, "smoke run: tiny image, few points");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (a.quick) {
    a.width = 64, a.height = 48, a.spps = "1,2,4", a.ks = "1,4", a.oracle_ks = "1,4";
    a.ref_max_spp = 64, a.oracle_rays = 8, a.oracle_spp = 2;
  }
  if (a.runs < 1 || a.oracle_runs < 1 || a.oracle_rays < 1 || a.ref_batches < 2)
    throw InputError("--runs, --oracle-runs, --oracle-rays must be >= 1, --ref-batches >= 2");
  return std::nullopt;
}

/// The run's settings, the reference's and the bake's share of amalgam's fixed time.
json setup(const Args& a, const Reference& ref) {
  json result;
  result["scene"] = a.scene, result["view"] = a.view;
  result["width"] = a.width, result["height"] = a.height, result["threads"] = a.threads;
  result["runs"] = a.runs;
  result["opacity"] = a.opacity, result["light_samples"] = a.light_samples;
  result["loadavg_start"] = loadavg();
  result["embree"] = "Embree 3, RTC_BUILD_QUALITY_MEDIUM (its default), RTC_SCENE_FLAG_NONE";

  result["reference"] = {{"renderer", "traditional, stratified"},
                         {"spp", ref.spp},
                         {"mean_standard_error", ref.se},
                         {"mean_variance", ref.var},
                         {"seconds", ref.seconds},
                         {"cached", ref.cached}};
  write_image(a.out + "/reference.png", a.width, a.height, ref.image);
  {
    // The bake's share of amalgam's fixed time (the traditional renderer pays it too: the
    // loader always bakes): the loaded hierarchy baked once more, meshes and top level.
    LoadedScene s = load(a);
    auto& h = std::get<InstancedHierarchy>(s.hierarchy);
    const auto t0 = Clock::now();
    for (ExplicitHierarchy& m : h.meshes) bake(m);
    bake(h);
    result["bake_s"] = since(t0);
    result["load_s"] = s.load_seconds, result["build_and_bake_s"] = s.build_seconds;
  }

  return result;
}

/// Every curve at every spp, --runs times, interleaved (every curve at one spp and seed
/// before the next) so that the load of a shared machine drifting over the run does not
/// favour one curve; a 16-spp image of each curve is written.
std::map<std::pair<std::size_t, int>, std::vector<Run>> measure(const Args& a,
                                                                const std::vector<Curve>& curves,
                                                                const std::vector<int>& spps) {
  std::map<std::pair<std::size_t, int>, std::vector<Run>> runs;
  for (int spp : spps)
    for (int r = 0; r < a.runs; ++r)
      for (std::size_t c = 0; c < curves.size(); ++c) {
        Run one = run_once(a, curves[c].kind, curves[c].k, spp, 1000 + r);
        std::fprintf(stderr, "%s spp %d run %d: %.3f + %.3f s\n", label(curves[c]).c_str(), spp, r,
                     one.fixed, one.render);
        if (r == 0 && spp == 16) {
          std::string name = label(curves[c]);
          std::replace(name.begin(), name.end(), ' ', '-');
          std::erase(name, '=');
          write_image(a.out + "/" + name + "-16spp.png", a.width, a.height, one.image);
        }
        runs[{c, spp}].push_back(std::move(one));
      }

  return runs;
}

/// Each curve's rows (JSON and CSV) against the reference; returns its (RMSE, time) points.
std::vector<std::vector<std::pair<double, double>>> curve_rows(
    const Args& a, const std::vector<Curve>& curves, const std::vector<int>& spps,
    std::map<std::pair<std::size_t, int>, std::vector<Run>>& runs, const Reference& ref,
    json& result, std::ofstream& csv) {
  json rows = json::array();
  std::vector<std::vector<std::pair<double, double>>> pts(curves.size());
  for (std::size_t c = 0; c < curves.size(); ++c)
    for (int spp : spps) {
      const std::vector<Run>& rs = runs[{c, spp}];
      std::vector<std::vector<Vec3>> images;
      std::vector<double> total, rend, fixed, tests;
      for (const Run& r : rs) {
        images.push_back(r.image);
        total.push_back(r.fixed + r.render), rend.push_back(r.render), fixed.push_back(r.fixed);
        tests.push_back(r.tests);
      }
      const Errors e = errors(images, ref.image, ref.var, a.width, a.height);
      const double t = median(total);
      pts[c].push_back({e.rmse, t});
      rows.push_back(
          {{"renderer", curves[c].kind},
           {"K", curves[c].kind == "scale-sensitive" ? json(curves[c].k) : json()},
           {"spp", spp},
           {"time_s", t},
           {"render_s", median(rend)},
           {"fixed_s", median(fixed)},
           {"rmse", e.rmse},
           {"bias", e.bias},
           {"stddev", e.stddev},
           {"relmse", e.relmse},
           {"tile_worst", e.tile_worst},
           {"tile_within3", e.tile_within},
           {"tiles", e.tiles},
           {"tests_per_ray", curves[c].kind == "embree" ? json() : json(median(tests))}});
      csv << a.view << "," << curves[c].kind << ","
          << (curves[c].kind == "scale-sensitive" ? std::to_string(curves[c].k) : "") << "," << spp
          << "," << rs.size() << "," << t << "," << median(rend) << "," << median(fixed) << ","
          << e.rmse << "," << e.bias << "," << e.stddev << "," << e.relmse << "," << e.tile_worst
          << "," << e.tile_within << ","
          << (curves[c].kind == "embree" ? "" : std::to_string(median(tests))) << "\n";
    }
  result["curves"] = rows;
  result["tiles_x"] = (a.width + 31) / 32, result["tiles_y"] = (a.height + 31) / 32;

  return pts;
}

/// Equal error: each curve's time to the RMSE traditional reaches at 16 spp (or its nearest
/// measured spp), and its speed-up over traditional and Embree there.
void equal_error(const Args& a, const std::vector<Curve>& curves, const std::vector<int>& spps,
                 const std::vector<std::vector<std::pair<double, double>>>& pts, json& result) {
  std::size_t i16 = 0;
  for (std::size_t i = 0; i < spps.size(); ++i)
    if (std::abs(spps[i] - 16) < std::abs(spps[i16] - 16)) i16 = i;
  const double target = pts[0][i16].first;
  result["equal_error"] = {{"rmse", target}, {"traditional_spp", spps[i16]}};
  std::string bound;
  const double t_trad = time_at(pts[0], target, bound);
  const double t_embree = a.no_embree ? NAN : time_at(pts[1], target, bound);
  json eq = json::array();
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const double t = time_at(pts[c], target, bound);
    eq.push_back({{"curve", label(curves[c])},
                  {"time_s", num(t)},
                  {"bound", bound},
                  {"speedup_vs_traditional", num(t_trad / t)},
                  {"speedup_vs_embree", num(t_embree / t)},
                  {"best_rmse", std::min_element(pts[c].begin(), pts[c].end())->first}});
  }
  result["equal_error"]["curves"] = eq;
}

/// The oracle at each footprint of --oracle-footprints: one load, --oracle-runs seeds each.
json oracle_rows(const Args& a, const std::vector<float>& oks, const Reference& ref,
                 std::ofstream& csv) {
  json oracle = json::array();
  if (!oks.empty()) {
    const LoadedScene s = load(a);
    std::vector<std::pair<float, bool>> cases;
    for (bool box : {false, true})
      if (!box || a.oracle_box)
        for (float k : oks) cases.emplace_back(k, box);
    for (auto [k, box] : cases) {
      const char* disc = box ? "box" : "cone";
      std::vector<std::vector<Vec3>> images;
      double frac = 0;
      const auto t0 = Clock::now();
      for (int r = 0; r < a.oracle_runs; ++r) {
        images.push_back(run_oracle(s, a, k, box, 2000 + r, frac));
        std::fprintf(stderr,
                     "oracle K=%g (%s disc) run %d: %.1f s, %.1f %% of samples in amalgams\n", k,
                     disc, r, since(t0), 100 * frac);
      }
      const Errors e = errors(images, ref.image, ref.var, a.width, a.height);
      std::ostringstream name;
      name << a.out << "/oracle-K" << k << (box ? "-box" : "") << ".png";
      write_image(name.str(), a.width, a.height, images.front());
      oracle.push_back({{"K", k},
                        {"disc", disc},
                        {"spp", a.oracle_spp},
                        {"rays", a.oracle_rays},
                        {"runs", a.oracle_runs},
                        {"in_amalgam", frac},
                        {"rmse", e.rmse},
                        {"bias", e.bias},
                        {"stddev", e.stddev},
                        {"relmse", e.relmse},
                        {"tile_worst", e.tile_worst},
                        {"tile_within3", e.tile_within},
                        {"tiles", e.tiles},
                        {"seconds", since(t0)}});
      csv << a.view << (box ? ",oracle-box," : ",oracle,") << k << "," << a.oracle_spp << ","
          << a.oracle_runs << ",,,," << e.rmse << "," << e.bias << "," << e.stddev << ","
          << e.relmse << "," << e.tile_worst << "," << e.tile_within << ",\n";
    }
  }
  return oracle;
}

int run(int argc, char** argv) {
  Args a;
  if (const std::optional<int> status = parse_args(argc, argv, a)) return *status;
  std::filesystem::create_directories(a.out);
  const std::vector<int> spps = parse_ints(a.spps);
  const std::vector<float> ks = parse_floats(a.ks);
  const std::vector<float> oks = a.oracle_ks.empty() || a.oracle_ks == "none"
                                     ? std::vector<float>{}
                                     : parse_floats(a.oracle_ks);
  const Reference ref = reference(a);
  json result = setup(a, ref);
  std::vector<Curve> curves{{"traditional", 0}};
  if (!a.no_embree) curves.push_back({"embree", 0});
  for (float k : ks) curves.push_back({"scale-sensitive", k});
  auto runs = measure(a, curves, spps);
  std::ofstream csv(a.out + "/results.csv");
  csv << "view,renderer,K,spp,runs,time_s,render_s,fixed_s,rmse,bias,stddev,relmse,tile_worst,"
         "tile_within3,tests_per_ray\n";
  const auto pts = curve_rows(a, curves, spps, runs, ref, result, csv);
  equal_error(a, curves, spps, pts, result);
  result["oracle"] = oracle_rows(a, oks, ref, csv);
  result["loadavg_end"] = loadavg();
  write_file_atomic(a.out + "/results.json", result.dump(1) + "\n");
  return 0;
}

}  // namespace
}  // namespace amalgam

int main(int argc, char** argv) {
  try {
    return amalgam::run(argc, argv);
  } catch (const amalgam::InputError& e) {
    std::fprintf(stderr, "quality_bench: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "quality_bench: %s\n", e.what());
    return 1;
  }
}

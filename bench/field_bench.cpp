// Whole renders of the instanced field (scenes/field.json): Intel Embree 3 at full detail vs
// amalgam's scale-sensitive renderer, at equal image error, and how each one's time per ray
// grows with the field (issue 5, item 2e).
//
//   build/bench/amalgam_field_bench --out bench/results/field      (see scripts/bench.sh)
//   build/bench/amalgam_field_bench --quick --out /tmp/f           (smoke run, seconds)
//
// Both renderers run the same code but for the ray tracer: the pass loop of render()
// (render/passes.h) and the Integrator (direct light, one shadow ray per light, same pixel
// sampling and random streams). Embree's side is the library's `--tracer embree`
// (render/embree_tracer.h): one Embree scene per mesh (its triangles; the ground box as user
// geometry calling amalgam's own box test), one RTC_GEOMETRY_TYPE_INSTANCE per instance with
// the same 3x4 transform, rtcIntersect1 for closest hits (the hit's surface is then taken from
// amalgam's own test of that one primitive, so shading sees the same normal and error bounds)
// and rtcOccluded1 for shadow rays. Embree renders at full detail, so its image is amalgam's
// traditional renderer's but where the two ray tracers disagree on a ray (the driver reports
// the RMSE between the two 1-spp images).
//
// Part 1 (equal error): the reference is amalgam's traditional renderer at --ref-spp samples
// (its own seed). Embree renders at each spp of --spps, amalgam scale-sensitive (stochastic
// opacity) at each footprint K of --footprints and each spp; each image's RMSE (linear RGB,
// all channels) against the reference and its wall time (minimum of --repeat runs, the two
// renderers interleaved). For every amalgam render, Embree's time to reach the same error is
// interpolated (log-log) between the Embree renders that bracket it: "equal-error speed-up" =
// that time / amalgam's time. Where even Embree's 1-spp image has a lower error, Embree's 1-spp
// time is used (a render has at least one sample per pixel), and the row says so.
//
// Views: "street" (scenes/field.json's camera, low at the field's edge: most of the frame
// close-up) and "aerial" (the whole field from afar and above: a Wuson about a pixel wide).
// Part 1 runs for both.
//
// Part 2 (growth): time per primary ray (its shadow ray included) of each, 1 spp, as the
// field grows (a) in extent: more Wusons at the same density, 10^6 .. 10^10 triangles, the
// street camera at the near edge; (b) in detail: the same 17,000 Wusons subdivided 0..4
// times (6.3e7 .. 1.6e10 triangles), from both views.

#include <oneapi/tbb/task_arena.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "amalgam/analysis/metrics.h"
#include "amalgam/io/image.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/render/tracer.h"

namespace amalgam {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// ---- scenes ----------------------------------------------------------------------------------

/// scenes/field.json with `count` Wusons subdivided `subdivide` times, at the density of
/// the original (17,000 in a disc of radius 110) in a disc whose near edge stays 8 units in
/// front of the camera; the ground box covers the disc.
/// Where the camera looks from: "street" is scenes/field.json's own camera (most of the frame
/// close-up); "aerial" looks down on the whole field from afar, a Wuson about a pixel wide.
struct View {
  const char* name;
  const char* camera;  ///< the scene file's "camera" object
};
constexpr View kViews[] = {
    {"street", R"({"position": [0, 2.2, 118], "look_at": [0, 0.2, 70], "vfov": 40})"},
    {"aerial", R"({"position": [0, 260, 420], "look_at": [0, 0, 0], "vfov": 40})"},
};

std::string field_json(long count, int subdivide, const View& view) {
  const double radius = 110.0 * std::sqrt(static_cast<double>(count) / 17000.0);
  const double cz = 110.0 - radius, g = radius + 15.0;
  std::ostringstream s;
  s.precision(9);
  s << R"({"camera": )" << view.camera << R"(,
  "lights": [{"type": "directional", "direction": [0.45, -1, -0.6], "intensity": [2.4, 2.3, 2.1]}],
  "background": [0.55, 0.7, 0.9],
  "materials": {"ground": {"colour": [0.35, 0.45, 0.25]}, "hide": {"colour": [0.8, 0.6, 0.4]}},
  "meshes": [{"name": "wuson", "file": "/usr/share/assimp/models/PLY/Wuson.ply", "fit": 1.0,
              "subdivide": )"
    << subdivide << R"(, "material": "hide", "place": false}],
  "instances": [{"mesh": "wuson", "scatter": {"count": )"
    << count << R"(, "radius": )" << radius << R"(, "seed": 1, "centre": [0, 0, )" << cz << R"(]}}],
  "boxes": [{"min": [)"
    << -g << ", -0.05, " << cz - g << "], \"max\": [" << g << ", 0, " << cz + g
    << R"(], "material": "ground"}]})";
  return s.str();
}

struct Field {
  LoadedScene scene;
  std::unique_ptr<Tracer> embree;  ///< --tracer embree
  double triangles = 0;
  double our_build_s = 0;
};

std::unique_ptr<Field> make_field(long count, int subdivide, const View& view) {
  auto f = std::make_unique<Field>();
  SceneFileConfig config;
  config.expand_limit = 0;  // always instanced, as Embree sees it
  const auto t0 = Clock::now();
  SceneDescription d = parse_scene_json(field_json(count, subdivide, view), "field.json", config);
  f->scene.name = "field";
  f->scene.env = d.env;
  f->scene.hierarchy = build_hierarchy(std::move(d));
  f->our_build_s = seconds_since(t0);
  f->triangles = f->scene.info().primitives;
  RenderOptions oe;
  oe.lod = FullDetail{};
  oe.tracer = TracerKind::kEmbree;
  f->embree = make_tracer(f->scene, oe);
  return f;
}

// ---- renders ---------------------------------------------------------------------------------

struct Shot {
  std::vector<Vec3> image;
  double seconds = 0;
  double tests_per_ray = 0;
};

RenderOptions options(const RenderOptions& base, int spp, RendererKind kind, float footprint,
                      std::uint64_t seed = 0) {
  RenderOptions o = base;
  o.spp = spp;
  o.lod = kind == RendererKind::kTraditional ? LevelOfDetail{FullDetail{}}
                                             : LevelOfDetail{ByFootprint{footprint}};
  o.seed = seed;
  return o;
}

Shot ours(const Field& f, const RenderOptions& o) {
  RenderOutput r = render(f.scene, o);
  return {std::move(r.image), r.seconds, r.per_primary.mean()};
}

Shot embree(const Field& f, const RenderOptions& o) {
  RenderOptions oe = o;
  oe.tracer = TracerKind::kEmbree;
  RenderOutput r = f.embree->render(oe);
  return {std::move(r.image), r.seconds, 0.0};
}

/// Runs a and b `repeat` times, interleaved, and keeps each one's fastest time.
template <class A, class B>
std::pair<Shot, Shot> interleaved(int repeat, A&& a, B&& b) {
  Shot sa = a(), sb = b();
  for (int i = 1; i < repeat; ++i) {
    sa.seconds = std::min(sa.seconds, a().seconds);
    sb.seconds = std::min(sb.seconds, b().seconds);
  }
  return {std::move(sa), std::move(sb)};
}

std::vector<double> parse_list(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stod(item));
  return out;
}

int run(int argc, char** argv) {
  CLI::App app{"amalgam vs Embree on the instanced field: equal error, growth"};
  std::string out_dir = "bench/results/field", spps_s = "1,2,4,8,16", ks_s = "1,2,4,8,16";
  std::string counts_s = "17,170,1700,17000,170000", subdivs_s = "0,1,2,3,4";
  int width = 512, height = 384, ref_spp = 32, repeat = 2, threads = 0;
  bool quick = false;
  app.add_option("--out", out_dir, "folder for results.json, CSVs and images");
  app.add_option("--width", width);
  app.add_option("--height", height);
  app.add_option("--ref-spp", ref_spp, "samples per pixel of the reference");
  app.add_option("--spps", spps_s, "samples per pixel of the measured renders");
  app.add_option("--footprints", ks_s, "footprints K of the scale-sensitive renders");
  app.add_option("--counts", counts_s, "Wusons in the extent sweep");
  app.add_option("--subdivs", subdivs_s, "subdivisions in the detail sweep (17,000 Wusons)");
  app.add_option("--repeat", repeat, "runs per timed render (fastest kept)");
  app.add_option("--threads", threads, "threads (0: all cores)");
  app.add_flag("--quick", quick, "smoke run: tiny images, small fields");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    width = 64, height = 48, ref_spp = 4, repeat = 1;
    spps_s = "1,2", ks_s = "1,4", counts_s = "17,170", subdivs_s = "0";
  }
  std::filesystem::create_directories(out_dir);
  RenderOptions base;
  base.width = width;
  base.height = height;
  base.threads = threads;
  const std::vector<double> spps = parse_list(spps_s), ks = parse_list(ks_s);
  std::ofstream json(out_dir + "/results.json");
  json.precision(6);
  json << "{\n  \"width\": " << width << ", \"height\": " << height << ", \"ref_spp\": " << ref_spp
       << ", \"threads\": " << (threads > 0 ? threads : tbb::this_task_arena::max_concurrency())
       << ",\n";

  // Part 1: equal error on the field of scenes/field.json (17,000 Wusons, subdivided twice),
  // from each view.
  struct Row {
    double spp, k, rmse, seconds, tests;
  };
  json << "  \"equal_error\": {";
  for (const View& view : kViews) {
    const long count = quick ? 170 : 17000;
    auto f = make_field(count, 2, view);
    std::fprintf(stderr, "%s: %.0f triangles, build ours %.2f s, embree %.2f s\n", view.name,
                 f->triangles, f->our_build_s, f->embree->build_seconds());
    const std::string prefix = out_dir + "/" + view.name + "-";
    const Shot ref = ours(*f, options(base, ref_spp, RendererKind::kTraditional, 1, 9001));
    write_image(prefix + "reference.png", width, height, ref.image);
    // The Embree render is amalgam's traditional one sample for sample: check it.
    // Also our traditional renderer's time at 1 spp against Embree's through the same
    // integrator (the same rays), interleaved, the best of `repeat` runs each.
    const RenderOptions ot = options(base, 1, RendererKind::kTraditional, 1);
    const auto [trad1, embree1] = interleaved(
        repeat, [&] { return ours(*f, ot); }, [&] { return embree(*f, ot); });
    std::vector<Row> e_rows, a_rows;
    double same_rmse = 0;
    for (double spp : spps) {
      const RenderOptions oe = options(base, static_cast<int>(spp), RendererKind::kTraditional, 1);
      Shot e = embree(*f, oe);
      for (int i = 1; i < repeat; ++i) e.seconds = std::min(e.seconds, embree(*f, oe).seconds);
      if (spp == 1) same_rmse = rmse(e.image, trad1.image);
      e_rows.push_back({spp, 0, rmse(e.image, ref.image), e.seconds, 0});
      std::fprintf(stderr, "%s: embree spp %g: rmse %.5f, %.3f s\n", view.name, spp,
                   e_rows.back().rmse, e.seconds);
      if (spp == spps.front()) write_image(prefix + "embree.png", width, height, e.image);
      for (double k : ks) {
        const RenderOptions oa = options(base, static_cast<int>(spp), RendererKind::kScaleSensitive,
                                         static_cast<float>(k));
        Shot a = ours(*f, oa);
        for (int i = 1; i < repeat; ++i) a.seconds = std::min(a.seconds, ours(*f, oa).seconds);
        a_rows.push_back({spp, k, rmse(a.image, ref.image), a.seconds, a.tests_per_ray});
        std::fprintf(stderr, "%s: amalgam K %g spp %g: rmse %.5f, %.3f s\n", view.name, k, spp,
                     a_rows.back().rmse, a.seconds);
        if (spp == spps.front() && k == ks.front())
          write_image(prefix + "amalgam.png", width, height, a.image);
      }
    }
    // Embree's time at amalgam's error: log-log interpolation along its spp curve.
    auto embree_time_at = [&](double err, bool& floor) {
      floor = false;
      if (err >= e_rows.front().rmse) {
        floor = true;
        return e_rows.front().seconds;
      }
      for (std::size_t i = 1; i < e_rows.size(); ++i) {
        const Row &lo = e_rows[i - 1], &hi = e_rows[i];
        if (err >= hi.rmse) {
          const double w = std::log(err / lo.rmse) / std::log(hi.rmse / lo.rmse);
          return std::exp(std::log(lo.seconds) + w * std::log(hi.seconds / lo.seconds));
        }
      }
      return std::numeric_limits<double>::quiet_NaN();  // below Embree's best measured error
    };
    json << (&view == kViews ? "\n" : ",\n") << "   \"" << view.name
         << "\": {\"triangles\": " << f->triangles
         << ", \"embree_vs_traditional_rmse\": " << same_rmse
         << ", \"traditional_1spp_seconds\": " << trad1.seconds
         << ", \"embree_1spp_seconds\": " << embree1.seconds << ",\n    \"embree\": [";
    for (std::size_t i = 0; i < e_rows.size(); ++i)
      json << (i ? ", " : "") << "{\"spp\": " << e_rows[i].spp << ", \"rmse\": " << e_rows[i].rmse
           << ", \"seconds\": " << e_rows[i].seconds << "}";
    json << "],\n    \"amalgam\": [";
    for (std::size_t i = 0; i < a_rows.size(); ++i) {
      bool floor = false;
      const double te = embree_time_at(a_rows[i].rmse, floor);
      json << (i ? ",\n      " : "") << "{\"spp\": " << a_rows[i].spp
           << ", \"footprint\": " << a_rows[i].k << ", \"rmse\": " << a_rows[i].rmse
           << ", \"seconds\": " << a_rows[i].seconds << ", \"tests_per_ray\": " << a_rows[i].tests
           << ", \"embree_seconds_at_equal_error\": ";
      if (std::isnan(te))
        json << "null";
      else
        json << te;
      json << ", \"embree_floor\": " << (floor ? "true" : "false") << "}";
    }
    json << "]}";
  }
  json << "},\n";

  // Part 2: time per primary ray (with its shadow ray) as the field grows.
  auto sweep = [&](const char* name, const View& view,
                   const std::vector<std::pair<long, int>>& fields) {
    json << "  \"" << name << "\": [";
    bool first = true;
    for (auto [count, sub] : fields) {
      auto f = make_field(count, sub, view);
      const RenderOptions oa = options(base, 1, RendererKind::kScaleSensitive, 1);
      const RenderOptions oe = options(base, 1, RendererKind::kTraditional, 1);
      auto [a, e] = interleaved(
          repeat, [&] { return ours(*f, oa); }, [&] { return embree(*f, oe); });
      const double rays = static_cast<double>(width) * height;
      std::fprintf(stderr,
                   "%s: %ld wusons x subdivide %d = %.3g triangles: amalgam %.3f us/ray "
                   "(%.1f tests), embree %.3f us/ray; build ours %.2f s, embree %.2f s\n",
                   name, count, sub, f->triangles, 1e6 * a.seconds / rays, a.tests_per_ray,
                   1e6 * e.seconds / rays, f->our_build_s, f->embree->build_seconds());
      json << (first ? "\n    " : ",\n    ") << "{\"instances\": " << count
           << ", \"subdivide\": " << sub << ", \"triangles\": " << f->triangles
           << ", \"amalgam_us_per_ray\": " << 1e6 * a.seconds / rays
           << ", \"amalgam_tests_per_ray\": " << a.tests_per_ray
           << ", \"embree_us_per_ray\": " << 1e6 * e.seconds / rays
           << ", \"amalgam_build_s\": " << f->our_build_s
           << ", \"embree_build_s\": " << f->embree->build_seconds() << "}";
      first = false;
    }
    json << "]";
  };
  std::vector<std::pair<long, int>> extent, detail;
  for (double c : parse_list(counts_s)) extent.emplace_back(static_cast<long>(c), 2);
  for (double s : parse_list(subdivs_s))
    detail.emplace_back(quick ? 170 : 17000, static_cast<int>(s));
  sweep("extent_street", kViews[0], extent);
  json << ",\n";
  sweep("detail_street", kViews[0], detail);
  json << ",\n";
  sweep("detail_aerial", kViews[1], detail);
  json << "\n}\n";
  return 0;
}

}  // namespace
}  // namespace amalgam

int main(int argc, char** argv) {
  try {
    return amalgam::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "field_bench: %s\n", e.what());
    return 1;
  }
}

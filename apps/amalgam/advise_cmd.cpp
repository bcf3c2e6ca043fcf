// `amalgam advise SCENE`: should I use amalgams on this scene and view? Renders full detail,
// Embree (where built) and the level-of-detail renderers for the same render time, measures
// each image's error against a converged full-detail estimate, and prints error x time of each
// relative to full detail (docs/cli.md, "advise").

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "amalgam/io/legend.h"
#include "amalgam/io/render_outputs.h"
#include "amalgam/render/tracer.h"
#include "amalgam/util/atomic_file.h"
#include "amalgam/util/error.h"
#include "common.h"
#include "render_setup.h"

namespace amalgam::cli {
namespace {

/// One renderer advise compares.
struct Candidate {
  std::string name;  ///< as the table and the strip name it
  std::string key;   ///< as the JSON and --keep name it
  RenderOptions options;
};

struct Measured {
  Candidate c;
  RenderOutput out;
  double setup_s = 0;  ///< what this renderer needs beyond reading the scene
  double rmse = 0;
  double efficiency = 0;  ///< 1 / (MSE x render seconds), relative to full detail
};

double mse(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double d = static_cast<double>(a[i][k]) - b[i][k];
      s += d * d;
    }
  return s / (3.0 * static_cast<double>(a.size()));
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::vector<Candidate> candidates(const RenderOptions& base) {
  std::vector<Candidate> out;
  RenderOptions o = base;
  o.lod = FullDetail{};
  out.push_back({"full detail", "traditional", o});
  if (have_embree()) {
    o.tracer = TracerKind::kEmbree;
    out.push_back({"Embree, full detail", "embree", o});
    o.tracer = TracerKind::kAmalgam;
  }
  for (float k : {1.0f, 4.0f}) {
    o.lod = ByFootprint{k};
    o.opacity = OpacityKind::kStochastic;
    out.push_back({"amalgams K=" + fixed(k, 0) + ", stochastic",
                   "scale-sensitive-k" + fixed(k, 0) + "-stochastic", o});
  }
  o.lod = ByFootprint{1.0f};
  o.opacity = OpacityKind::kComposite;
  out.push_back({"amalgams K=1, composite", "scale-sensitive-k1-composite", o});
  return out;
}

/// Render seconds per sample of `tracer` at `o`'s size: the mean of an 8-sample render (half
/// the default budget for full detail: shorter pilots misjudge by 20-30 % at 320x240).
double seconds_per_sample(const Tracer& tracer, RenderOptions o) {
  o.spp = 8;
  return tracer.render(o).seconds / 8;
}

// --- the strip -------------------------------------------------------------------------------

constexpr int kGap = 4;

/// Copies a picture of w x h pixels into the canvas at (x0, y0).
void paste(Canvas& c, const std::vector<Vec3>& px, int w, int h, int x0, int y0) {
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) c.at(x0 + x, y0 + y) = px[static_cast<std::size_t>(y) * w + x];
}

/// Columns: the reference, then each renderer. Rows: the image with its name and figures,
/// the cost per sample on one log scale, the level rendered; legends for both below.
Canvas strip(const RenderOutput& ref, const std::vector<Measured>& ms, int max_level, int ref_spp) {
  const int w = ref.width, h = ref.height, cols = static_cast<int>(ms.size()) + 1;
  const int scale = w >= 320 ? 2 : 1;
  const int line = text_height(scale) + 4 * scale;
  Canvas c;
  c.width = cols * w + (cols - 1) * kGap;
  const int image_y = line, caption_y = image_y + h, cost_y = caption_y + 2 * line,
            level_y = cost_y + h + kGap;
  c.height = level_y + h;
  c.pixels.assign(static_cast<std::size_t>(c.width) * c.height, Vec3{});
  std::vector<double> all;
  for (const Measured& m : ms)
    if (m.c.options.tracer == TracerKind::kAmalgam)
      all.insert(all.end(), m.out.cost.begin(), m.out.cost.end());
  const LogRange range = own_range(all);
  const Vec3 white{1, 1, 1};
  auto column = [&](int j, const std::string& title, const RenderOutput& r,
                    const std::string& line1, const std::string& line2, bool counted, bool levels) {
    const int x0 = j * (w + kGap);
    draw_text(c, x0, 2 * scale, title, scale, white);
    paste(c, r.image, w, h, x0, image_y);
    draw_text(c, x0, caption_y + 2 * scale, line1, scale, white);
    draw_text(c, x0, caption_y + line + 2 * scale, line2, scale, white);
    if (counted)
      paste(c, log_colours(r.cost, range), w, h, x0, cost_y);
    else
      draw_text(c, x0 + 2, cost_y + h / 2, "tests not counted", scale, white);
    if (levels)
      paste(c, level_colours(r, max_level), w, h, x0, level_y);
    else
      draw_text(c, x0 + 2, level_y + h / 2, "no amalgam rendered", scale, white);
  };
  column(0, "reference", ref, "full detail, " + std::to_string(ref_spp) + " spp", "", true, false);
  for (std::size_t j = 0; j < ms.size(); ++j) {
    const Measured& m = ms[j];
    const bool counted = m.c.options.tracer == TracerKind::kAmalgam;
    column(static_cast<int>(j) + 1, m.c.name, m.out,
           std::to_string(m.out.spp) + " spp, " + fixed(m.out.seconds, 2) + " s",
           "RMSE " + fixed(m.rmse, 4) + ", " + fixed(m.efficiency, 2) + "x", counted,
           m.c.options.renderer() == RendererKind::kScaleSensitive);
  }
  // The legends: the cost bar across the strip, then the levels.
  int bar_h = 0;
  Canvas legend{c.width, 0, with_colour_bar({}, c.width, 0, range, bar_h)};
  legend.height = bar_h;
  append_labels(legend, log_bar_labels(range, c.width),
                "middle row: intersection tests per sample, log scale", "tests/sample (log)");
  const Canvas levels =
      with_level_legend({}, c.width, 0, max_level, kLevelPrimitiveColour, kLevelNothingColour);
  for (const Canvas* part : std::initializer_list<const Canvas*>{&legend, &levels}) {
    const int y0 = c.height;
    c.height += part->height;
    c.pixels.resize(static_cast<std::size_t>(c.width) * c.height, Vec3{});
    paste(c, part->pixels, part->width, part->height, 0, y0);
  }
  return c;
}

/// The files advise writes: the strip, the table and, with --keep, every render and the
/// reference (named by candidate key).
std::vector<OutputFile> advise_outputs(const AdviseOptions& a, const RenderOptions& base) {
  std::vector<OutputFile> outs{{"--out", a.out}, {"--json", a.json}};
  if (!a.keep.empty()) {
    const std::filesystem::path dir(a.keep);
    outs.push_back({"--keep", (dir / "reference.pfm").string()});
    for (const Candidate& c : candidates(base))
      outs.push_back({"--keep", (dir / (c.key + ".pfm")).string()});
  }
  return outs;
}

/// Refuses, before any work, outputs that cannot be written, that are one file twice or the
/// scene file, and a film larger than the machine's memory; creates --keep's directory (so
/// that one that cannot be created fails now, not after every render).
void check_advise_outputs(const AdviseOptions& a, const CommonOptions& common) {
  if (!a.out.empty() && !is_png_path(a.out))
    throw InputError("--out " + a.out + ": the strip is a PNG (.png)");
  RenderOptions film = common.options;
  film.width = a.width, film.height = a.height;
  const std::size_t films = 1 + candidates(common.options).size();  // all held at once
  const double bytes = static_cast<double>(film_bytes(film)) * static_cast<double>(films);
  if (bytes > static_cast<double>(physical_memory()))
    throw InputError("--width " + std::to_string(a.width) + " --height " +
                     std::to_string(a.height) + ": the " + std::to_string(films) +
                     " films held at once need " + format_bytes(bytes) +
                     ", more than this machine's memory");
  check_files({{"--out", a.out}, {"--json", a.json}}, common.scene);
  if (!a.keep.empty())
    make_output_dir("--keep", a.keep, advise_outputs(a, common.options), common.scene);
}

/// Each candidate rendered for `budget` seconds of rendering, its RMSE against `ref`, and
/// full detail's MSE x time over its own.
std::vector<Measured> measure(const LoadedScene& scene, const RenderOptions& base,
                              const RenderOutput& ref, double budget) {
  std::vector<Measured> ms;
  for (const Candidate& c : candidates(base)) {
    set_activity("rendering with " + c.name);
    const std::unique_ptr<Tracer> tracer = make_tracer(scene, c.options);
    Measured m{c, {}, 0, 0, 0};
    m.setup_s = scene.build_seconds + tracer->build_seconds() +
                (c.options.renderer() == RendererKind::kTraditional ? 0.0 : scene.bake_seconds);
    const double per_sample = seconds_per_sample(*tracer, c.options);
    m.c.options.spp =
        static_cast<int>(std::clamp(std::floor(budget / std::max(per_sample, 1e-9)), 1.0, 65536.0));
    m.out = tracer->render(m.c.options);
    m.rmse = std::sqrt(mse(m.out.image, ref.image));
    ms.push_back(std::move(m));
  }
  // Error x time relative to full detail: above 1, lower error in the same time.
  const double base_cost = ms[0].rmse * ms[0].rmse * ms[0].out.seconds;
  for (Measured& m : ms) m.efficiency = base_cost / (m.rmse * m.rmse * m.out.seconds);
  return ms;
}

/// The table and the verdict; returns the best level-of-detail renderer.
const Measured& report(std::ostream& log, const std::vector<Measured>& ms, double budget,
                       const AdviseOptions& a) {
  log << "time per renderer: " << fixed(budget, 3) << " s of rendering; " << a.width << "x"
      << a.height << ", stratified\n\n";
  char row[256];
  std::snprintf(row, sizeof row, "%-30s %6s %9s %9s %10s %9s %12s\n", "renderer", "spp", "render s",
                "setup s", "tests/ray", "RMSE", "vs full det.");
  log << row;
  for (const Measured& m : ms) {
    const std::string tests = m.c.options.tracer == TracerKind::kAmalgam
                                  ? fixed(m.out.per_primary.mean(), 1)
                                  : std::string("-");
    std::snprintf(row, sizeof row, "%-30s %6d %9.3f %9.3f %10s %9.5f %11.2fx\n", m.c.name.c_str(),
                  m.out.spp, m.out.seconds, m.setup_s, tests.c_str(), m.rmse, m.efficiency);
    log << row;
  }
  const auto best =
      std::max_element(ms.begin(), ms.end(), [](const Measured& x, const Measured& y) {
        const bool ax = x.c.options.renderer() == RendererKind::kScaleSensitive;
        const bool ay = y.c.options.renderer() == RendererKind::kScaleSensitive;
        return ax != ay ? ay : x.efficiency < y.efficiency;
      });
  log << "\n\"vs full det.\": full detail's MSE x time over this renderer's (above 1: lower "
         "error in the same time).\n";
  const double e = best->efficiency;
  log << (e > 1.1   ? "Amalgams pay off on this view: "
          : e < 0.9 ? "Amalgams do not pay off on this view: "
                    : "Amalgams about break even on this view: ")
      << "the best, " << best->c.name << ", has " << fixed(e, 2)
      << "x full detail's error-per-time";
  if (have_embree()) log << " (Embree: " << fixed(ms[1].efficiency, 2) << "x)";
  log << ".\n";
  return *best;
}

/// Every image and the reference as PFM in --keep's directory, named by key.
void keep_images(const AdviseOptions& a, const RenderOutput& ref, const std::vector<Measured>& ms) {
  std::filesystem::create_directories(a.keep);
  write_image((std::filesystem::path(a.keep) / "reference.pfm").string(), ref.width, ref.height,
              ref.image);
  for (const Measured& m : ms)
    write_image((std::filesystem::path(a.keep) / (m.c.key + ".pfm")).string(), m.out.width,
                m.out.height, m.out.image);
}

/// The table as JSON (--json FILE or -).
void write_json(const AdviseOptions& a, const std::string& scene, double budget,
                const RenderOutput& ref, const std::vector<Measured>& ms, const Measured& best) {
  nlohmann::ordered_json j;
  j["scene"] = scene;
  j["width"] = a.width, j["height"] = a.height;
  j["render_seconds_each"] = budget;
  j["reference"] = {{"spp", a.reference_spp}, {"seconds", ref.seconds}};
  for (const Measured& m : ms) {
    nlohmann::ordered_json r;
    r["name"] = m.c.name;
    r["key"] = m.c.key;
    r["spp"] = m.out.spp;
    r["render_seconds"] = m.out.seconds;
    r["setup_seconds"] = m.setup_s;
    if (m.c.options.tracer == TracerKind::kAmalgam)
      r["tests_per_primary_ray"] = m.out.per_primary.mean();
    r["rmse"] = m.rmse;
    r["vs_full_detail"] = m.efficiency;
    j["renderers"].push_back(r);
  }
  j["best_level_of_detail"] = best.c.key;
  if (a.json == "-")
    std::cout << j.dump(2) << "\n";
  else
    write_file_atomic(a.json, j.dump(2) + "\n");
}

}  // namespace

int run_advise(CommonOptions& common, const AdviseOptions& a) {
  common.finish();
  check_advise_outputs(a, common);
  set_activity("loading and building " + common.scene);
  SceneFileConfig config;
  config.smooth_normals = common.smooth_normals;
  LoadedScene scene = load_scene(common.scene, common.params(), config);
  check_files_spare_inputs(advise_outputs(a, common.options), scene);
  common.prepare(scene);
  print_warnings(scene);

  RenderOptions base = common.options;
  base.width = a.width, base.height = a.height;
  base.sampler = PixelSampler::kStratified;
  std::ostream& log = a.json == "-" ? std::cerr : std::cout;

  set_activity("rendering the reference");
  RenderOptions ref_options = base;
  ref_options.lod = FullDetail{};
  ref_options.spp = a.reference_spp;
  ref_options.seed = base.seed ^ 0x9e3779b97f4a7c15ULL;  // its own samples
  const std::unique_ptr<Tracer> full = make_tracer(scene, ref_options);
  const RenderOutput ref = full->render(ref_options);
  log << "reference: full detail, " << a.reference_spp << " spp (stratified), "
      << fixed(ref.seconds, 2) << " s\n";
  double budget = a.seconds;
  if (budget <= 0) {
    RenderOptions o = base;
    o.lod = FullDetail{}, o.spp = 16;
    budget = full->render(o).seconds;
  }

  const std::vector<Measured> ms = measure(scene, base, ref, budget);
  const Measured& best = report(log, ms, budget, a);
  if (!a.keep.empty()) keep_images(a, ref, ms);
  if (!a.out.empty()) {
    const Canvas c = strip(ref, ms, scene.info().levels - 1, a.reference_spp);
    write_image(a.out, c.width, c.height, c.pixels);
    log << "strip: " << a.out << "\n";
  }
  if (!a.json.empty()) write_json(a, common.scene, budget, ref, ms, best);
  return 0;
}

}  // namespace amalgam::cli

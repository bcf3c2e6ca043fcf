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

#include "advise.h"
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

using advise::Candidate;
using advise::Measured;

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

/// Renders under this many seconds each are timed too coarsely to compare (the default time
/// is at least this).
constexpr double kMinSeconds = 0.5;

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
           std::to_string(m.out.spp) + " spp, " + fixed(m.seconds(), 2) + " s",
           "RMSE " + fixed(m.rmse(), 4) + ", " + fixed(m.vs_full.value, 2) + "x", counted,
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
    for (const Candidate& c : advise::candidates(base))
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
  const std::size_t films = 1 + advise::candidates(common.options).size();  // all held at once
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

/// Every image and the reference as PFM in --keep's directory, named by key.
void keep_images(const AdviseOptions& a, const RenderOutput& ref, const std::vector<Measured>& ms) {
  std::filesystem::create_directories(a.keep);
  write_image((std::filesystem::path(a.keep) / "reference.pfm").string(), ref.width, ref.height,
              ref.image);
  for (const Measured& m : ms)
    write_image((std::filesystem::path(a.keep) / (m.c.key + ".pfm")).string(), m.out.width,
                m.out.height, m.out.image);
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
  const double scene_bytes = resident_bytes();
  advise::Scenes scenes{&scene, nullptr, 0};
  if (!scene.inputs.empty()) {  // a scene file or mesh: its objects for the volumetric renderer
    set_activity("loading the objects of " + common.scene + " for the volumetric renderer");
    config.objects = true, config.amalgams = false;
    auto objects = std::make_shared<LoadedScene>(load_scene(common.scene, common.params(), config));
    common.prepare(*objects);
    scenes.objects_bytes = std::max(0.0, resident_bytes() - scene_bytes);
    if (objects->volumes) scenes.objects = std::move(objects);
  }

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
  if (!scenes.objects) log << "volumetric cells: not compared (the scene has no meshes)\n";
  double budget = a.seconds;
  if (budget <= 0) {
    RenderOptions o = base;
    o.lod = FullDetail{}, o.spp = 16;
    budget = std::max(full->render(o).seconds, kMinSeconds);
  }

  const std::vector<Measured> ms = advise::measure(scenes, base, ref, budget, a.repeats);
  const advise::Verdict v = advise::judge(ms);
  advise::report(log, ms, v, budget, a.repeats, a);
  if (!a.keep.empty()) keep_images(a, ref, ms);
  if (!a.out.empty()) {
    const Canvas c = strip(ref, ms, scene.info().levels - 1, a.reference_spp);
    write_image(a.out, c.width, c.height, c.pixels);
    log << "strip: " << a.out << "\n";
  }
  if (!a.json.empty())
    advise::write_json(a, common.scene, budget, a.repeats, ref, ms, v, scene_bytes);
  return 0;
}

}  // namespace amalgam::cli

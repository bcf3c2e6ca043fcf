#include "quality_measure.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "amalgam/analysis/metrics.h"
#include "amalgam/io/image.h"
#include "amalgam/render/passes.h"
#include "amalgam/render/tracer.h"
#include "amalgam/util/atomic_file.h"
#include "oracle.h"

namespace amalgam::quality {

using nlohmann::json;

void apply_view(Camera& c, const std::string& view) {
  if (view == "street" || view == "scene") return;  // the scene file's own camera
  if (view == "aerial") {
    c.position = {0, 260, 420};
    c.look_at = {0, 0, 0};
    c.up = {0, 1, 0};
    c.vfov_deg = 40;
    return;
  }
  throw InputError("--view " + view + ": expected street (the scene's camera) or aerial");
}

LoadedScene load(const Args& a) {
  SceneFileConfig config;
  config.expand_limit = 0;  // always instanced, as Embree sees it
  LoadedScene s = load_scene_path(a.scene, config);
  apply_view(s.env.camera, a.view);
  return s;
}

RenderOptions base_options(const Args& a) {
  RenderOptions o;
  o.width = a.width, o.height = a.height, o.threads = a.threads;
  o.sampler = PixelSampler::kStratified;
  o.opacity = OpacityKind::kStochastic;
  return o;
}

Reference reference(const Args& a) {
  LoadedScene s = load(a);
  std::ostringstream key;
  key << std::hex << content_hash(s) << std::dec << "-" << a.width << "x" << a.height << "-max"
      << a.ref_max_spp << "-se" << a.ref_se << "-b" << a.ref_batches << "-v2";
  std::filesystem::create_directories(a.cache);
  const std::string img_path = a.cache + "/ref-" + key.str() + ".pfm";
  const std::string meta_path = a.cache + "/ref-" + key.str() + ".json";
  Reference ref;
  if (std::filesystem::exists(img_path) && std::filesystem::exists(meta_path)) {
    int w = 0, h = 0;
    ref.image = read_image(img_path, w, h);
    const json m = json::parse(std::ifstream(meta_path));
    ref.spp = m.at("spp"), ref.se = m.at("se"), ref.seconds = m.at("seconds");
    ref.var = m.at("var");
    ref.cached = true;
    return ref;
  }
  const auto t0 = Clock::now();
  const int batches = std::max(2, a.ref_batches);
  std::vector<FilmState> states(batches);
  RenderOptions o = base_options(a);
  o.lod = FullDetail{};
  const std::size_t n = static_cast<std::size_t>(a.width) * a.height;
  for (int each = std::min(16, std::max(1, a.ref_max_spp / batches));; each *= 2) {
    each = std::min(each, std::max(1, a.ref_max_spp / batches));
    std::vector<std::vector<Vec3>> means;
    for (int b = 0; b < batches; ++b) {
      o.seed = 9001 + static_cast<std::uint64_t>(b), o.spp = each;
      means.push_back(render(s, o, &states[b]).image);
    }
    ref.image.assign(n, Vec3{});
    for (const auto& m : means)
      for (std::size_t i = 0; i < n; ++i) ref.image[i] += m[i] / static_cast<float>(batches);
    double se_sum = 0, var_sum = 0;  // per pixel: RMS over channels of the standard error
    for (std::size_t i = 0; i < n; ++i) {
      double var = 0;
      for (const auto& m : means)
        for (int c = 0; c < 3; ++c) var += std::pow(double(m[i][c]) - ref.image[i][c], 2);
      var /= 3.0 * (batches - 1);
      se_sum += std::sqrt(var / batches), var_sum += var / batches;
    }
    ref.se = se_sum / static_cast<double>(n), ref.var = var_sum / static_cast<double>(n);
    ref.spp = each * batches;
    std::fprintf(stderr, "reference: %d spp, mean standard error %.5f (%.1f s)\n", ref.spp, ref.se,
                 since(t0));
    if (ref.se < a.ref_se || each * batches * 2 > a.ref_max_spp) break;
  }
  ref.seconds = since(t0);
  write_image(img_path, a.width, a.height, ref.image);
  write_file_atomic(
      meta_path,
      json{{"spp", ref.spp}, {"se", ref.se}, {"var", ref.var}, {"seconds", ref.seconds}}.dump());
  return ref;
}

Errors errors(const std::vector<std::vector<Vec3>>& runs, const std::vector<Vec3>& ref,
              double ref_var, int w, int h) {
  const std::size_t n = ref.size();
  const double k = static_cast<double>(runs.size());
  std::vector<Vec3> mean(n, Vec3{});
  for (const auto& r : runs)
    for (std::size_t i = 0; i < n; ++i) mean[i] += r[i] / static_cast<float>(k);
  Errors e;
  double mse = 0, var = 0, rel = 0, mean_mse = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const double r = ref[i][c], m = mean[i][c];
      mean_mse += (m - r) * (m - r);
      for (const auto& img : runs) {
        const double x = img[i][c];
        mse += (x - r) * (x - r);
        rel += (x - r) * (x - r) / (r * r + 0.01);
        var += (x - m) * (x - m);
      }
    }
  const double cells = 3.0 * static_cast<double>(n);
  mse /= cells * k, rel /= cells * k, mean_mse /= cells;
  var = runs.size() > 1 ? var / (cells * (k - 1)) : 0.0;  // unbiased per-sample variance
  e.rmse = std::sqrt(mse);
  e.relmse = rel;
  e.stddev = std::sqrt(var);
  // E|mean - ref|^2 = bias^2 + var / k + the reference's own variance.
  e.bias = std::sqrt(std::max(0.0, mean_mse - var / k - ref_var));
  e.tiles_x = (w + 31) / 32, e.tiles_y = (h + 31) / 32;
  int within = 0;
  for (int ty = 0; ty < e.tiles_y; ++ty)
    for (int tx = 0; tx < e.tiles_x; ++tx) {
      double lm = 0, lr = 0;
      for (int y = ty * 32; y < std::min(h, ty * 32 + 32); ++y)
        for (int x = tx * 32; x < std::min(w, tx * 32 + 32); ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * w + x;
          lm += luminance(mean[i]), lr += luminance(ref[i]);
        }
      const double b = (lm - lr) / std::max(lr, 1e-9);
      e.tiles.push_back(b);
      if (std::fabs(b) <= 0.03) ++within;
      if (std::fabs(b) > std::fabs(e.tile_worst)) e.tile_worst = b;
    }
  e.tile_within = within / static_cast<double>(e.tiles.size());
  return e;
}

Run run_once(const Args& a, const std::string& kind, float k, int spp, std::uint64_t seed) {
  LoadedScene s = load(a);
  RenderOptions o = base_options(a);
  o.spp = spp, o.seed = seed;
  if (k > 0) o.lod = ByFootprint{k};
  if (kind == "scale-sensitive") o.opacity = *parse_opacity(a.opacity);
  if (a.light_samples > 0) {
    CameraChoice samples;  // the view as loaded, with --light-samples
    samples.light_samples = a.light_samples;
    s.env = chosen_view(s, samples);
  }
  Run r;
  if (kind == "embree") {
    o.lod = FullDetail{};
    o.tracer = TracerKind::kEmbree;
    // Embree's default configuration: RTC_BUILD_QUALITY_MEDIUM, RTC_SCENE_FLAG_NONE.
    const std::unique_ptr<Tracer> embree =
        make_tracer(s, o, {EmbreeBuild::Quality::kMedium, /*robust=*/false});
    RenderOutput out = embree->render(o);
    r.image = std::move(out.image);
    r.render = out.seconds;
    r.fixed = s.load_seconds + embree->build_seconds();
    return r;
  }
  if (kind == "traditional") o.lod = FullDetail{};
  RenderOutput out = render(s, o);
  r.image = std::move(out.image);
  r.render = out.seconds;
  r.fixed = s.load_seconds + s.build_seconds;
  r.tests = out.per_primary.mean();
  return r;
}

std::vector<Vec3> run_oracle(const LoadedScene& s, const Args& a, float k, bool box,
                             std::uint64_t seed, double& in_amalgam) {
  const auto& h = std::get<InstancedHierarchy>(s.hierarchy);
  RenderOptions o = base_options(a);
  o.spp = a.oracle_spp, o.seed = seed;
  FilmState st;
  st.width = o.width, st.height = o.height;
  st.sum.assign(static_cast<std::size_t>(o.width) * o.height, Vec3{});
  st.tests.assign(st.sum.size(), 0);
  std::atomic<std::uint64_t> count{0};
  render_passes(s.env.camera, o, st, RenderControl{}, [&](Counters& c) {
    return OracleIntegrator<InstancedHierarchy>(h, s.env, k, a.oracle_rays, box, c, count);
  });
  in_amalgam = static_cast<double>(count.load()) / (static_cast<double>(st.sum.size()) * o.spp);
  return finish(st).image;
}

}  // namespace amalgam::quality

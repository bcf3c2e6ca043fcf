#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/io/checkpoint.h"
#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "amalgam/io/scene_json.h"
#include "amalgam/io/stats_json.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/util/atomic_file.h"
#include "common.h"
#include "progress.h"

namespace amalgam::cli {

namespace {

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};
std::atomic<int> g_signals{0};         ///< SIGINT/SIGTERM received
std::atomic<bool> g_finishing{false};  ///< the render is done: its outputs are being written

/// SIGINT/SIGTERM: the first stops the render at the next tile; the image so far and a
/// checkpoint are then written. Once the outputs are being written, finishing them wins: a
/// further signal is noted, and only a third in all ends the process at once, removing the
/// temporary being written (nothing half-written stays).
extern "C" void on_signal(int sig) {
  g_signal.store(sig);
  g_cancel.store(true);
  const int n = g_signals.fetch_add(1) + 1;
  if (g_finishing.load() && n >= 3) {
    remove_temporary_from_signal_handler();
    ::_exit(128 + sig);
  }
}

/// Everything that determines the image except spp and threads: the renderer options and the
/// scene as loaded (content_hash: its geometry, lights and camera, or a builtin's parameters
/// as applied). A checkpoint is only resumed under the same fingerprint.
std::string fingerprint(const CommonOptions& c, const LoadedScene& scene) {
  const RenderOptions& o = c.options;
  std::ostringstream f;
  f << c.scene << " (scene " << std::hex << content_hash(scene) << std::dec << ")"
    << " --renderer " << c.renderer << " --opacity " << c.opacity << " --order " << c.order
    << " --seed " << o.seed << " --width " << o.width << " --height " << o.height;
  if (o.level)
    f << " --level " << *o.level;
  else
    f << " --footprint " << o.footprint;
  // Only when not the default, so checkpoints written before the option existed still resume.
  if (o.sampler == PixelSampler::kStratified) f << " --sampler stratified";
  return f.str();
}

/// Checks every output path before any work: an image path must name a format we write, every
/// path must be writable, and no two outputs may be the same file. Throws InputError.
void check_outputs(const RenderExtras& e, const std::string& ckpt) {
  if (!is_image_path(e.out))
    throw InputError("--out " + e.out + ": unsupported image format (expected .png, .exr or .pfm)");
  if (!e.cost_image.empty() && !is_image_path(e.cost_image))
    throw InputError("--cost-image " + e.cost_image +
                     ": unsupported image format (expected .png, .exr or .pfm)");
  struct Output {
    const char* option;
    const std::string& path;
  };
  const Output outputs[] = {{"--out", e.out},
                            {"--cost-image", e.cost_image},
                            {"--stats", e.stats},
                            {"--checkpoint", ckpt}};
  std::vector<std::pair<std::string, const char*>> files;  // resolved regular files
  for (const Output& o : outputs) {
    if (o.path.empty()) continue;
    check_writable(o.path);
    const OutputTarget t = resolve_output(o.path);
    if (t.kind != OutputTarget::Kind::kFile) continue;  // devices and "-" may be shared
    const std::string key = std::filesystem::weakly_canonical(t.path).string();
    for (const auto& [other, option] : files)
      if (other == key)
        throw InputError(std::string(o.option) + " " + o.path + ": the same file as " + option);
    files.emplace_back(key, o.option);
  }
}

std::uint64_t physical_memory() {
  return static_cast<std::uint64_t>(sysconf(_SC_PHYS_PAGES)) *
         static_cast<std::uint64_t>(sysconf(_SC_PAGE_SIZE));
}

/// Bytes a render of these options needs beyond the scene: the process and the film (sums,
/// tests, image and cost per pixel; MemoryModel, hierarchy/build/build.h).
std::uint64_t film_bytes(const RenderOptions& o) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(o.width) * o.height;
  return MemoryModel::kProcess + pixels * MemoryModel::kPerPixel;
}

void write_cost_image(const std::string& path, const RenderOutput& r) {
  const std::string ext = path.substr(path.find_last_of('.') + 1);
  if (ext == "png" || ext == "PNG") {
    write_image(path, r.width, r.height, false_colour(r.cost, true));
    return;
  }
  std::vector<Vec3> raw(r.cost.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const auto v = static_cast<float>(r.cost[i]);
    raw[i] = {v, v, v};
  }
  write_image(path, r.width, r.height, raw);
}

}  // namespace

int run_render(CommonOptions& common, const RenderExtras& extra) {
  common.finish();
  const RenderOptions& o = common.options;
  const std::string ckpt = extra.checkpoint.empty() ? extra.out + ".ckpt" : extra.checkpoint;
  check_outputs(extra, ckpt);
  const std::uint64_t asked =
      extra.max_memory.empty() ? 0 : parse_bytes(extra.max_memory, "--max-memory");
  if (!extra.max_memory.empty() && asked == 0)
    throw InputError("--max-memory 0: expected a positive byte count");
  const std::uint64_t limit = asked ? asked : physical_memory();
  const std::uint64_t film = film_bytes(o);
  if (film > limit)
    throw InputError("--width " + std::to_string(o.width) + " --height " +
                     std::to_string(o.height) + ": the film needs " + format_bytes(film) +
                     ", more than --max-memory " + format_bytes(limit));
  set_activity("loading and building " + common.scene);
  PhaseStatus status(!extra.quiet);
  SceneFileConfig budget;  // checked before the scene is built (MemoryModel)
  budget.max_bytes = limit - film;
  budget.limit_name = "--max-memory " + format_bytes(static_cast<double>(limit)) + " less " +
                      format_bytes(static_cast<double>(film)) + " for the film";
  budget.on_phase = [&](const std::string& what) {
    set_activity(what);
    status.phase(what);
  };
  const LoadedScene scene = load_scene(common.scene, common.params(), budget);
  status.stop();
  check_options(scene, o);

  const std::string fp = fingerprint(common, scene);
  FilmState state;
  if (extra.resume) {
    if (!std::filesystem::exists(ckpt)) throw InputError(ckpt + ": no checkpoint to resume from");
    state = read_checkpoint(ckpt, fp);
    if (state.spp_done > o.spp)
      throw InputError(ckpt + ": checkpoint holds " + std::to_string(state.spp_done) +
                       " samples per pixel, more than --spp " + std::to_string(o.spp));
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  Progress progress(o.spp, !extra.quiet);
  auto last_checkpoint = std::chrono::steady_clock::now();
  RenderControl control;
  control.cancel = &g_cancel;
  control.on_pass = [&](const FilmState& st) {
    progress.update(st.spp_done);
    const auto now = std::chrono::steady_clock::now();
    if (st.spp_done < o.spp &&
        std::chrono::duration<double>(now - last_checkpoint).count() >= extra.checkpoint_every) {
      write_checkpoint(ckpt, fp, st);  // survives even a SIGKILL
      last_checkpoint = now;
    }
  };
  set_activity("rendering " + common.scene);
  RenderOutput r = render(scene, o, &state, control);
  progress.finish();
  set_activity("writing the outputs of " + common.scene);
  // The work is done: writing its results wins over further signals (on_signal).
  g_finishing.store(true);

  // Each output is written even when another fails; the ones missing are named at the end.
  std::vector<std::string> failed;
  auto attempt = [&](const std::string& what, auto&& write) {
    try {
      write();
    } catch (const std::exception& e) {
      std::cerr << "amalgam: " << e.what() << "\n";
      failed.push_back(what);
    }
  };
  if (r.spp > 0) {
    attempt(extra.out, [&] { write_image(extra.out, r.width, r.height, r.image); });
    if (!extra.cost_image.empty())
      attempt(extra.cost_image, [&] { write_cost_image(extra.cost_image, r); });
  }
  const std::string json =
      stats_json(scene, o, r.counters, r.per_primary, r.seconds).dump(2) + "\n";
  if (!extra.stats.empty()) attempt(extra.stats, [&] { write_file_atomic(extra.stats, json); });
  if (r.interrupted || !failed.empty()) attempt(ckpt, [&] { write_checkpoint(ckpt, fp, state); });
  if (!failed.empty()) {
    std::cerr << "amalgam: not written: ";
    for (std::size_t i = 0; i < failed.size(); ++i) std::cerr << (i ? ", " : "") << failed[i];
    std::cerr << "\n";
    return 1;
  }

  if (r.interrupted) {
    const int sig = g_signal.load();
    std::cerr << "amalgam: interrupted by " << (sig == SIGTERM ? "SIGTERM" : "SIGINT") << ": "
              << (r.spp > 0 ? extra.out : std::string("no image")) << " holds " << r.spp << " of "
              << o.spp << " samples per pixel; checkpoint " << ckpt
              << " (continue with the same command and --resume)\n";
    return 1;
  }
  std::error_code ec;
  std::filesystem::remove(ckpt, ec);  // complete: the checkpoint is no longer needed
  if (!extra.quiet)
    std::cerr << "amalgam: wrote " << extra.out << " (" << r.width << "x" << r.height << ", "
              << r.spp << " spp, " << r.seconds << " s, " << r.per_primary.mean()
              << " tests per primary ray)\n";
  return 0;
}

int run_trace(CommonOptions& common, const std::string& origin, const std::string& direction) {
  common.finish();
  set_activity("loading and building " + common.scene);
  const LoadedScene scene = load_scene(common.scene, common.params());
  check_options(scene, common.options);
  Ray ray = scene.env.camera.centre_ray(common.options.width, common.options.height);
  if (!origin.empty() || !direction.empty()) {
    const Vec3 o = origin.empty() ? ray.origin : parse_vec3(origin, "--origin");
    const Vec3 d = direction.empty() ? ray.dir : parse_vec3(direction, "--direction");
    if (length(d) == 0.0f) throw InputError("--direction: must not be the zero vector");
    const float spread = ray.cone_spread;
    ray = Ray::make(o, normalize(d));
    ray.cone_spread = spread;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const TraceOutput t = trace(scene, common.options, ray);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nlohmann::json j = stats_json(scene, common.options, t.counters, t.per_primary, secs);
  if (t.hit.kind == TraceHit::Kind::kNone) {
    j["hit"] = nullptr;
  } else {
    j["hit"] = {{"t", t.hit.t},
                {"object",
                 {{"kind", t.hit.kind == TraceHit::Kind::kPrimitive ? "primitive" : "amalgam"},
                  {"id", t.hit.id},
                  {"level", t.hit.level}}},
                {"point", {t.hit.surf.p.x, t.hit.surf.p.y, t.hit.surf.p.z}}};
  }
  j["colour"] = {t.colour.x, t.colour.y, t.colour.z};
  std::cout << j.dump(2) << "\n";
  return 0;
}

int run_scenes() {
  for (const BuiltinDoc& d : builtin_docs()) {
    std::cout << "builtin:" << d.name << "\n  " << d.summary << "\n";
    for (const std::string& p : d.params) std::cout << "    --set " << p << "\n";
  }
  std::cout << "\nEvery builtin also takes --set lights=K where listed.\n";
  return 0;
}

}  // namespace amalgam::cli

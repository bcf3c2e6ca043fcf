#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/io/checkpoint.h"
#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "amalgam/io/render_outputs.h"
#include "amalgam/io/scene_json.h"
#include "amalgam/io/stats_json.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/render/tracer.h"
#include "amalgam/util/atomic_file.h"
#include "amalgam/util/file_kind.h"
#include "amalgam/util/version.h"
#include "common.h"
#if defined(AMALGAM_HAVE_MPI)
#include "mpi_render.h"
#endif
#include "progress.h"

namespace amalgam::cli {

namespace {

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};
std::atomic<int> g_signals{0};  ///< stop signals received
/// The signals that stop a render and keep its work (on_signal).
constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
std::atomic<bool> g_finishing{false};  ///< the render is done: its outputs are being written

/// SIGINT, SIGTERM, SIGHUP, SIGQUIT: the first stops the render at the next tile; the image so far
/// and a checkpoint are then written. Once the outputs are being written, finishing them wins: a
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

/// "SIGINT", "SIGTERM", "SIGHUP" or "SIGQUIT".
const char* signal_name(int sig) {
  switch (sig) {
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    case SIGQUIT:
      return "SIGQUIT";
    default:
      return "SIGINT";
  }
}

/// The --footprint value of `lod` (1, the default, where there is none), as fingerprints and
/// the EXR header spell it.
float footprint_of(const LevelOfDetail& lod) {
  if (const auto* f = std::get_if<ByFootprint>(&lod)) return f->pixels;
  if (const auto* c = std::get_if<VolumetricCells>(&lod)) return c->cone_widths;
  return 1.0f;
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
  if (const auto* l = std::get_if<OnLevel>(&o.lod))
    f << " --level " << l->level;
  else
    f << " --footprint " << footprint_of(o.lod);
  if (o.tracer == TracerKind::kEmbree) f << " --tracer embree";  // amalgam's: as before
  // Only when not the default, so checkpoints written before the option existed still resume.
  if (o.sampler == PixelSampler::kStratified) f << " --sampler stratified";
  return f.str();
}

/// Checks every output path before any work: an image path must name a format we write, every
/// path must be writable, no two outputs may be the same file and none may be the scene file
/// (compared by file identity: device and inode, or the resolved path of a new file). Throws
/// InputError.
struct Output {
  const char* option;
  const std::string& path;
};

/// The files a render writes, by option (an empty path: not written).
std::array<Output, 5> outputs(const RenderExtras& e, const std::string& ckpt) {
  return {{{"--out", e.out},
           {"--cost-image", e.cost_image},
           {"--level-image", e.level_image},
           {"--stats", e.stats},
           {"--checkpoint", ckpt}}};
}

/// Once the scene is loaded, before anything is written: no output on a file it read (the
/// meshes a scene file names and the textures they name; the scene file itself was checked
/// before loading). Throws InputError.
void check_outputs_spare_inputs(const RenderExtras& e, const std::string& ckpt,
                                const LoadedScene& scene) {
  std::vector<std::pair<std::string, const std::string*>> inputs;  // by identity
  for (const std::string& in : scene.inputs) inputs.emplace_back(file_identity(in), &in);
  for (const Output& o : outputs(e, ckpt)) {
    if (o.path.empty() || resolve_output(o.path).kind != OutputTarget::Kind::kFile) continue;
    const std::string key = file_identity(o.path);
    for (const auto& [identity, path] : inputs)
      if (identity == key)
        throw InputError(std::string(o.option) + " " + o.path + ": " + *path +
                         ", which the scene " + scene.name +
                         " reads (an output never replaces an input)");
  }
}

void check_outputs(const RenderExtras& e, const std::string& ckpt, const RenderOptions& ro,
                   const std::string& scene) {
  if (!e.cost_image.empty() && ro.tracer == TracerKind::kEmbree)
    throw InputError("--cost-image " + e.cost_image +
                     ": --tracer embree counts no intersection tests (no cost image)");
  if (!is_image_path(e.out))
    throw InputError("--out " + e.out + ": unsupported image format (expected .png, .exr or .pfm)");
  if (!e.cost_image.empty() && !is_image_path(e.cost_image))
    throw InputError("--cost-image " + e.cost_image +
                     ": unsupported image format (expected .png, .exr or .pfm)");
  if (!e.level_image.empty() && !is_image_path(e.level_image))
    throw InputError("--level-image " + e.level_image +
                     ": unsupported image format (expected .png, .exr or .pfm)");
  std::error_code ec;
  const bool scene_file = scene.rfind("builtin:", 0) != 0 && std::filesystem::exists(scene, ec);
  const std::string input = scene_file ? file_identity(scene) : std::string();
  std::vector<std::pair<std::string, const char*>> files;  // regular files, by identity
  for (const Output& o : outputs(e, ckpt)) {
    if (o.path.empty()) continue;
    check_writable(o.path);
    const OutputTarget t = resolve_output(o.path);
    if (t.kind != OutputTarget::Kind::kFile) continue;  // devices and "-" may be shared
    const std::string key = file_identity(o.path);
    if (key == input)
      throw InputError(std::string(o.option) + " " + o.path + ": the scene " + scene +
                       " itself (an output never replaces an input)");
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

/// "--cost-range MIN,MAX": two finite numbers, 0 < MIN < MAX (a log scale). Throws InputError.
LogRange parse_cost_range(const std::string& text) {
  const std::string what = "--cost-range " + text + ": ";
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos)
    throw InputError(what + "expected two numbers MIN,MAX (e.g. 10,1000)");
  double v[2];
  const std::string parts[2] = {text.substr(0, comma), text.substr(comma + 1)};
  for (int k = 0; k < 2; ++k) {
    std::size_t end = 0;
    try {
      v[k] = std::stod(parts[k], &end);
    } catch (const std::exception&) {
      end = 0;
    }
    if (parts[k].empty() || end != parts[k].size() || !std::isfinite(v[k]))
      throw InputError(what + "expected two numbers MIN,MAX (e.g. 10,1000)");
  }
  if (!(v[0] > 0.0))
    throw InputError(what + "MIN must be greater than 0 on the log scale of the cost image");
  if (!(v[0] < v[1])) throw InputError(what + "MIN must be less than MAX");
  return {v[0], v[1]};
}

/// The command line as one string, each argument that needs it in single quotes, without
/// --threads: it goes into the EXR header, which is part of the file's bytes, and those are the
/// same for any thread count (the stats hold the threads used).
std::string command_text(const std::vector<std::string>& argv) {
  std::string out;
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (i > 0 && a == "--threads") {
      ++i;  // and its value
      continue;
    }
    if (a.starts_with("--threads=")) continue;
    if (!out.empty()) out += ' ';
    const bool plain = !a.empty() && a.find_first_not_of(
                                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMN"
                                         "OPQRSTUVWXYZ0123456789-_.,:/=+@%") == std::string::npos;
    if (plain) {
      out += a;
      continue;
    }
    out += '\'';
    for (char c : a) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    out += '\'';
  }
  return out;
}

/// The renderer options as command-line text (the EXR header's "amalgam:options").
std::string options_text(const CommonOptions& c, int spp) {
  const RenderOptions& o = c.options;
  std::ostringstream f;
  f << "--renderer " << c.renderer << " --opacity " << c.opacity << " --order " << c.order;
  if (const auto* l = std::get_if<OnLevel>(&o.lod))
    f << " --level " << l->level;
  else if (o.renderer() != RendererKind::kTraditional)
    f << " --footprint " << footprint_of(o.lod);
  f << " --seed " << o.seed << " --width " << o.width << " --height " << o.height << " --spp "
    << spp;
  return f.str();
}

std::uint64_t peak_memory_bytes() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return static_cast<std::uint64_t>(u.ru_maxrss) * 1024;  // Linux: kibibytes
}

std::string format_range(const LogRange& r) {
  std::ostringstream s;
  s << r.min << ".." << r.max;
  return s.str();
}

}  // namespace

int run_render(CommonOptions& common, const RenderExtras& given) {
  RenderExtras extra = given;
#if defined(AMALGAM_HAVE_MPI)
  const bool parallel = mpi::parallel();  // one of several ranks under mpirun (docs/mpi.md)
  const bool root = !parallel || mpi::rank() == 0;
  const int ranks = parallel ? mpi::size() : 1;
#else
  const bool parallel = false, root = true;
  const int ranks = 1;
#endif
  if (!root) extra.quiet = true;  // rank 0 speaks for the job
  const RenderOptions& o = common.options;
  const std::string ckpt = extra.checkpoint.empty() ? extra.out + ".ckpt" : extra.checkpoint;
  std::optional<LogRange> given_range;
  std::optional<LoadedScene> loaded;
  std::string fp;
  FilmState state;
  std::unique_ptr<Tracer> tracer;
  // In a parallel render every rank prepares (options, scene) before any renders, and a rank
  // that fails tells the others (mpi::agree) rather than leaving them waiting.
  std::exception_ptr failure;
  try {
    common.finish();
    if (!extra.cost_range.empty()) given_range = parse_cost_range(extra.cost_range);
    // A checkpoint to resume must be a regular file: known before any work (read_checkpoint
    // refuses it too, without opening a FIFO for reading, which would wait for a writer).
    if (extra.resume && root)
      if (const std::string why = not_a_regular_file(ckpt); !why.empty())
        throw InputError(ckpt + ": " + why + ": cannot resume from it");
    if (root) check_outputs(extra, ckpt, o, common.scene);  // the outputs are rank 0's
    const std::uint64_t asked =
        extra.max_memory_given ? parse_bytes(extra.max_memory, "--max-memory") : 0;
    if (extra.max_memory_given && asked == 0)
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
    budget.import_max_bytes = limit;
    budget.import_limit_name = "--max-memory " + format_bytes(static_cast<double>(limit));
    budget.objects = o.renderer() == RendererKind::kVolumetric;
    budget.smooth_normals = common.smooth_normals;
    budget.on_phase = [&](const std::string& what) {
      set_activity(what);
      status.phase(what);
    };
    loaded.emplace(load_scene(common.scene, common.params(), budget));
    if (root) check_outputs_spare_inputs(extra, ckpt, *loaded);
    common.prepare(*loaded);  // the view options, before the fingerprint takes the camera
    if (o.tracer == TracerKind::kEmbree) {
      set_activity("building Embree's BVH of " + common.scene);
      status.phase(activity());
    }
    tracer = make_tracer(*loaded, o);  // checks the options against the scene first
    status.stop();
    if (root) print_warnings(*loaded);  // after the load phases' status line

    fp = fingerprint(common, *loaded);
    if (extra.resume && root) {
      if (!std::filesystem::exists(ckpt)) throw InputError(ckpt + ": no checkpoint to resume from");
      state = read_checkpoint(ckpt, fp);
      if (state.spp_done > o.spp)
        throw InputError(ckpt + ": checkpoint holds " + std::to_string(state.spp_done) +
                         " samples per pixel, more than --spp " + std::to_string(o.spp));
    }
  } catch (...) {
    if (!parallel) throw;
    failure = std::current_exception();
  }
#if defined(AMALGAM_HAVE_MPI)
  if (parallel) {
    if (const int st = mpi::agree(failure)) return st;
    // Every rank must render the same image: the same scene (content hash) and options.
    const std::string root_fp = mpi::broadcast(fp);
    failure = nullptr;
    if (root_fp != fp)
      failure = std::make_exception_ptr(
          InputError(common.scene + ": this rank loads a different scene or options than rank 0 (" +
                     fp + " against " + root_fp + ")"));
    if (const int st = mpi::agree(failure)) return st;
  }
#endif
  const LoadedScene& scene = *loaded;

  // SIGHUP (a closed terminal, a dropped SSH session) and SIGQUIT stop the render as SIGINT and
  // SIGTERM do. A signal ignored at start stays ignored: nohup ignores SIGHUP, and a shell
  // ignores SIGINT and SIGQUIT in the background jobs it starts, so they outlive a Ctrl-C.
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (const int sig : kStopSignals) {
    struct sigaction old {};
    if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    sigaction(sig, &sa, nullptr);
  }
#if defined(AMALGAM_HAVE_MPI)
  // What renders a tile on this rank: amalgam's traversal or Embree, as for one process.
  const mpi::TileRenderer tile_renderer = [&](FilmTile& t, int s0, int s1,
                                              const std::atomic<bool>* cancel) {
    return tracer->render_tile(o, t, s0, s1, cancel);
  };
  if (!root) {
    mpi::serve(tile_renderer, o, g_cancel, g_signal);
    return 0;
  }
  // Rank 0, once its outputs are written (or not): the other ranks are told to stop; one that
  // was lost ends the job with an error. Not while an exception unwinds (mpi::Session aborts).
  struct Release {
    bool on;
    ~Release() {
      if (on && std::uncaught_exceptions() == 0 && !mpi::release()) mpi::abort(1);
    }
  } release{parallel};
  mpi::Stop stop;
#endif
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
  RenderOutput r;
#if defined(AMALGAM_HAVE_MPI)
  if (parallel) {
    // Rounds as long as the checkpoint interval: a checkpoint is written at the end of one.
    r = mpi::render_root(tile_renderer, o, &state, control, g_signal, extra.rank_timeout,
                         extra.checkpoint_every, stop);
  }
#endif
  if (!parallel) r = tracer->render(o, &state, control);
  const double embree_build = tracer->build_seconds();
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
  const LogRange range = given_range ? *given_range : own_range(r.cost);
  const int max_level = scene.info().levels - 1;
  if (r.spp > 0) {
    attempt(extra.out, [&] {
      if (is_exr_path(extra.out)) {
        const double top = write_render_exr(
            extra.out, r,
            {{"amalgam:command", command_text(extra.argv)},
             {"amalgam:version", version()},
             {"amalgam:scene", common.scene},
             {"amalgam:seed", std::to_string(o.seed)},
             {"amalgam:spp", std::to_string(r.spp)},
             {"amalgam:options", options_text(common, r.spp)},
             {"amalgam:cost", "cost.Y: intersection tests per pixel, total over its spp samples"},
             {"amalgam:level", "level.Y: level of the rendered amalgams (majority of samples); " +
                                   std::to_string(kLevelPrimitive) + ": primitives; " +
                                   std::to_string(kLevelNothing) + ": nothing hit"}},
            tracer->counts_tests());
        if (top > 16777216.0)
          std::cerr << "amalgam: warning: " << extra.out << ": a pixel holds " << top
                    << " tests, beyond 2^24: its cost.Y is rounded to float32 (the stats JSON "
                       "is exact)\n";
      } else {
        write_image(extra.out, r.width, r.height, r.image);
      }
    });
    if (!extra.cost_image.empty())
      attempt(extra.cost_image, [&] { write_cost_image(extra.cost_image, r, range); });
    if (!extra.level_image.empty())
      attempt(extra.level_image, [&] { write_level_image(extra.level_image, r, max_level); });
  }
  nlohmann::json stats = stats_json(scene, o, r.counters, r.per_primary, r.seconds, embree_build);
  RunInfo run;
  run.argv = extra.argv;
  run.width = r.width;
  run.height = r.height;
  run.spp = r.spp;
  run.threads = render_threads(o);
  run.ranks = ranks;
  run.peak_memory_bytes = peak_memory_bytes();
  run.cost_range = range;
  add_run_info(stats, run);
  const std::string json = stats.dump(2) + "\n";
  if (!extra.stats.empty()) attempt(extra.stats, [&] { write_file_atomic(extra.stats, json); });
  if (r.interrupted || !failed.empty()) attempt(ckpt, [&] { write_checkpoint(ckpt, fp, state); });
  if (!failed.empty()) {
    std::cerr << "amalgam: not written: ";
    for (std::size_t i = 0; i < failed.size(); ++i) std::cerr << (i ? ", " : "") << failed[i];
    std::cerr << "\n";
    return 1;
  }

  if (r.interrupted) {
    int sig = g_signal.load();
    std::string where;
#if defined(AMALGAM_HAVE_MPI)
    if (parallel) {
      sig = stop.signal;
      where = " on rank " + std::to_string(stop.signal_rank);
      if (!stop.missing.empty()) std::cerr << "amalgam: " << stop.missing << "\n";
    }
#endif
    std::cerr << "amalgam: interrupted by " << signal_name(sig) << where << ": "
              << (r.spp > 0 ? extra.out : std::string("no image")) << " holds " << r.spp << " of "
              << o.spp << " samples per pixel; checkpoint " << ckpt
              << " (continue with the same command and --resume)\n";
    return 1;
  }
  // Complete: the checkpoint is no longer needed. What is removed is the file it was written to:
  // through a symbolic link, its target (the link is the user's and stays); a device or FIFO
  // is never removed.
  try {
    const OutputTarget t = resolve_output(ckpt);
    std::error_code ec;
    if (t.kind == OutputTarget::Kind::kFile && std::filesystem::is_regular_file(t.path, ec))
      std::filesystem::remove(t.path, ec);
  } catch (const InputError&) {  // its directory went away meanwhile: nothing to remove
  }
  if (!extra.quiet) {
    std::cerr << "amalgam: wrote " << extra.out << " (" << r.width << "x" << r.height << ", "
              << r.spp << " spp, " << r.seconds << " s, ";
    if (!tracer->counts_tests())
      std::cerr << "Embree, BVH build " << embree_build << " s)\n";
    else
      std::cerr << r.per_primary.mean() << " tests per primary ray)\n";
    if (!extra.cost_image.empty() && is_png_path(extra.cost_image))
      std::cerr << "amalgam: cost image " << extra.cost_image << ": viridis, log scale "
                << format_range(range)
                << " tests per primary sample (colour bar along the bottom)\n";
    if (!extra.level_image.empty() && is_png_path(extra.level_image))
      std::cerr << "amalgam: level image " << extra.level_image << ": viridis from level 0 to "
                << max_level << "; light grey: primitives; black: nothing hit\n";
  }
  return 0;
}

int run_trace(CommonOptions& common, const std::string& origin, const std::string& direction) {
  common.finish();
  set_activity("loading and building " + common.scene);
  SceneFileConfig config;
  config.objects = common.options.renderer() == RendererKind::kVolumetric;
  config.smooth_normals = common.smooth_normals;
  LoadedScene scene = load_scene(common.scene, common.params(), config);
  common.prepare(scene);
  print_warnings(scene);
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
  const std::unique_ptr<Tracer> tracer = make_tracer(scene, common.options);
  const double embree_build = tracer->build_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  const TraceOutput t = tracer->trace(common.options, ray);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const nlohmann::json j = trace_json(scene, common.options, t, secs, embree_build);
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

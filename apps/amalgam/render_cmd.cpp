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
#include <functional>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "amalgam/analysis/metrics.h"
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
#include "render_setup.h"

namespace amalgam::cli {

namespace {

/// What the scene is loaded with for `common`'s renderer: cells for the volumetric renderer,
/// the box amalgams' appearances only for the scale-sensitive one (the rest never render them).
void load_for_renderer(SceneFileConfig& config, const CommonOptions& common) {
  config.objects = common.options.renderer() == RendererKind::kVolumetric;
  config.amalgams = common.options.renderer() == RendererKind::kScaleSensitive;
  config.smooth_normals = common.smooth_normals;
}

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

/// What a render needs once its options, outputs and scene are checked.
struct Prepared {
  std::optional<LogRange> given_range;
  std::optional<LoadedScene> loaded;
  std::string fp;   ///< fingerprint(): a checkpoint resumes only under the same
  FilmState state;  ///< the checkpoint resumed (rank 0), or empty
  std::unique_ptr<Tracer> tracer;
};

/// Checks the options and the outputs (rank 0's), loads the scene within the memory budget,
/// builds its tracer and reads the checkpoint to resume. Throws InputError.
void prepare(CommonOptions& common, const RenderExtras& extra, const std::string& ckpt, bool root,
             Prepared& p) {
  const RenderOptions& o = common.options;
  common.finish();
  if (!extra.cost_range.empty()) p.given_range = parse_cost_range(extra.cost_range);
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
  load_for_renderer(budget, common);
  budget.on_phase = [&](const std::string& what) {
    set_activity(what);
    status.phase(what);
  };
  p.loaded.emplace(load_scene(common.scene, common.params(), budget));
  if (root) check_outputs_spare_inputs(extra, ckpt, *p.loaded);
  common.prepare(*p.loaded);  // the view options, before the fingerprint takes the camera
  if (o.tracer == TracerKind::kEmbree) {
    set_activity("building Embree's BVH of " + common.scene);
    status.phase(activity());
  }
  p.tracer = make_tracer(*p.loaded, o);  // checks the options against the scene first
  status.stop();
  if (root) print_warnings(*p.loaded);  // after the load phases' status line

  p.fp = fingerprint(common, *p.loaded);
  if (extra.resume && root) {
    if (!std::filesystem::exists(ckpt)) throw InputError(ckpt + ": no checkpoint to resume from");
    p.state = read_checkpoint(ckpt, p.fp, {o.width, o.height});
    if (p.state.spp_done > o.spp)
      throw InputError(ckpt + ": checkpoint holds " + std::to_string(p.state.spp_done) +
                       " samples per pixel, more than --spp " + std::to_string(o.spp));
  }
}

/// SIGHUP (a closed terminal, a dropped SSH session) and SIGQUIT stop the render as SIGINT and
/// SIGTERM do. A signal ignored at start stays ignored: nohup ignores SIGHUP, and a shell
/// ignores SIGINT and SIGQUIT in the background jobs it starts, so they outlive a Ctrl-C.
/// SIGPIPE is ignored: a FIFO or pipe whose reader went away fails that one write (EPIPE), as
/// a full disk does, instead of ending the render without its other outputs.
void catch_stop_signals() {
  std::signal(SIGPIPE, SIG_IGN);
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (const int sig : kStopSignals) {
    struct sigaction old {};
    if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    sigaction(sig, &sa, nullptr);
  }
}

/// Writes the image, the cost and level images, the stats and, when the render was interrupted
/// or an output failed, the checkpoint. Each output is written even when another fails; returns
/// false, with each failure and the list of the outputs not written printed, if any failed.
bool write_outputs(const CommonOptions& common, const RenderExtras& extra, const std::string& ckpt,
                   const Prepared& p, const RenderOutput& r, const LogRange& range, int ranks) {
  const RenderOptions& o = common.options;
  std::vector<std::string> failed;
  auto attempt = [&](const std::string& what, auto&& write) {
    try {
      write();
    } catch (const std::exception& e) {
      std::cerr << "amalgam: " << e.what() << "\n";
      failed.push_back(what);
    }
  };
  const int max_level = p.loaded->info().levels - 1;
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
            p.tracer->counts_tests());
        if (top > 16777216.0)
          std::cerr << "amalgam: warning: " << extra.out << ": a pixel holds " << top
                    << " tests, beyond 2^24: its cost.Y is rounded to float32 (the stats JSON "
                       "is exact)\n";
      } else {
        write_image(extra.out, r.width, r.height, r.image);
      }
    });
    if (!extra.cost_image.empty())
      attempt(extra.cost_image,
              [&] { write_cost_image(extra.cost_image, r, range, extra.cost_legend); });
    if (!extra.level_image.empty())
      attempt(extra.level_image, [&] { write_level_image(extra.level_image, r, max_level); });
  }
  nlohmann::json stats =
      stats_json(*p.loaded, o, r.counters, r.per_primary, r.seconds, p.tracer->build_seconds());
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
  if (r.interrupted || !failed.empty())
    attempt(ckpt, [&] { write_checkpoint(ckpt, p.fp, p.state); });
  if (failed.empty()) return true;
  std::cerr << "amalgam: not written: ";
  for (std::size_t i = 0; i < failed.size(); ++i) std::cerr << (i ? ", " : "") << failed[i];
  std::cerr << "\n";
  return false;
}

/// A complete render: the checkpoint is no longer needed, and (unless --quiet) what was written
/// is said. What is removed is the file the checkpoint was written to: through a symbolic link,
/// its target (the link is the user's and stays), and only if it is a checkpoint of this render
/// (any other file at that path stays); a device or FIFO is never removed.
void finish_complete(const RenderExtras& extra, const std::string& ckpt, const Prepared& p,
                     const RenderOutput& r, const LogRange& range) {
  try {
    const OutputTarget t = resolve_output(ckpt);
    std::error_code ec;
    if (t.kind == OutputTarget::Kind::kFile && is_checkpoint_of(t.path, p.fp))
      std::filesystem::remove(t.path, ec);
  } catch (const InputError&) {  // its directory went away meanwhile: nothing to remove
  }
  if (const std::string dark = dark_view(r.image, r.depth); !dark.empty())
    std::cerr << "amalgam: warning: " << extra.out << ": " << dark << "\n";
  if (extra.quiet) return;
  std::cerr << "amalgam: wrote " << extra.out << " (" << r.width << "x" << r.height << ", " << r.spp
            << " spp, " << r.seconds << " s, ";
  if (!p.tracer->counts_tests())
    std::cerr << "Embree, BVH build " << p.tracer->build_seconds() << " s)\n";
  else
    std::cerr << r.per_primary.mean() << " tests per primary ray)\n";
  if (!extra.cost_image.empty() && is_png_path(extra.cost_image))
    std::cerr << "amalgam: cost image " << extra.cost_image << ": viridis, log scale "
              << format_range(range) << " tests per primary sample (colour bar "
              << (extra.cost_legend.empty() ? std::string("along the bottom")
                                            : "in " + extra.cost_legend)
              << ")\n";
  if (!extra.level_image.empty() && is_png_path(extra.level_image))
    std::cerr << "amalgam: level image " << extra.level_image << ": viridis from level 0 to "
              << p.loaded->info().levels - 1 << "; light grey: primitives; black: nothing hit\n";
}

#if defined(AMALGAM_HAVE_MPI)
/// In a parallel render, once every rank has prepared: whether one failed, then whether every
/// rank loaded the same scene and options as rank 0 (the same fingerprint). Returns the exit
/// status to end with, or 0 to render.
int agree_to_render(const std::exception_ptr& failure, const std::string& scene,
                    const std::string& fp) {
  if (const int st = mpi::agree(failure)) return st;
  const std::string root_fp = mpi::broadcast(fp);
  std::exception_ptr differs;
  if (root_fp != fp)
    differs = std::make_exception_ptr(
        InputError(scene + ": this rank loads a different scene or options than rank 0 (" + fp +
                   " against " + root_fp + ")"));
  return mpi::agree(differs);
}
#endif

/// Says that signal `sig` (on rank `where`) stopped the render, what the image holds and how to
/// continue from the checkpoint.
void say_interrupted(const RenderExtras& extra, int spp_asked, const std::string& ckpt,
                     const RenderOutput& r, int sig, const std::string& where) {
  std::cerr << "amalgam: interrupted by " << signal_name(sig) << where << ": "
            << (r.spp > 0 ? extra.out : std::string("no image")) << " holds " << r.spp << " of "
            << spp_asked << " samples per pixel; checkpoint " << ckpt
            << " (continue with the same command and --resume)\n";
}

/// Runs `render` with a progress line and a checkpoint every --checkpoint-every seconds (at
/// the end of the pass that crosses it), stopping at the next tile on a stop signal.
RenderOutput render_with_progress(const RenderOptions& o, const RenderExtras& extra,
                                  const std::string& ckpt, const Prepared& p,
                                  const std::function<RenderOutput(const RenderControl&)>& render) {
  Progress progress(static_cast<std::uint64_t>(o.width) * static_cast<std::uint64_t>(o.height),
                    o.spp, p.state.spp_done, !extra.quiet);
  auto last_checkpoint = std::chrono::steady_clock::now();
  bool warned = false;
  RenderControl control;
  control.cancel = &g_cancel;
  control.pixel_samples = progress.counter();
  control.on_pass = [&](const FilmState& st) {
    progress.passes_done(st.spp_done);
    const auto now = std::chrono::steady_clock::now();
    if (st.spp_done < o.spp &&
        std::chrono::duration<double>(now - last_checkpoint).count() >= extra.checkpoint_every) {
      // Survives even a SIGKILL. One that cannot be written (a full disk) costs only the
      // protection: the render goes on and its outputs are written.
      try {
        write_checkpoint(ckpt, p.fp, st);
      } catch (const std::exception& e) {
        if (!warned) {
          progress.finish();
          std::cerr << "amalgam: warning: checkpoint " << ckpt
                    << " not written, the render goes on: " << e.what() << "\n";
        }
        warned = true;
      }
      last_checkpoint = now;
    }
  };
  RenderOutput r = render(control);
  progress.finish();
  return r;
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
  Prepared p;
  // In a parallel render every rank prepares (options, scene) before any renders, and a rank
  // that fails tells the others (mpi::agree) rather than leaving them waiting.
  std::exception_ptr failure;
  try {
    prepare(common, extra, ckpt, root, p);
  } catch (...) {
    if (!parallel) throw;
    failure = std::current_exception();
  }
#if defined(AMALGAM_HAVE_MPI)
  if (parallel)
    if (const int st = agree_to_render(failure, common.scene, p.fp)) return st;
#endif
  catch_stop_signals();
#if defined(AMALGAM_HAVE_MPI)
  // What renders a tile on this rank: amalgam's traversal or Embree, as for one process.
  const mpi::TileRenderer tile_renderer = [&](FilmTile& t, int s0, int s1,
                                              const std::atomic<bool>* cancel) {
    return p.tracer->render_tile(o, t, s0, s1, cancel);
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
  set_activity("rendering " + common.scene);
  const RenderOutput r = render_with_progress(o, extra, ckpt, p, [&](const RenderControl& control) {
#if defined(AMALGAM_HAVE_MPI)
    // Rounds as long as the checkpoint interval: a checkpoint is written at the end of one.
    if (parallel)
      return mpi::render_root(tile_renderer, o, &p.state, control, g_signal, extra.rank_timeout,
                              extra.checkpoint_every, stop);
#endif
    return p.tracer->render(o, &p.state, control);
  });
  set_activity("writing the outputs of " + common.scene);
  // The work is done: writing its results wins over further signals (on_signal).
  g_finishing.store(true);

  const LogRange range = p.given_range ? *p.given_range : own_range(r.cost);
  if (!write_outputs(common, extra, ckpt, p, r, range, ranks)) return 1;
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
    say_interrupted(extra, o.spp, ckpt, r, sig, where);
    return 1;
  }
  finish_complete(extra, ckpt, p, r, range);
  return 0;
}

int run_trace(CommonOptions& common, const std::string& origin, const std::string& direction) {
  common.finish();
  set_activity("loading and building " + common.scene);
  SceneFileConfig config;
  load_for_renderer(config, common);
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

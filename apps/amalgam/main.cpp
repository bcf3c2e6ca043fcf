/// The `amalgam` command line: render, trace, info, scenes, experiment, compare, advise
/// (docs/cli.md).

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <optional>
#include <string>

#include "amalgam/analysis/experiments.h"
#include "amalgam/util/error.h"
#include "amalgam/util/version.h"
#include "common.h"
#if defined(AMALGAM_HAVE_MPI)
#include "mpi_render.h"
#endif

namespace {

/// Out of memory where no handler can catch it (e.g. std::bad_alloc thrown while another
/// exception unwinds, inside a library): one line naming what was being done, exit 1, no core
/// dump. Anything else that reaches std::terminate is a bug: abort as usual.
[[noreturn]] void on_terminate() {
  if (const std::exception_ptr e = std::current_exception()) {
    try {
      std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
      const std::string& what = amalgam::cli::activity();
      std::fprintf(stderr, "amalgam: out of memory while %s\n", what.c_str());
      std::_Exit(1);
    } catch (...) {
    }
  }
  std::abort();
}

/// The subcommands, what each parsed into, and whether it was given.
struct Commands {
  amalgam::cli::CommonOptions render_opts, trace_opts, advise_opts, info_opts;
  bool info_json = false;
  amalgam::cli::RenderExtras extras;
  CLI::Option* max_memory = nullptr;
  std::string origin, direction;  ///< trace
  std::string exp_name, exp_out, exp_scenes;
  bool exp_quick = false, exp_partial = false;
  int exp_threads = 0;
  amalgam::cli::CompareOptions cmp;
  amalgam::cli::AdviseOptions adv;
  CLI::App *render = nullptr, *trace = nullptr, *experiment = nullptr, *compare = nullptr,
           *advise = nullptr, *info = nullptr;
};

void add_render(CLI::App& app, Commands& c, int argc, char** argv) {
  namespace cli = amalgam::cli;
  c.render = app.add_subcommand("render", "render an image and report exact costs");
  c.render_opts.add_to(*c.render);
  c.render->add_option("--out", c.extras.out, "output image (.png, .exr or .pfm)")->required();
  c.render->add_option("--stats", c.extras.stats, "write the stats JSON to FILE, or - for stdout");
  c.render->add_option(
      "--cost-image", c.extras.cost_image,
      "write intersection tests per pixel: false colour (.png) or raw (.exr/.pfm)");
  c.render->add_option("--cost-legend", c.extras.cost_legend,
                       "write the cost PNG's colour bar to this PNG instead of below the "
                       "picture, so that the cost PNG is the image's size and overlays it");
  c.render->add_option("--cost-range", c.extras.cost_range,
                       "MIN,MAX: the log scale of the cost PNG, in tests per primary sample "
                       "(default: the image's own range)");
  c.render->add_option(
      "--level-image", c.extras.level_image,
      "write the rendered level per pixel: colour-coded (.png) or raw (.pfm/.exr)");
  c.extras.argv.assign(argv, argv + argc);
  c.render->add_option("--width", c.render_opts.options.width, "image width (default 512)")
      ->check(cli::positive_int());
  c.render->add_option("--height", c.render_opts.options.height, "image height (default 512)")
      ->check(cli::positive_int());
  c.render->add_option("--spp", c.render_opts.options.spp, "samples per pixel (default 4)")
      ->check(cli::positive_int());
  c.render
      ->add_option("--sampler", c.render_opts.sampler,
                   "pixel sampling: independent (default: a random point per sample) or "
                   "stratified (scrambled Sobol points per pixel: edges converge faster)")
      ->check(CLI::IsMember({"independent", "stratified"}));
  c.render->add_option("--checkpoint", c.extras.checkpoint,
                       "checkpoint file written when interrupted (default: OUT.ckpt)");
  c.render->add_flag("--resume", c.extras.resume,
                     "continue an interrupted render from its checkpoint (same options)");
  c.render->add_flag("--quiet", c.extras.quiet, "no progress bar or summary on stderr");
  c.max_memory = c.render->add_option(
      "--max-memory", c.extras.max_memory,
      "fail early if the render needs more bytes than this (suffixes K, M, G, T; default: "
      "physical memory)");
  c.render
      ->add_option("--checkpoint-every", c.extras.checkpoint_every,
                   "seconds between checkpoints while rendering (default 60; 0: after every "
                   "pass of samples)")
      ->check(cli::seconds_in(0.0, 1e9, "[0, 1e9]"));

  c.render
      ->add_option("--rank-timeout", c.extras.rank_timeout,
                   "under mpirun: seconds a rank may hold a tile without answering before it is "
                   "taken as lost and its tile rendered by the others (default 600)")
      ->check(cli::seconds_in(0.001, 1e9, "[0.001, 1e9]"));
}

void add_trace(CLI::App& app, Commands& c) {
  namespace cli = amalgam::cli;
  c.trace = app.add_subcommand(
      "trace", "trace one primary ray (default: the scene's centre ray) and print its costs");
  c.trace_opts.add_to(*c.trace);
  c.trace->add_option("--origin", c.origin, "ray origin x,y,z");
  c.trace->add_option("--direction", c.direction, "ray direction x,y,z");
  // The ray's footprint (its cone spread) is that of a pixel of a width x height image.
  c.trace
      ->add_option("--width", c.trace_opts.options.width,
                   "image width the ray's footprint is of (default 512)")
      ->check(cli::positive_int());
  c.trace->add_option("--height", c.trace_opts.options.height, "image height (default 512)")
      ->check(cli::positive_int());
}

void add_info(CLI::App& app, Commands& c) {
  c.info = app.add_subcommand("info",
                              "what a scene holds, without rendering: bounds, primitives and "
                              "instances, cameras, lights, and the view a render would use");
  c.info_opts.add_scene_to(*c.info);
  c.info_opts.add_view_to(*c.info);
  c.info->add_flag("--json", c.info_json, "print it as JSON");
}

void add_experiment(CLI::App& app, Commands& c) {
  namespace cli = amalgam::cli;
  namespace experiments = amalgam::experiments;
  c.experiment = app.add_subcommand(
      "experiment", "reproduce the paper's analyses as measured sweeps (NAME or all)");
  std::string exp_names;
  for (const std::string& n : experiments::names())
    exp_names += (exp_names.empty() ? "" : ", ") + n;
  c.experiment->add_option("name", c.exp_name, "experiment name, or all; one of: " + exp_names)
      ->required();
  c.experiment->add_option("--out", c.exp_out, "output directory")->required();
  c.experiment->add_flag("--quick", c.exp_quick, "small sizes (as the tests use)");
  c.experiment->add_option("--scenes", c.exp_scenes,
                           "the bundled scene files (scenes/field.json, ...) in DIR (default: "
                           "installed with amalgam, or the source tree it was built from)");
  c.experiment->add_flag("--allow-partial", c.exp_partial,
                         "exit 0 with a partial report when a part cannot be measured (a scene "
                         "file missing); otherwise that is exit 1");
  c.experiment->add_option("--threads", c.exp_threads, "worker threads (default: all cores)")
      ->check(cli::non_negative_int());
}

void add_compare(CLI::App& app, Commands& c) {
  c.compare = app.add_subcommand(
      "compare",
      "compare two images: RMSE, PSNR, SSIM on luminance, mean and max error, relative MSE");
  c.compare->add_option("a", c.cmp.a, "first image (.png, .pfm or .exr)")->required();
  c.compare->add_option("b", c.cmp.b, "second image, e.g. the reference (same size)")->required();
  c.compare->add_option("--error-image", c.cmp.error_image,
                        "write the per-pixel RMS error in false colour (.png, .exr or .pfm)");
  c.compare->add_flag("--json", c.cmp.json, "print the figures as JSON");
}

void add_advise(CLI::App& app, Commands& c) {
  namespace cli = amalgam::cli;
  c.advise = app.add_subcommand(
      "advise",
      "should I use amalgams on this scene? renders full detail, Embree (where built) and the "
      "level-of-detail renderers for equal time, prints each one's error x time against a "
      "converged full-detail estimate, and writes a side-by-side strip");
  c.advise_opts.add_scene_to(*c.advise);
  c.advise_opts.add_view_to(*c.advise);
  c.advise->add_option("--width", c.adv.width, "image width (default 320)")
      ->check(cli::positive_int());
  c.advise->add_option("--height", c.adv.height, "image height (default 240)")
      ->check(cli::positive_int());
  c.advise
      ->add_option(
          "--time", c.adv.seconds,
          "render seconds per render (default: what full detail takes for 16 spp, at least 0.5)")
      ->check(cli::seconds_in(1e-3, 86400, "[0.001, 86400]"));
  c.advise
      ->add_option("--repeats", c.adv.repeats,
                   "renders per renderer, in rounds, for the 95 % intervals of the ratios "
                   "(default 3; 1: no interval)")
      ->check(CLI::Range(1, 20));
  c.advise
      ->add_option("--reference-spp", c.adv.reference_spp,
                   "samples per pixel of the converged full-detail estimate (default 256)")
      ->check(cli::positive_int());
  c.advise->add_option("--out", c.adv.out, "the side-by-side strip (.png): images, cost, levels");
  c.advise->add_option("--json", c.adv.json, "write the table as JSON to FILE, or - for stdout");
  c.advise->add_option("--keep", c.adv.keep,
                       "write every render and the reference as PFM into this directory");
}

/// Refuses an empty value given to any option or argument of `app` and the subcommands parsed
/// (`--eye ''`, `--stats ''`): it used to be taken as not given.
void refuse_empty_values(const CLI::App& app) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->count() == 0 || opt->get_type_size_max() == 0) continue;  // not given, or a flag
    for (const std::string& v : opt->results())
      if (v.empty()) throw CLI::ValidationError(opt->get_name(false, true), "an empty value ''");
  }
  for (const CLI::App* sub : app.get_subcommands()) refuse_empty_values(*sub);
}

/// Parses the command line; returns the exit status when it ends here (help, version, a
/// mistake: one line naming it and the help to read, exit 2).
std::optional<int> parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    refuse_empty_values(app);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // The help of the command the mistake is in: `amalgam render --help` for a render option.
    std::string help = "amalgam";
    for (const CLI::App* sub : app.get_subcommands()) help += " " + sub->get_name();
    std::cerr << "amalgam: " << e.what() << " (see '" << help << " --help')\n";
    return 2;
  }
  return std::nullopt;
}

/// Standard output's write errors (a full disk, /dev/full) fail the command that printed
/// there: its output is flushed and checked before the status is returned.
int checked_stdout(int status) {
  errno = 0;
  std::cout.flush();
  if (std::cout && std::fflush(stdout) == 0) return status;
  const int err = errno;
  std::cerr << "amalgam: cannot write to standard output"
            << (err != 0 ? std::string(": ") + std::strerror(err) : std::string()) << "\n";
  return status == 0 ? 1 : status;
}

int run(Commands& c) {
  namespace cli = amalgam::cli;
  if (c.render->parsed()) return cli::run_render(c.render_opts, c.extras);
  if (c.trace->parsed()) return cli::run_trace(c.trace_opts, c.origin, c.direction);
  if (c.info->parsed()) return cli::run_info(c.info_opts, c.info_json);
  if (c.experiment->parsed())
    return cli::run_experiment(c.exp_name, c.exp_out, c.exp_quick, c.exp_threads, c.exp_scenes,
                               c.exp_partial);
  if (c.compare->parsed()) return cli::run_compare(c.cmp);
  if (c.advise->parsed()) return cli::run_advise(c.advise_opts, c.adv);
  return cli::run_scenes();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace amalgam;
  std::set_terminate(on_terminate);
#if defined(AMALGAM_HAVE_MPI)
  cli::mpi::Session mpi_session(&argc, &argv);  // only under mpirun (docs/mpi.md)
#endif
  CLI::App app{
      "amalgam: a ray tracer with renderable bounding volumes (amalgams), after "
      "Thompson & Fussell, 'Time Costs of Ray Tracing with Amalgams' (1991)"};
  app.set_version_flag("--version", std::string("amalgam ") + version());
  app.require_subcommand(1);
  Commands c;
  add_render(app, c, argc, argv);
  add_trace(app, c);
  add_info(app, c);
  app.add_subcommand("scenes", "list the builtin scenes and their parameters");
  add_experiment(app, c);
  add_compare(app, c);
  add_advise(app, c);
  if (const std::optional<int> status = parse(app, argc, argv)) return checked_stdout(*status);

  c.extras.max_memory_given = c.max_memory->count() > 0;  // an empty value is given, and refused
  try {
    return checked_stdout(run(c));
  } catch (const std::bad_alloc&) {
    std::cerr << "amalgam: out of memory while " << cli::activity() << "\n";
    return 1;
  } catch (const std::exception& e) {  // the one place failures become exit statuses
    std::cerr << "amalgam: " << e.what() << "\n";
    return exit_status(e);
  }
}

/// The `amalgam` command line: render, trace, scenes, experiment, compare, advise (docs/cli.md).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <new>
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

  cli::CommonOptions render_opts;
  cli::RenderExtras extras;
  CLI::App* render = app.add_subcommand("render", "render an image and report exact costs");
  render_opts.add_to(*render);
  render->add_option("--out", extras.out, "output image (.png, .exr or .pfm)")->required();
  render->add_option("--stats", extras.stats, "write the stats JSON to FILE, or - for stdout");
  render->add_option("--cost-image", extras.cost_image,
                     "write intersection tests per pixel: false colour (.png) or raw (.exr/.pfm)");
  render->add_option("--cost-range", extras.cost_range,
                     "MIN,MAX: the log scale of the cost PNG, in tests per primary sample "
                     "(default: the image's own range)");
  render->add_option("--level-image", extras.level_image,
                     "write the rendered level per pixel: colour-coded (.png) or raw (.pfm/.exr)");
  extras.argv.assign(argv, argv + argc);
  render->add_option("--width", render_opts.options.width, "image width (default 512)")
      ->check(cli::positive_int());
  render->add_option("--height", render_opts.options.height, "image height (default 512)")
      ->check(cli::positive_int());
  render->add_option("--spp", render_opts.options.spp, "samples per pixel (default 4)")
      ->check(cli::positive_int());
  render
      ->add_option("--sampler", render_opts.sampler,
                   "pixel sampling: independent (default: a random point per sample) or "
                   "stratified (scrambled Sobol points per pixel: edges converge faster)")
      ->check(CLI::IsMember({"independent", "stratified"}));
  render->add_option("--checkpoint", extras.checkpoint,
                     "checkpoint file written when interrupted (default: OUT.ckpt)");
  render->add_flag("--resume", extras.resume,
                   "continue an interrupted render from its checkpoint (same options)");
  render->add_flag("--quiet", extras.quiet, "no progress bar or summary on stderr");
  CLI::Option* max_memory = render->add_option(
      "--max-memory", extras.max_memory,
      "fail early if the render needs more bytes than this (suffixes K, M, G, T; default: "
      "physical memory)");
  render
      ->add_option("--checkpoint-every", extras.checkpoint_every,
                   "seconds between checkpoints while rendering (default 60; 0: after every "
                   "pass of samples)")
      ->check(cli::seconds_in(0.0, 1e9, "[0, 1e9]"));

  render
      ->add_option("--rank-timeout", extras.rank_timeout,
                   "under mpirun: seconds a rank may hold a tile without answering before it is "
                   "taken as lost and its tile rendered by the others (default 600)")
      ->check(cli::seconds_in(0.001, 1e9, "[0.001, 1e9]"));

  cli::CommonOptions trace_opts;
  std::string origin, direction;
  CLI::App* trace = app.add_subcommand(
      "trace", "trace one primary ray (default: the scene's centre ray) and print its costs");
  trace_opts.add_to(*trace);
  trace->add_option("--origin", origin, "ray origin x,y,z");
  trace->add_option("--direction", direction, "ray direction x,y,z");
  // The ray's footprint (its cone spread) is that of a pixel of a width x height image.
  trace
      ->add_option("--width", trace_opts.options.width,
                   "image width the ray's footprint is of (default 512)")
      ->check(cli::positive_int());
  trace->add_option("--height", trace_opts.options.height, "image height (default 512)")
      ->check(cli::positive_int());

  app.add_subcommand("scenes", "list the builtin scenes and their parameters");

  std::string exp_name, exp_out;
  bool exp_quick = false;
  int exp_threads = 0;
  std::string exp_scenes;
  bool exp_partial = false;
  CLI::App* experiment = app.add_subcommand(
      "experiment", "reproduce the paper's analyses as measured sweeps (NAME or all)");
  std::string exp_names;
  for (const std::string& n : experiments::names())
    exp_names += (exp_names.empty() ? "" : ", ") + n;
  experiment->add_option("name", exp_name, "experiment name, or all; one of: " + exp_names)
      ->required();
  experiment->add_option("--out", exp_out, "output directory")->required();
  experiment->add_flag("--quick", exp_quick, "small sizes (as the tests use)");
  experiment->add_option("--scenes", exp_scenes,
                         "the bundled scene files (scenes/field.json, ...) in DIR (default: "
                         "installed with amalgam, or the source tree it was built from)");
  experiment->add_flag("--allow-partial", exp_partial,
                       "exit 0 with a partial report when a part cannot be measured (a scene "
                       "file missing); otherwise that is exit 1");
  experiment->add_option("--threads", exp_threads, "worker threads (default: all cores)")
      ->check(cli::non_negative_int());

  cli::CompareOptions cmp;
  CLI::App* compare = app.add_subcommand(
      "compare",
      "compare two images: RMSE, PSNR, SSIM on luminance, mean and max error, relative MSE");
  compare->add_option("a", cmp.a, "first image (.png, .pfm or .exr)")->required();
  compare->add_option("b", cmp.b, "second image, e.g. the reference (same size)")->required();
  compare->add_option("--error-image", cmp.error_image,
                      "write the per-pixel RMS error in false colour (.png, .exr or .pfm)");
  compare->add_flag("--json", cmp.json, "print the figures as JSON");

  cli::CommonOptions advise_opts;
  cli::AdviseOptions adv;
  CLI::App* advise = app.add_subcommand(
      "advise",
      "should I use amalgams on this scene? renders full detail, Embree (where built) and the "
      "level-of-detail renderers for equal time, prints each one's error x time against a "
      "converged full-detail estimate, and writes a side-by-side strip");
  advise_opts.add_scene_to(*advise);
  advise_opts.add_view_to(*advise);
  advise->add_option("--width", adv.width, "image width (default 320)")->check(cli::positive_int());
  advise->add_option("--height", adv.height, "image height (default 240)")
      ->check(cli::positive_int());
  advise
      ->add_option("--time", adv.seconds,
                   "render seconds per renderer (default: what full detail takes for 16 spp)")
      ->check(cli::seconds_in(1e-3, 86400, "[0.001, 86400]"));
  advise
      ->add_option("--reference-spp", adv.reference_spp,
                   "samples per pixel of the converged full-detail estimate (default 256)")
      ->check(cli::positive_int());
  advise->add_option("--out", adv.out, "the side-by-side strip (.png): images, cost, levels");
  advise->add_option("--json", adv.json, "write the table as JSON to FILE, or - for stdout");
  advise->add_option("--keep", adv.keep,
                     "write every render and the reference as PFM into this directory");

  try {
    app.parse(argc, argv);
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

  extras.max_memory_given = max_memory->count() > 0;  // an empty value is given, and refused
  try {
    if (render->parsed()) return cli::run_render(render_opts, extras);
    if (trace->parsed()) return cli::run_trace(trace_opts, origin, direction);
    if (experiment->parsed())
      return cli::run_experiment(exp_name, exp_out, exp_quick, exp_threads, exp_scenes,
                                 exp_partial);
    if (compare->parsed()) return cli::run_compare(cmp);
    if (advise->parsed()) return cli::run_advise(advise_opts, adv);
    return cli::run_scenes();
  } catch (const std::bad_alloc&) {
    std::cerr << "amalgam: out of memory while " << cli::activity() << "\n";
    return 1;
  } catch (const std::exception& e) {  // the one place failures become exit statuses
    std::cerr << "amalgam: " << e.what() << "\n";
    return exit_status(e);
  }
}

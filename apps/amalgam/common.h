#pragma once
/// \file Options shared by the subcommands, and the error-to-exit-status rule.

#include <cstdint>
#include <string>
#include <vector>

#include "amalgam/builtin/params.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/math/vec.h"
#include "amalgam/render/options.h"

// Declared, not included: CLI11's header costs about 8 s of compile time at -O3 in every file
// that includes it (it defines its validators in each), and only the files that build the
// command line need it (main.cpp, common.cpp).
namespace CLI {
class App;
class Option;
class Validator;
}  // namespace CLI

namespace amalgam::cli {

/// Holds the text of the shared options until they are checked.
struct CommonOptions {
  std::string scene;
  std::vector<std::string> sets;
  std::string renderer = "scale-sensitive";
  std::string opacity = "stochastic";
  std::string order = "sorted";
  int level = -1;
  double footprint = 1.0;  ///< as given: resolve_options checks its range
  std::string seed = "0";
  std::string sampler = "independent";  ///< render only (registered in main.cpp)
  int threads = 0;
  std::string tracer = "amalgam";
  RenderOptions options;
  CLI::Option* level_option = nullptr;
  CLI::Option* footprint_option = nullptr;
  CLI::Option* renderer_option = nullptr;
  CLI::Option* opacity_option = nullptr;
  CLI::Option* order_option = nullptr;
  std::string camera, eye, look_at, up, fov;  ///< the view options, as given
  int light_samples = 0;                      ///< --light-samples (0: not given)
  bool smooth_normals = false;                ///< --smooth-normals
  CameraChoice view;                          ///< set by finish()

  /// Registers SCENE, --set and the renderer options of docs/cli.md on `app`.
  void add_to(CLI::App& app);
  /// Only SCENE and --set (add_to's first part).
  void add_scene_to(CLI::App& app);
  /// Only --seed, --threads, the view options, --smooth-normals and --light-samples (add_to's
  /// last part): what a command that chooses the renderers itself (advise) takes.
  void add_view_to(CLI::App& app);
  /// Converts the parsed text into `options`; throws InputError on bad values, and on options
  /// --tracer embree cannot honour (it renders at full detail) or a build without Embree.
  void finish();
  Params params() const;
  /// Applies the view options to a loaded scene (choose_camera).
  void prepare(LoadedScene& scene) const;
};

/// CLI11 validators with short messages of our own (CLI11's range messages print both bounds
/// with 6 decimals: 390 characters for "positive").
const CLI::Validator& positive_int();
const CLI::Validator& non_negative_int();
/// A number of seconds in [lo, hi] (`range` is how the message writes it); NaN, infinities and
/// trailing text are refused.
CLI::Validator seconds_in(double lo, double hi, const std::string& range);

/// "--seed TEXT" as an unsigned 64-bit integer; throws InputError with the allowed range for
/// anything else (a sign, an exponent, a fraction, 2^64 or more).
std::uint64_t parse_seed(const std::string& text);

/// A byte count: an integer with an optional suffix K, M, G or T (powers of 1024, optionally
/// followed by B or iB, any case). Throws InputError naming `option` for anything else.
std::uint64_t parse_bytes(const std::string& text, const std::string& option);

/// What the command is doing, for the one line an out-of-memory failure prints ("reading
/// scene.json", "rendering", ...). Set by the subcommands as they go.
void set_activity(std::string what);
const std::string& activity();

/// Prints what a loaded scene holds that is not rendered, one line each on stderr
/// ("amalgam: warning: ...").
void print_warnings(const LoadedScene& scene);

/// Parses "x,y,z" into three floats, each within the range of scene coordinates (+-1e12);
/// throws InputError naming the option.
Vec3 parse_vec3(const std::string& text, const std::string& option);

/// The options of `render` beyond the shared ones.
struct RenderExtras {
  std::string out, stats, cost_image, checkpoint;
  std::string level_image;        ///< --level-image PATH
  std::string cost_legend;        ///< --cost-legend PATH: the cost PNG's bar apart
  std::string cost_range;         ///< --cost-range MIN,MAX as given; empty: the image's own
  std::vector<std::string> argv;  ///< the whole command line, for the stats and EXR header
  bool resume = false;
  bool quiet = false;
  std::string max_memory;          ///< as given (parse_bytes), when max_memory_given
  bool max_memory_given = false;   ///< false: the limit is the machine's physical memory
  double checkpoint_every = 60.0;  ///< seconds between checkpoints during a render
  double rank_timeout = 600.0;     ///< under mpirun: seconds a rank may hold a tile (docs/mpi.md)
};

int run_render(CommonOptions& common, const RenderExtras& extra);
int run_trace(CommonOptions& common, const std::string& origin, const std::string& direction);
int run_scenes();
/// `amalgam experiment`: scene files named scenes/... are read from `scenes_dir` (else found as
/// bundled_scenes_dir says); a part not measured is a warning and exit 1 unless `allow_partial`.
int run_experiment(const std::string& name, const std::string& out_dir, bool quick, int threads,
                   const std::string& scenes_dir, bool allow_partial);

/// The options of `advise` beyond the scene and view ones (docs/cli.md).
struct AdviseOptions {
  int width = 320, height = 240;
  double seconds = 0;       ///< time per render; 0: that of full detail at 16 spp, >= 0.5 s
  int repeats = 3;          ///< renders per renderer, interleaved: the ratios' intervals
  int reference_spp = 256;  ///< the converged estimate's samples (full detail, stratified)
  std::string out;          ///< the strip PNG; empty: none
  std::string json;         ///< the table as JSON (- for stdout); empty: none
  std::string keep;         ///< a directory for every render and the reference (PFM)
};
int run_advise(CommonOptions& common, const AdviseOptions& advise);

/// `info`: the scene's bounds, primitives, instances, cameras and lights, and the view a
/// render would use (as text, or JSON with `as_json`). Loads the scene without baking.
int run_info(CommonOptions& common, bool as_json);

/// The arguments of `compare`.
struct CompareOptions {
  std::string a, b, error_image;
  bool json = false;
};
int run_compare(const CompareOptions& o);

}  // namespace amalgam::cli

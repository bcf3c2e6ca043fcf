#pragma once
// What the yardstick (quality_bench.cpp) measures with: its arguments, the scene as loaded for
// a view, the converged reference, the errors of a curve's runs against it, one timed render of
// a renderer and one oracle estimate.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

namespace amalgam::quality {

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The command line of the yardstick.
struct Args {
  std::string scene = "scenes/field.json", view = "street", out = "build/yardstick/street";
  std::string cache = "build/yardstick/cache";
  std::string spps = "1,2,4,8,16,32,64", ks = "1,4,16", oracle_ks = "1,4,16";
  int width = 512, height = 384, threads = 2, runs = 3;
  int ref_max_spp = 1024, ref_batches = 8, oracle_rays = 64, oracle_spp = 2, oracle_runs = 2;
  double ref_se = 0.002;
  bool quick = false, no_embree = false, oracle_box = false;
  std::string opacity = "stochastic";  ///< of the scale-sensitive curves
  int light_samples = 0;  ///< shadow rays per sized light in every curve (0: the scene's)
};

/// The camera of `view`: street (the scene file's own) or the field's aerial view (as in
/// field_bench.cpp: the whole field from afar and above). Throws InputError otherwise.
void apply_view(Camera& c, const std::string& view);

/// The scene for --scene and --view, always instanced (as Embree sees it).
LoadedScene load(const Args& a);

/// The options every curve shares: size, threads, stratified sampling, stochastic opacity.
RenderOptions base_options(const Args& a);

/// The converged reference: amalgam's traditional renderer in independent batches.
struct Reference {
  std::vector<Vec3> image;
  int spp = 0;
  double se = 0, seconds = 0;
  double var = 0;  ///< mean over pixels and channels of the squared standard error
  bool cached = false;
};

/// The reference of `a`, read from --cache when there, else rendered (batches whose spp
/// doubles until the mean standard error is below --ref-se or --ref-max-spp is reached) and
/// cached.
Reference reference(const Args& a);

/// The errors of a curve's runs against the reference.
struct Errors {
  double rmse = 0, bias = 0, stddev = 0, relmse = 0, tile_worst = 0, tile_within = 0;
  std::vector<double> tiles;  ///< relative luminance bias per 32x32 tile, row-major
  int tiles_x = 0, tiles_y = 0;
};

/// `ref_var`: the reference's own squared standard error (mean over pixels and channels),
/// removed from the bias with the runs' variance.
Errors errors(const std::vector<std::vector<Vec3>>& runs, const std::vector<Vec3>& ref,
              double ref_var, int w, int h);

/// One timed render: its image, its fixed and render seconds, tests per primary ray.
struct Run {
  std::vector<Vec3> image;
  double fixed = 0, render = 0, tests = 0;  ///< fixed: reading + build (+ bake) seconds
};

/// kind: "traditional", "embree", "scale-sensitive" (at footprint k).
Run run_once(const Args& a, const std::string& kind, float k, int spp, std::uint64_t seed);

/// One oracle estimate at footprint k (oracle.h); `in_amalgam`: the fraction of samples that
/// ended in an amalgam.
std::vector<Vec3> run_oracle(const LoadedScene& s, const Args& a, float k, bool box,
                             std::uint64_t seed, double& in_amalgam);

}  // namespace amalgam::quality

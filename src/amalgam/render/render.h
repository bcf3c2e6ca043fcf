#pragma once
/// \file Whole renders and single traced rays, with exact cost statistics.

#include <atomic>
#include <functional>
#include <vector>

#include "amalgam/render/loaded_scene.h"
#include "amalgam/render/options.h"
#include "amalgam/stats/counters.h"
#include "amalgam/stats/distribution.h"
#include "amalgam/traverse/hit.h"

namespace amalgam {

/// The value of the rendered-level output (RenderOutput::level) where a pixel's samples mostly
/// met nothing, or mostly a primitive (at full detail, no amalgam rendered).
inline constexpr float kLevelNothing = -1.0f;
inline constexpr float kLevelPrimitive = -2.0f;

/// A pixel's auxiliary outputs summed over its samples, in sample order (docs/outputs.md).
/// All fields are 4 bytes wide, so the struct has no padding and is stored as raw bytes in a
/// checkpoint.
struct PixelAov {
  Vec3 normal{};                 ///< shading normals turned toward the viewer; a miss adds 0
  Vec3 albedo{};                 ///< diffuse colours of what was shaded; a miss adds 0
  float depth = 0.0f;            ///< distances t of the primary hits (misses add nothing)
  std::uint32_t amalgams = 0;    ///< samples whose primary ray ended at a rendered amalgam
  std::uint32_t primitives = 0;  ///< samples whose primary ray ended at a primitive
  std::uint32_t level_sum = 0;   ///< sum of the levels of those rendered amalgams
  friend bool operator==(const PixelAov&, const PixelAov&) = default;
};
static_assert(sizeof(PixelAov) == 40, "PixelAov is stored in checkpoints as raw bytes");

/// Everything a render measured.
struct RenderOutput {
  int width = 0, height = 0, spp = 0;  ///< spp: samples per pixel the image holds
  bool interrupted = false;            ///< stopped by RenderControl::cancel before options.spp
  std::vector<Vec3> image;             ///< linear RGB, mean over samples, row-major from the top
  std::vector<double> cost;  ///< intersection tests per pixel (all rays of its samples) / spp
  std::vector<std::uint64_t> tests;  ///< intersection tests per pixel, total over its samples
  /// Auxiliary outputs (docs/outputs.md): depth, the mean t over the samples that hit something
  /// (+inf if none did); normal and albedo, means over all samples (a miss counts as 0);
  /// level, by the majority of samples: the mean level of the rendered amalgams when most
  /// samples rendered one, else kLevelPrimitive or kLevelNothing (ties: amalgam, primitive).
  std::vector<float> depth, level;
  std::vector<Vec3> normal, albedo;
  Counters counters;             ///< exact totals, merged over threads
  CostDistribution per_primary;  ///< tests per primary ray including its shadow rays
  double seconds = 0.0;
};

/// The accumulated state of a progressive render, enough to resume it exactly: per-pixel
/// running sums over samples 0 .. spp_done-1 (added in sample order), tests per pixel, and
/// the merged counters.
struct FilmState {
  int width = 0, height = 0, spp_done = 0;
  std::vector<Vec3> sum;
  std::vector<std::uint64_t> tests;
  std::vector<PixelAov> aov;  ///< empty is taken as all zero (render_passes sizes it)
  Counters counters;
  CostDistribution per_primary;
};

/// A rectangle of pixels [x0, x1) x [y0, y1) of an image.
struct TileRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  std::size_t pixels() const { return static_cast<std::size_t>(x1 - x0) * (y1 - y0); }
};

/// The running sums of a rectangle of a FilmState (row-major within it), and the counters and
/// cost distribution of the samples added to it since it was cut: the unit of work handed to
/// another process (apps/amalgam/mpi_render.h).
struct FilmTile {
  TileRect rect;
  std::vector<Vec3> sum;
  std::vector<std::uint64_t> tests;
  std::vector<PixelAov> aov;
  Counters counters;
  CostDistribution per_primary;
};

/// The pixels of `rect` of `st` (zero counters), to continue rendering them with render_tile.
FilmTile cut_tile(const FilmState& st, const TileRect& rect);
/// Copies the pixels of `tile` into `st` (counters are not touched: the caller merges them).
void paste_tile(const FilmTile& tile, FilmState& st);

/// Hooks into a running render.
struct RenderControl {
  /// When it becomes true, the render stops at the next tile; the unfinished pass of samples is
  /// discarded and the output holds the completed ones.
  const std::atomic<bool>* cancel = nullptr;
  /// Called after every completed pass (checkpoints).
  std::function<void(const FilmState&)> on_pass;
  /// If set, each finished block of pixels adds its pixel samples (pixels x samples of the
  /// pass) as it finishes, from the worker threads: a display polls it for progress within a
  /// pass. A discarded pass's blocks stay counted.
  std::atomic<std::uint64_t>* pixel_samples = nullptr;
};

/// Renders the scene's camera view progressively with amalgam's traversal (options.tracer must
/// be kAmalgam; Embree renders go through make_tracer, render/tracer.h), in passes of
/// whole samples per pixel. Pixel (x, y), sample s uses the random stream hash(seed, y * width + x,
/// s), and each pixel's samples are summed in sample order: the output is identical for any thread
/// count, and a render resumed from a FilmState equals the uninterrupted one bit for bit. `resume`
/// (optional) is the state to continue from and receives the final state.
RenderOutput render(const LoadedScene& scene, const RenderOptions& options,
                    FilmState* resume = nullptr, const RenderControl& control = {});

/// The same with another view of the scene: `env` (camera, lights, background) replaces
/// scene.env, the hierarchy and its bake are shared (e.g. `chosen_view`, load/load_scene.h).
RenderOutput render(const LoadedScene& scene, const Environment& env, const RenderOptions& options,
                    FilmState* resume = nullptr, const RenderControl& control = {});

/// Adds samples s0 .. s1 - 1 to the pixels of `tile` (cut from a film of options.width x
/// options.height), with the sampling and per-pixel sample order of `render`: rendering every
/// tile of an image over the same sample ranges gives the bytes of `render` (and its counters,
/// merged). options.tracer must be kAmalgam. Returns false when `cancel` stopped it (the tile
/// is then incomplete).
bool render_tile(const LoadedScene& scene, const RenderOptions& options, FilmTile& tile, int s0,
                 int s1, const std::atomic<bool>* cancel = nullptr);

/// Samples per pixel one pass of `render` adds to an image of `pixels` pixels: about 2^16 primary
/// rays per pass, at least one sample.
int samples_per_pass(std::size_t pixels);

/// Prepares `st` for a render of `options`: a fresh film when it holds none, else checks that
/// the saved one fits (InputError). Shared by `render` and the Embree tracer.
void start_film(FilmState& st, const RenderOptions& options);

/// Converts accumulated state into an output (mean over the samples it holds).
RenderOutput finish(const FilmState& state);

/// What tracing one primary ray measured.
struct TraceOutput {
  Counters counters;
  CostDistribution per_primary;
  TraceHit hit;
  Vec3 colour;
};

/// Traces one primary ray with its shadow rays (random stream hash(seed, 0, 0)).
TraceOutput trace(const LoadedScene& scene, const RenderOptions& options, const Ray& ray);

/// The worker threads a render with these options runs on: options.threads (0: all cores),
/// at most the machine's concurrency.
int render_threads(const RenderOptions& options);

/// Throws InputError when options do not fit the scene (e.g. --level beyond l_max) or the
/// tracer (Embree renders at full detail only: the traditional renderer).
void check_options(const LoadedScene& scene, const RenderOptions& options,
                   OptionSpelling spelling = OptionSpelling::kFlags);

}  // namespace amalgam

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

/// Everything a render measured.
struct RenderOutput {
  int width = 0, height = 0, spp = 0;  ///< spp: samples per pixel the image holds
  bool interrupted = false;            ///< stopped by RenderControl::cancel before options.spp
  std::vector<Vec3> image;             ///< linear RGB, mean over samples, row-major from the top
  std::vector<double> cost;      ///< intersection tests per pixel (all rays of its samples) / spp
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
  Counters counters;
  CostDistribution per_primary;
};

/// Hooks into a running render.
struct RenderControl {
  /// When it becomes true, the render stops at the next tile; the unfinished pass of samples is
  /// discarded and the output holds the completed ones.
  const std::atomic<bool>* cancel = nullptr;
  /// Called after every completed pass (progress display, checkpoints).
  std::function<void(const FilmState&)> on_pass;
};

/// Renders the scene's camera view progressively with amalgam's traversal (options.tracer must
/// be kAmalgam; Embree renders go through render_embree, render/embree_tracer.h), in passes of
/// whole samples per pixel. Pixel (x, y), sample s uses the random stream hash(seed, y * width + x,
/// s), and each pixel's samples are summed in sample order: the output is identical for any thread
/// count, and a render resumed from a FilmState equals the uninterrupted one bit for bit. `resume`
/// (optional) is the state to continue from and receives the final state.
RenderOutput render(const LoadedScene& scene, const RenderOptions& options,
                    FilmState* resume = nullptr, const RenderControl& control = {});

/// Prepares `st` for a render of `options`: a fresh film when it holds none, else checks that
/// the saved one fits (InputError). Shared by `render` and `render_embree`.
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

/// Throws InputError when options do not fit the scene (e.g. --level beyond l_max) or the
/// tracer (Embree renders at full detail only: the traditional renderer).
void check_options(const LoadedScene& scene, const RenderOptions& options);

}  // namespace amalgam

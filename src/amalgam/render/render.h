#pragma once
/// \file Whole renders and single traced rays, with exact cost statistics.

#include <vector>

#include "amalgam/render/options.h"
#include "amalgam/scene/load.h"
#include "amalgam/stats/counters.h"
#include "amalgam/stats/distribution.h"
#include "amalgam/traverse/traverse.h"

namespace amalgam {

/// Everything a render measured.
struct RenderOutput {
  int width = 0, height = 0, spp = 0;
  std::vector<Vec3> image;   ///< linear RGB, mean over samples, row-major from the top
  std::vector<double> cost;  ///< intersection tests per pixel (all rays of its samples) / spp
  Counters counters;         ///< exact totals, merged over threads
  CostDistribution per_primary;  ///< tests per primary ray including its shadow rays
  double seconds = 0.0;
};

/// Renders the scene's camera view. Pixel (x, y), sample s uses the random stream
/// hash(seed, y * width + x, s): the output is identical for any thread count.
RenderOutput render(const LoadedScene& scene, const RenderOptions& options);

/// What tracing one primary ray measured.
struct TraceOutput {
  Counters counters;
  CostDistribution per_primary;
  TraceHit hit;
  Vec3 colour;
};

/// Traces one primary ray with its shadow rays (random stream hash(seed, 0, 0)).
TraceOutput trace(const LoadedScene& scene, const RenderOptions& options, const Ray& ray);

/// Throws InputError when options do not fit the scene (e.g. --level beyond l_max).
void check_options(const LoadedScene& scene, const RenderOptions& options);

}  // namespace amalgam

#pragma once
/// \file The stats JSON of CONTRACT.md ("renderer", "scene", "rays", "tests", ...).

#include <nlohmann/json.hpp>

#include "amalgam/render/loaded_scene.h"
#include "amalgam/render/options.h"
#include "amalgam/stats/counters.h"
#include "amalgam/stats/distribution.h"

namespace amalgam {

/// Builds the stats object. `render_seconds` is the render (or trace) time. With
/// options.tracer == kEmbree, `embree_build_seconds` is Embree's BVH build time
/// ("time_s.embree_build"), and the figures Embree cannot give are null: "opacity", "order"
/// (not used at full detail), "tests" and "per_primary_ray" (Embree counts no tests); "rays"
/// are counted exactly either way.
nlohmann::json stats_json(const LoadedScene& scene, const RenderOptions& options,
                          const Counters& counters, const CostDistribution& per_primary,
                          double render_seconds, double embree_build_seconds = 0.0);

}  // namespace amalgam

#pragma once
/// \file The stats JSON of CONTRACT.md ("renderer", "scene", "rays", "tests", ...).

#include <nlohmann/json.hpp>

#include "amalgam/render/loaded_scene.h"
#include "amalgam/render/options.h"
#include "amalgam/stats/counters.h"
#include "amalgam/stats/distribution.h"

namespace amalgam {

/// Builds the stats object. `render_seconds` is the render (or trace) time.
nlohmann::json stats_json(const LoadedScene& scene, const RenderOptions& options,
                          const Counters& counters, const CostDistribution& per_primary,
                          double render_seconds);

}  // namespace amalgam

#pragma once
/// \file The stats JSON of docs/outputs.md ("renderer", "scene", "rays", "tests", ...), with the
/// run's description (docs/outputs.md lists every key and its unit).

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "amalgam/io/colormap.h"
#include "amalgam/render/loaded_scene.h"
#include "amalgam/render/options.h"
#include "amalgam/render/render.h"
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

/// The JSON of `amalgam trace` (and Python's Scene.trace): stats_json of the one ray plus
/// "hit" (null, or t, object {kind, id, level} and point) and "colour". The level is null
/// under --tracer embree (Embree knows no levels).
nlohmann::json trace_json(const LoadedScene& scene, const RenderOptions& options,
                          const TraceOutput& t, double seconds, double embree_build_seconds = 0.0);

/// What a whole render adds to its stats object.
struct RunInfo {
  std::vector<std::string> argv;  ///< the command line, as given
  int width = 0, height = 0;
  int spp = 0;      ///< samples per pixel the outputs hold
  int threads = 0;  ///< worker threads used (per rank under MPI)
  int ranks = 1;    ///< MPI ranks that rendered the image (1 without mpirun)
  std::uint64_t peak_memory_bytes = 0;
  /// The cost PNG's scale (--cost-range, else the image's own range), also when no PNG is
  /// written: the range to give another render's --cost-range to compare the two.
  std::optional<LogRange> cost_range;
};

/// Adds "width", "height", "spp", "threads", "ranks", "command_line", "peak_memory_bytes" and
/// "cost_range" ({"min", "max", "scale": "log", "unit"}) to `j`.
void add_run_info(nlohmann::json& j, const RunInfo& info);

}  // namespace amalgam

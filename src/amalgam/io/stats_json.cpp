#include "amalgam/io/stats_json.h"

#include <cmath>

#include "amalgam/util/probe.h"
#include "amalgam/util/version.h"

namespace amalgam {
namespace {

/// A count held as a double (an implicit hierarchy's can exceed 2^64) as a JSON integer when
/// it is one that a double holds exactly, else as a number.
nlohmann::json count(double v) {
  if (v >= 0 && v <= 9007199254740992.0 && std::floor(v) == v) return static_cast<std::uint64_t>(v);
  return v;
}

}  // namespace

nlohmann::json stats_json(const LoadedScene& scene, const RenderOptions& o, const Counters& c,
                          const CostDistribution& d, double render_seconds,
                          double embree_build_seconds) {
  using nlohmann::json;
  const HierarchyInfo info = scene.info();
  json j;
  j["renderer"] = std::string(renderer_name(o.renderer()));
  j["opacity"] = std::string(opacity_name(o.opacity));
  const auto* on_level = std::get_if<OnLevel>(&o.lod);
  const auto* by_footprint = std::get_if<ByFootprint>(&o.lod);
  const auto* cells = std::get_if<VolumetricCells>(&o.lod);
  j["level"] = on_level ? json(on_level->level) : json(nullptr);
  j["footprint"] = by_footprint ? json(by_footprint->pixels)
                   : cells      ? json(cells->cone_widths)
                                : json(nullptr);
  j["order"] = o.sorted ? "sorted" : "unsorted";
  const bool embree = o.tracer == TracerKind::kEmbree;
  j["tracer"] = embree ? "embree" : "amalgam";
  j["seed"] = o.seed;
  j["sampler"] = o.sampler == PixelSampler::kStratified ? "stratified" : "independent";
  if (!light_probe().is_default()) j["light_probe"] = light_probe().describe();
  if (scene.volumes)
    j["volumes"] = {{"cells", scene.volumes->cells()},
                    {"bytes", scene.volumes->bytes()},
                    {"levels", scene.volumes->config.levels},
                    {"world_cells", scene.volumes->world.cells()},
                    {"world_levels", scene.volumes->world.levels},
                    {"world_bytes", scene.volumes->world.bytes()},
                    {"world_bake_s", scene.volumes->world_seconds},
                    {"bake_s", scene.volume_seconds}};
  j["scene"] = {{"name", scene.name},
                {"primitives", count(info.primitives)},
                {"nodes", count(info.nodes)},
                {"levels", info.levels}};
  j["rays"] = {{"primary", c.rays[0]}, {"shadow", c.rays[1]}};
  json by_level = json::array();
  int last = 0;
  for (int l = 0; l < kCountedLevels; ++l)
    if (c.by_level[l]) last = l;
  for (int l = 0; l <= std::max(last, info.levels - 1) && l < kCountedLevels; ++l)
    by_level.push_back(c.by_level[l]);
  j["tests"] = {{"total", c.total()},
                {"primary", c.tests_of(RayKind::kPrimary)},
                {"shadow", c.tests_of(RayKind::kShadow)},
                {"primitive", c.tests_of(ObjectKind::kPrimitive)},
                {"bounding_volume", c.tests_of(ObjectKind::kBoundingVolume)},
                {"amalgam", c.tests_of(ObjectKind::kAmalgam)},
                {"cell", c.tests_of(ObjectKind::kCell)},
                {"by_level", by_level}};
  // The paper's counting (Eq. 4, Figure 4): nodes reached in sorted order plus primitives
  // tested; `tests` counts every child of an entered node.
  j["traversed"] = {{"primary", c.traversed_of(RayKind::kPrimary)},
                    {"shadow", c.traversed_of(RayKind::kShadow)}};
  j["per_primary_ray"] = {
      {"mean", d.mean()}, {"p50", d.quantile(0.5)}, {"p99", d.quantile(0.99)}, {"max", d.max()}};
  j["time_s"] = {{"load", scene.load_seconds},
                 {"build", scene.build_seconds},
                 {"bake", scene.bake_seconds},
                 {"render", render_seconds}};
  j["version"] = version();
  if (embree) {
    j["opacity"] = nullptr;
    j["order"] = nullptr;
    j["tests"] = nullptr;
    j["traversed"] = nullptr;
    j["per_primary_ray"] = nullptr;
    j["time_s"]["embree_build"] = embree_build_seconds;
  }
  return j;
}

nlohmann::json trace_json(const LoadedScene& scene, const RenderOptions& o, const TraceOutput& t,
                          double seconds, double embree_build_seconds) {
  using nlohmann::json;
  json j = stats_json(scene, o, t.counters, t.per_primary, seconds, embree_build_seconds);
  if (t.hit.kind == TraceHit::Kind::kNone) {
    j["hit"] = nullptr;
  } else {
    const bool embree = o.tracer == TracerKind::kEmbree;
    j["hit"] = {{"t", t.hit.t},
                {"object",
                 {{"kind", t.hit.kind == TraceHit::Kind::kPrimitive ? "primitive" : "amalgam"},
                  {"id", t.hit.id},
                  {"level", embree ? json(nullptr) : json(t.hit.level)}}},
                {"point", {t.hit.surf.p.x, t.hit.surf.p.y, t.hit.surf.p.z}}};
  }
  j["colour"] = {t.colour.x, t.colour.y, t.colour.z};
  return j;
}

void add_run_info(nlohmann::json& j, const RunInfo& info) {
  j["width"] = info.width;
  j["height"] = info.height;
  j["spp"] = info.spp;
  j["threads"] = info.threads;
  j["ranks"] = info.ranks;
  j["command_line"] = info.argv;
  j["peak_memory_bytes"] = info.peak_memory_bytes;
  if (info.cost_range)
    j["cost_range"] = {{"min", info.cost_range->min},
                       {"max", info.cost_range->max},
                       {"scale", "log"},
                       {"unit", "tests per primary sample"}};
  else
    j["cost_range"] = nullptr;
}

}  // namespace amalgam

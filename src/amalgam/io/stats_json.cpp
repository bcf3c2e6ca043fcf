#include "amalgam/io/stats_json.h"

namespace amalgam {

nlohmann::json stats_json(const LoadedScene& scene, const RenderOptions& o, const Counters& c,
                          const CostDistribution& d, double render_seconds) {
  using nlohmann::json;
  const HierarchyInfo info = scene.info();
  json j;
  j["renderer"] = o.renderer == RendererKind::kTraditional ? "traditional" : "scale-sensitive";
  j["opacity"] = o.opacity == OpacityKind::kStochastic ? "stochastic" : "deterministic";
  const bool ss = o.renderer == RendererKind::kScaleSensitive;
  j["level"] = (ss && o.level) ? json(*o.level) : json(nullptr);
  j["footprint"] = (ss && !o.level) ? json(o.footprint) : json(nullptr);
  j["order"] = o.sorted ? "sorted" : "unsorted";
  j["seed"] = o.seed;
  j["sampler"] = o.sampler == PixelSampler::kStratified ? "stratified" : "independent";
  j["scene"] = {{"name", scene.name},
                {"primitives", info.primitives},
                {"nodes", info.nodes},
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
                {"by_level", by_level}};
  j["per_primary_ray"] = {
      {"mean", d.mean()}, {"p50", d.quantile(0.5)}, {"p99", d.quantile(0.99)}, {"max", d.max()}};
  j["time_s"] = {
      {"load", scene.load_seconds}, {"build", scene.build_seconds}, {"render", render_seconds}};
  return j;
}

}  // namespace amalgam

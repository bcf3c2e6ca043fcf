#include <chrono>
#include <iostream>

#include "amalgam/io/image.h"
#include "amalgam/io/stats_json.h"
#include "amalgam/render/render.h"
#include "common.h"

namespace amalgam::cli {

int run_render(CommonOptions& common, const std::string& out, const std::string& stats,
               const std::string& cost_image) {
  common.finish();
  const LoadedScene scene = load_scene(common.scene, common.params());
  check_options(scene, common.options);
  const RenderOutput r = render(scene, common.options);
  write_image(out, r.width, r.height, r.image);
  if (!cost_image.empty()) {
    const std::string ext = cost_image.substr(cost_image.find_last_of('.') + 1);
    if (ext == "png" || ext == "PNG") {
      write_image(cost_image, r.width, r.height, false_colour(r.cost, true));
    } else {
      std::vector<Vec3> raw(r.cost.size());
      for (std::size_t i = 0; i < raw.size(); ++i) {
        const auto v = static_cast<float>(r.cost[i]);
        raw[i] = {v, v, v};
      }
      write_image(cost_image, r.width, r.height, raw);
    }
  }
  const std::string json =
      stats_json(scene, common.options, r.counters, r.per_primary, r.seconds).dump(2) + "\n";
  if (stats == "-")
    std::cout << json;
  else if (!stats.empty())
    write_text_atomic(stats, json);
  std::cerr << "amalgam: wrote " << out << " (" << r.width << "x" << r.height << ", " << r.spp
            << " spp, " << r.seconds << " s, " << r.per_primary.mean()
            << " tests per primary ray)\n";
  return 0;
}

int run_trace(CommonOptions& common, const std::string& origin, const std::string& direction) {
  common.finish();
  const LoadedScene scene = load_scene(common.scene, common.params());
  check_options(scene, common.options);
  Ray ray = scene.env.camera.centre_ray(common.options.width, common.options.height);
  if (!origin.empty() || !direction.empty()) {
    const Vec3 o = origin.empty() ? ray.origin : parse_vec3(origin, "--origin");
    const Vec3 d = direction.empty() ? ray.dir : parse_vec3(direction, "--direction");
    if (length(d) == 0.0f) throw InputError("--direction: must not be the zero vector");
    const float spread = ray.cone_spread;
    ray = Ray::make(o, normalize(d));
    ray.cone_spread = spread;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const TraceOutput t = trace(scene, common.options, ray);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nlohmann::json j = stats_json(scene, common.options, t.counters, t.per_primary, secs);
  if (t.hit.kind == TraceHit::Kind::kNone) {
    j["hit"] = nullptr;
  } else {
    j["hit"] = {{"t", t.hit.t},
                {"object",
                 {{"kind", t.hit.kind == TraceHit::Kind::kPrimitive ? "primitive" : "amalgam"},
                  {"id", t.hit.id},
                  {"level", t.hit.level}}},
                {"point", {t.hit.surf.p.x, t.hit.surf.p.y, t.hit.surf.p.z}}};
  }
  j["colour"] = {t.colour.x, t.colour.y, t.colour.z};
  std::cout << j.dump(2) << "\n";
  return 0;
}

int run_scenes() {
  for (const BuiltinDoc& d : builtin_docs()) {
    std::cout << "builtin:" << d.name << "\n  " << d.summary << "\n";
    for (const std::string& p : d.params) std::cout << "    --set " << p << "\n";
  }
  std::cout << "\nEvery builtin also takes --set lights=K where listed.\n";
  return 0;
}

}  // namespace amalgam::cli

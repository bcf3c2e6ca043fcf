/// `amalgam info SCENE`: what a scene holds and how a render would see it, without rendering:
/// bounds, triangles and instances, the file's cameras and lights, and the camera chosen.

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <variant>

#include "amalgam/load/load_scene.h"
#include "common.h"

namespace amalgam::cli {
namespace {

using nlohmann::json;

json vec(Vec3 v) {
  return json::array({v.x, v.y, v.z});
}

std::string text(Vec3 v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.6g,%.6g,%.6g", v.x, v.y, v.z);
  return buf;
}

const char* kind_name(LightKind k) {
  switch (k) {
    case LightKind::kPoint:
      return "point";
    case LightKind::kDirectional:
      return "directional";
    case LightKind::kSpot:
      return "spot";
    case LightKind::kSky:
      return "sky";
  }
  return "?";
}

json camera_json(const Camera& c) {
  return {{"eye", vec(c.position)},
          {"look_at", vec(c.look_at)},
          {"up", vec(c.up)},
          {"fov_deg", c.vfov_deg}};
}

std::string camera_text(const Camera& c) {
  std::ostringstream s;
  s << "--eye " << text(c.position) << " --look-at " << text(c.look_at) << " --up " << text(c.up)
    << " --fov " << c.vfov_deg;
  return s.str();
}

json light_json(const Light& l) {
  json j = {{"kind", kind_name(l.kind)}, {"intensity", vec(l.intensity)}};
  if (l.kind == LightKind::kPoint || l.kind == LightKind::kSpot) j["position"] = vec(l.position);
  if (l.kind == LightKind::kDirectional || l.kind == LightKind::kSpot)
    j["direction"] = vec(l.direction);
  if (l.kind == LightKind::kPoint && l.radius > 0.0f) j["radius"] = l.radius;
  if (l.kind == LightKind::kDirectional && l.angle > 0.0f) j["angle_rad"] = l.angle;
  if (l.sized()) j["samples"] = l.samples;
  return j;
}

/// Where the chosen camera comes from, in words.
std::string camera_source(const LoadedScene& s, const CommonOptions& c) {
  const CameraChoice& v = c.view;
  std::string from;
  if (!v.camera.empty())
    from = "the file's camera " + v.camera;
  else if (!s.cameras.empty())
    from = "the file's first camera '" + s.cameras.front().name + "'";
  else if (s.framed_camera)
    from = "the default framing (the scene has no camera)";
  else
    from = "the scene's camera";
  if (v.eye || v.look_at || v.up || v.fov_deg) from += ", changed by the view options";
  return from;
}

json describe(const LoadedScene& s, const CommonOptions& c) {
  const HierarchyInfo hi = s.info();
  const Bbox b = std::visit([](const auto& h) { return h.bounds(h.root()); }, s.hierarchy);
  json j = {{"scene", s.name},
            {"bounds", {{"min", vec(b.lo)}, {"max", vec(b.hi)}}},
            {"primitives", hi.primitives},
            {"levels", hi.levels}};
  if (const auto* inst = std::get_if<InstancedHierarchy>(&s.hierarchy)) {
    double distinct = 0;
    for (const ExplicitHierarchy& m : inst->meshes) distinct += m.info().primitives;
    j["instances"] = inst->instances.size();
    j["meshes"] = inst->meshes.size();
    j["distinct_primitives"] = distinct;
  } else {
    j["instances"] = 0;
  }
  json cams = json::array();
  for (std::size_t i = 0; i < s.cameras.size(); ++i)
    cams.push_back(
        {{"index", i}, {"name", s.cameras[i].name}, {"camera", camera_json(s.cameras[i].camera)}});
  j["cameras"] = cams;
  json lights = json::array();
  for (const Light& l : s.env.lights) lights.push_back(light_json(l));
  j["lights"] = lights;
  j["default_lights"] = s.default_lights;
  j["render_camera"] = camera_json(s.env.camera);
  j["render_camera_from"] = camera_source(s, c);
  j["warnings"] = s.warnings;
  return j;
}

std::string count(double n) {
  char buf[64];
  if (n < 1e15) {
    std::string d = std::to_string(static_cast<unsigned long long>(n)), out;
    for (std::size_t i = 0; i < d.size(); ++i) {
      if (i > 0 && (d.size() - i) % 3 == 0) out += ',';
      out += d[i];
    }
    return out;
  }
  std::snprintf(buf, sizeof buf, "%.3g", n);
  return buf;
}

std::string light_text(const Light& l) {
  std::ostringstream o;
  o << kind_name(l.kind);
  if (l.kind == LightKind::kPoint || l.kind == LightKind::kSpot) o << " at " << text(l.position);
  if (l.kind == LightKind::kDirectional || l.kind == LightKind::kSpot)
    o << " toward " << text(l.direction);
  o << ", intensity " << text(l.intensity);
  if (l.kind == LightKind::kPoint && l.radius > 0.0f) o << ", radius " << l.radius;
  if (l.kind == LightKind::kDirectional && l.angle > 0.0f) o << ", angle " << l.angle << " rad";
  if (l.sized()) o << ", " << l.samples << " shadow rays";
  return o.str();
}

/// The same facts as `describe`, for a reader: views as options `render` takes.
void print_text(const json& j, const LoadedScene& s) {
  std::ostream& o = std::cout;
  o << "scene       " << s.name << "\n";
  const Bbox b = std::visit([](const auto& h) { return h.bounds(h.root()); }, s.hierarchy);
  o << "bounds      " << text(b.lo) << " .. " << text(b.hi) << " (size " << text(b.hi - b.lo)
    << ")\n";
  o << "primitives  " << count(j["primitives"].get<double>()) << " in " << j["levels"].get<int>()
    << " levels";
  if (j["instances"].get<std::size_t>() > 0)
    o << ": " << count(j["instances"].get<double>()) << " instances of "
      << j["meshes"].get<std::size_t>() << " meshes ("
      << count(j["distinct_primitives"].get<double>()) << " distinct)";
  o << "\n";
  o << "cameras     " << s.cameras.size() << (s.cameras.empty() ? " (the file has none)" : "")
    << "\n";
  for (std::size_t i = 0; i < s.cameras.size(); ++i)
    o << "  " << i << " '" << s.cameras[i].name << "': " << camera_text(s.cameras[i].camera)
      << "\n";
  o << "lights      " << s.env.lights.size()
    << (s.default_lights ? " (default lights: the scene has none; they follow the camera)" : "")
    << "\n";
  for (const Light& l : s.env.lights) o << "  " << light_text(l) << "\n";
  o << "render view " << j["render_camera_from"].get<std::string>() << "\n  "
    << camera_text(s.env.camera) << "\n";
}

}  // namespace

int run_info(CommonOptions& common, bool as_json) {
  common.finish();
  set_activity("loading and building " + common.scene);
  SceneFileConfig config;
  config.amalgams = false;  // nothing is rendered: no bake
  LoadedScene scene = load_scene(common.scene, common.params(), config);
  common.prepare(scene);
  print_warnings(scene);
  const json j = describe(scene, common);
  if (as_json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  print_text(j, scene);
  return 0;
}

}  // namespace amalgam::cli

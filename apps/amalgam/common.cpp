#include "common.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <system_error>

#include "amalgam/render/option_rules.h"
#include "amalgam/render/tracer.h"
#include "amalgam/scene/coordinate_limit.h"

namespace amalgam::cli {

void CommonOptions::add_to(CLI::App& app) {
  add_scene_to(app);
  renderer_option =
      app.add_option("--renderer", renderer,
                     "scale-sensitive (default), traditional, or volumetric (objects as "
                     "prefiltered cells where the cone is wide enough, docs/volumetric.md)")
          ->check(CLI::IsMember({"scale-sensitive", "traditional", "volumetric"}));
  opacity_option =
      app.add_option("--opacity", opacity,
                     "stochastic (default), deterministic, prefiltered (stochastic for camera "
                     "rays, deterministic for shadow rays) or composite (deterministic for all, "
                     "one shadow computation per camera ray)")
          ->check(CLI::IsMember({"stochastic", "deterministic", "prefiltered", "composite"}));
  level_option =
      app.add_option("--level", level, "scale-sensitive: render the amalgams met on level L")
          ->check(non_negative_int());
  footprint_option =
      app.add_option("--footprint", footprint,
                     "scale-sensitive without --level: render an amalgam once it is smaller than K "
                     "pixels of ray footprint (default 1)")
          ->check(CLI::Validator(
              [](std::string& v) -> std::string {
                try {
                  std::size_t end = 0;
                  const double x = std::stod(v, &end);
                  if (end == v.size() && x >= kMinFootprint && x <= kMaxFootprint) return "";
                } catch (const std::exception&) {  // out_of_range: beyond double's range
                }
                return "expected a number in [1e-30, 1e30]";
              },
              "K in [1e-30, 1e30]"));
  order_option = app.add_option("--order", order,
                                "sorted (default): nearest child first; unsorted: stored order")
                     ->check(CLI::IsMember({"sorted", "unsorted"}));
  app.add_option("--tracer", tracer,
                 "amalgam (default) or embree: Intel Embree 3 at full detail, same shading "
                 "(docs/embree.md)")
      ->check(CLI::IsMember({"amalgam", "embree"}));
  add_view_to(app);
}

void CommonOptions::add_scene_to(CLI::App& app) {
  app.add_option("scene", scene, "builtin:NAME, a scene .json or a mesh file")->required();
  app.add_option("--set", sets, "builtin scene parameter key=value (repeatable)");
}

void CommonOptions::add_view_to(CLI::App& app) {
  app.add_option("--seed", seed, "seed of all randomness, 0 .. 2^64-1 (default 0)");
  app.add_option("--threads", threads, "worker threads (default: all cores)")
      ->check(non_negative_int());
  app.add_option("--camera", camera,
                 "view from the scene file's camera NAME or INDEX (default: the first)");
  app.add_option("--eye", eye, "camera position x,y,z (replaces the scene's)");
  app.add_option("--look-at", look_at, "point the camera looks at, x,y,z");
  app.add_option("--up", up, "camera up direction x,y,z");
  app.add_flag("--smooth-normals", smooth_normals,
               "give meshes without vertex normals smooth ones (split at creases over 80 "
               "degrees); meshes with normals are always shaded smooth");
  app.add_option("--fov", fov, "vertical field of view in degrees (0 < DEG < 180)");
  app.add_option("--light-samples", light_samples,
                 "shadow rays per shading point for every sized light (sphere or sun disc; "
                 "default: each light's \"samples\")")
      ->check(CLI::Range(1, 4096));
}

void CommonOptions::prepare(LoadedScene& scene) const {
  choose_camera(scene, view);
}

void print_warnings(const LoadedScene& scene) {
  for (const std::string& w : scene.warnings) std::cerr << "amalgam: warning: " << w << "\n";
}

void CommonOptions::finish() {
  auto given = [](const CLI::Option* opt) { return opt && opt->count() > 0; };
  OptionRequest r;
  if (given(renderer_option)) r.renderer = renderer;
  if (given(opacity_option)) r.opacity = opacity;
  if (given(order_option)) r.order = order;
  if (given(level_option)) r.level = level;
  if (given(footprint_option)) r.footprint = footprint;
  r.tracer = tracer;
  r.sampler = sampler;
  r.width = options.width, r.height = options.height, r.spp = options.spp;
  r.threads = threads;
  r.seed = parse_seed(seed);
  if (tracer == "embree") require_tracer(TracerKind::kEmbree);  // before its other refusals
  options = resolve_options(r, OptionSpelling::kFlags);
  view = CameraChoice{};
  view.camera = camera;
  if (!eye.empty()) view.eye = parse_vec3(eye, "--eye");
  if (!look_at.empty()) view.look_at = parse_vec3(look_at, "--look-at");
  if (!up.empty()) view.up = parse_vec3(up, "--up");
  if (!fov.empty()) {
    std::size_t end = 0;
    double x = NAN;
    try {
      x = std::stod(fov, &end);
    } catch (const std::exception&) {
    }
    if (end != fov.size() || !(x > 0.0 && x < 180.0))
      throw InputError("--fov " + one_line(fov, 40) +
                       ": expected a vertical field of view in degrees, > 0 and < 180");
    view.fov_deg = static_cast<float>(x);
  }
  if (light_samples > 0) view.light_samples = light_samples;
}

Params CommonOptions::params() const {
  Params p(scene);
  for (const auto& s : sets) p.set(s);
  return p;
}

namespace {

std::string g_activity = "starting";

/// An integer in [lo, hi] written in plain decimal digits (no sign unless lo < 0, no exponent).
CLI::Validator int_in(long long lo, long long hi, const std::string& what) {
  return CLI::Validator(
      [lo, hi, what](std::string& v) -> std::string {
        long long x = 0;
        const char* b = v.data();
        const auto [p, ec] = std::from_chars(b, b + v.size(), x);
        if (ec == std::errc() && p == b + v.size() && x >= lo && x <= hi) return "";
        return "expected " + what;
      },
      what);
}

}  // namespace

void set_activity(std::string what) {
  g_activity.reserve(256);  // later updates rarely need memory, even when it has run out
  g_activity = std::move(what);
}

const std::string& activity() {
  return g_activity;
}

const CLI::Validator& positive_int() {
  static const CLI::Validator v = int_in(1, 2147483647, "an integer >= 1");
  return v;
}

const CLI::Validator& non_negative_int() {
  static const CLI::Validator v = int_in(0, 2147483647, "an integer >= 0");
  return v;
}

CLI::Validator seconds_in(double lo, double hi, const std::string& range) {
  return CLI::Validator(
      [lo, hi, range](std::string& v) -> std::string {
        double x = NAN;
        std::size_t end = 0;
        try {
          x = std::stod(v, &end);
        } catch (const std::exception&) {
          end = 0;
        }
        // NaN fails both comparisons: refused like any other value outside the range.
        if (!v.empty() && end == v.size() && x >= lo && x <= hi) return "";
        return "expected seconds in " + range;
      },
      "SECONDS");
}

std::uint64_t parse_seed(const std::string& text) {
  std::uint64_t x = 0;
  const char* b = text.data();
  const auto [p, ec] = std::from_chars(b, b + text.size(), x);
  if (text.empty() || ec != std::errc() || p != b + text.size())
    throw InputError("--seed " + one_line(text, 40) +
                     ": expected an integer in [0, 18446744073709551615]");
  return x;
}

std::uint64_t parse_bytes(const std::string& text, const std::string& option) {
  std::uint64_t x = 0;
  const char* b = text.data();
  const char* e = b + text.size();
  const auto [p, ec] = std::from_chars(b, e, x);
  std::string suffix(p, e);
  for (char& c : suffix) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const std::string units = "KMGT";
  int shift = 0;
  bool ok = ec == std::errc() && p != b;
  if (ok && !suffix.empty()) {
    const auto u = units.find(suffix[0]);
    ok = u != std::string::npos &&
         (suffix.size() == 1 || suffix.substr(1) == "B" || suffix.substr(1) == "IB");
    shift = ok ? 10 * (static_cast<int>(u) + 1) : 0;
  }
  if (ok && shift && x > (std::uint64_t{~0ull} >> shift)) ok = false;
  if (!ok)
    throw InputError(option + " " + one_line(text, 40) +
                     ": expected a byte count, e.g. 512M or 8G (suffixes K, M, G, T)");
  return x << shift;
}

Vec3 parse_vec3(const std::string& text, const std::string& option) {
  Vec3 v;
  std::istringstream in(text);
  char c1 = 0, c2 = 0;
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() ||
      !is_finite(v))
    throw InputError(option + " '" + text + "': expected three numbers x,y,z");
  // The range scene files and meshes are held to (scene/coordinate_limit.h): beyond it the
  // triangle test overflows float and the image would be silently empty.
  for (const float c : {v.x, v.y, v.z})
    if (std::abs(static_cast<double>(c)) > kMaxCoordinate)
      throw InputError(option + " '" + text +
                       "': each coordinate must be within [-1e12, 1e12], the range of scene "
                       "coordinates");
  return v;
}

}  // namespace amalgam::cli

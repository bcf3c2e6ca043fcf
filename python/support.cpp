#include "support.h"

#include <sys/resource.h>

#include <cmath>

#include "amalgam/analysis/metrics.h"
#include "amalgam/render/option_rules.h"
#include "amalgam/render/tracer.h"
#include "amalgam/scene/coordinate_limit.h"
#include "amalgam/util/error.h"

namespace amalgam::python {

py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

Options make_options(int width, int height, int spp, const std::string& renderer,
                     const std::string& opacity, std::optional<int> level,
                     std::optional<float> footprint, const std::string& order, std::uint64_t seed,
                     int threads, const std::string& sampler, const std::string& tracer) {
  // The CLI's checks (render/option_rules.h), its messages naming keywords. A keyword left at
  // its default counts as not given, as a flag left out does (tracer='embree' alone is then
  // the traditional renderer in Embree, as `--tracer embree` is).
  OptionRequest q;
  auto given = [](const std::string& v, const char* def) {
    return v == def ? std::nullopt : std::optional<std::string>(v);
  };
  q.renderer = given(renderer, "scale-sensitive"), q.opacity = given(opacity, "stochastic");
  q.order = given(order, "sorted"), q.sampler = sampler, q.tracer = tracer;
  q.level = level;
  if (footprint) q.footprint = *footprint;
  q.width = width, q.height = height, q.spp = spp, q.threads = threads;
  q.seed = seed;
  Options r;
  r.o = resolve_options(q, OptionSpelling::kKeywords);
  return r;
}

std::shared_ptr<RenderResult> make_result(const LoadedScene& scene, const RenderOptions& o,
                                          RenderOutput&& r, double embree_build) {
  auto res = std::make_shared<RenderResult>();
  const bool whole = r.image.size() == static_cast<std::size_t>(r.width) * r.height && r.spp > 0;
  const py::ssize_t h = whole ? r.height : 0, w = whole ? r.width : 0;
  nlohmann::json j = stats_json(scene, o, r.counters, r.per_primary, r.seconds, embree_build);
  RunInfo run;
  run.argv = {"amalgam.Scene.render"};
  run.width = r.width;
  run.height = r.height;
  run.spp = r.spp;
  run.threads = render_threads(o);
  rusage u{};  // the process's peak resident memory, as the CLI reports it (Linux: KiB)
  if (getrusage(RUSAGE_SELF, &u) == 0)
    run.peak_memory_bytes = static_cast<std::uint64_t>(u.ru_maxrss) * 1024;
  run.cost_range = own_range(r.cost);
  add_run_info(j, run);
  res->stats = to_python(j);
  res->width = r.width;
  res->height = r.height;
  res->spp = r.spp;
  res->spp_requested = o.spp;
  res->interrupted = r.interrupted;
  res->seconds = r.seconds;
  auto plane = [&](auto&& v, auto elem) {
    using E = decltype(elem);
    if (!whole || v.size() != static_cast<std::size_t>(h * w)) return view<E>(std::move(v), {0, 0});
    return view<E>(std::move(v), {h, w});
  };
  auto rgb = [&](std::vector<Vec3>&& v) {
    if (!whole || v.size() != static_cast<std::size_t>(h * w))
      return view<float>(std::vector<Vec3>{}, {0, 0, 3});
    return view<float>(std::move(v), {h, w, 3});
  };
  // A view that shows almost nothing says so, as the CLI's warning line does.
  if (whole)
    if (const std::string dark = dark_view(r.image, r.depth); !dark.empty())
      py::module_::import("warnings")
          .attr("warn")(dark, py::module_::import("builtins").attr("RuntimeWarning"), 2);
  res->image = rgb(std::move(r.image));
  res->normal = rgb(std::move(r.normal));
  res->albedo = rgb(std::move(r.albedo));
  res->cost = plane(std::move(r.cost), double{});
  res->tests = plane(std::move(r.tests), std::uint64_t{});
  res->depth = plane(std::move(r.depth), float{});
  res->level = plane(std::move(r.level), float{});
  return res;
}

Vec3 view_vec(const py::handle& v, const std::string& option) {
  std::vector<float> x;
  try {
    x = v.cast<std::vector<float>>();
  } catch (const py::cast_error&) {
  }
  const std::string text = py::str(v).cast<std::string>();
  if (x.size() != 3 || !is_finite(Vec3{x[0], x[1], x[2]}))
    throw InputError(option_text(option, OptionSpelling::kKeywords, "'" + text + "'") +
                     ": expected three numbers x,y,z");
  for (const float c : x)  // the CLI's range (scene/coordinate_limit.h)
    if (std::abs(static_cast<double>(c)) > kMaxCoordinate)
      throw InputError(option_text(option, OptionSpelling::kKeywords, "'" + text + "'") +
                       ": each coordinate must be within [-1e12, 1e12], the range of scene "
                       "coordinates");
  return {x[0], x[1], x[2]};
}

bool view_keyword(const std::string& key, const py::handle& value, CameraChoice& view) {
  if (key == "camera") {
    view.camera = py::str(value).cast<std::string>();
  } else if (key == "eye") {
    view.eye = view_vec(value, "--eye");
  } else if (key == "look_at") {
    view.look_at = view_vec(value, "--look-at");
  } else if (key == "up") {
    view.up = view_vec(value, "--up");
  } else if (key == "light_samples") {
    int n = 0;
    try {
      n = value.cast<int>();
    } catch (const py::cast_error&) {
      throw InputError(option_text("--light-samples", OptionSpelling::kKeywords,
                                   one_line(py::str(value).cast<std::string>(), 40)) +
                       ": expected an integer in [1, 4096]");
    }
    view.light_samples = n;
  } else if (key == "fov") {
    const std::string text = py::str(value).cast<std::string>();
    double x = NAN;
    try {
      x = value.cast<double>();
    } catch (const py::cast_error&) {
    }
    if (!(x > 0.0 && x < 180.0))
      throw InputError(option_text("--fov", OptionSpelling::kKeywords, one_line(text, 40)) +
                       ": expected a vertical field of view in degrees, > 0 and < 180");
    view.fov_deg = static_cast<float>(x);
  } else {
    return false;
  }
  return true;
}

}  // namespace amalgam::python

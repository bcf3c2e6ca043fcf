/// \file `amalgam.load` and `amalgam.Scene` (docs/python.md): a scene loaded, built and baked
/// once, and its renders and traced rays.

#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <climits>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "amalgam/load/load_scene.h"
#include "amalgam/render/option_rules.h"
#include "amalgam/render/render.h"
#include "amalgam/render/tracer.h"
#include "amalgam/util/error.h"
#include "arguments.h"
#include "docstrings.h"
#include "support.h"

namespace amalgam::python {
namespace {

/// The options `render` and `trace` share, from their keywords (the CLI's checks and words).
Options options_of(const Args& a, int spp, int threads, const std::string& sampler) {
  const auto level = a.optional_integer("level", 0, INT_MAX);
  const auto footprint = a.optional_number("footprint");
  return make_options(
      static_cast<int>(a.integer("width", 1, INT_MAX)),
      static_cast<int>(a.integer("height", 1, INT_MAX)), spp, a.text("renderer"), a.text("opacity"),
      level ? std::optional<int>(static_cast<int>(*level)) : std::nullopt,
      footprint ? std::optional<float>(static_cast<float>(*footprint)) : std::nullopt,
      a.text("order"), a.unsigned_integer("seed", 0, UINT64_MAX), threads, sampler,
      a.text("tracer"));
}

/// A render's result, and the exception that stopped it early (KeyboardInterrupt, or what
/// the progress callback raised), if one did.
struct Rendered {
  std::shared_ptr<RenderResult> result;
  std::optional<py::error_already_set> interrupt;
};

/// Renders `env` with the GIL released. The render runs on its own thread while this one,
/// without the GIL, waits for it and every 50 ms takes the GIL to run Python's signal
/// handlers (PyErr_CheckSignals): a KeyboardInterrupt cancels the render at its next tile
/// (RenderControl::cancel). progress(spp_done, spp) is called from this thread too, with the
/// GIL, when a pass of samples has completed since the last call, and once at the end.
Rendered render_interruptibly(const std::shared_ptr<const LoadedScene>& scene,
                              const std::shared_ptr<const Tracer>& tracer,
                              const std::shared_ptr<const Environment>& env, const RenderOptions& o,
                              const py::object& progress) {
  auto cancel = std::make_shared<std::atomic<bool>>(false);
  auto passes = std::make_shared<std::atomic<int>>(0);
  std::packaged_task<RenderOutput()> task([keep = scene, tracer, env, o, cancel, passes] {
    RenderControl control;
    control.cancel = cancel.get();
    control.on_pass = [passes](const FilmState& st) { passes->store(st.spp_done); };
    return tracer->render_view(*env, o, nullptr, control);
  });
  Rendered r;
  int reported = 0;
  auto report = [&] {  // with the GIL
    const int done_spp = passes->load();
    if (progress.is_none() || r.interrupt || done_spp == reported) return;
    reported = done_spp;
    try {
      progress(done_spp, o.spp);
    } catch (py::error_already_set& e) {  // the callback's exception stops the render
      r.interrupt.emplace(std::move(e));
      cancel->store(true);
    }
  };
  std::future<RenderOutput> done = task.get_future();
  {
    py::gil_scoped_release nogil;
    std::thread worker(std::move(task));
    while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      if (r.interrupt) continue;
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {
        r.interrupt.emplace();  // fetches the exception the handler raised
        cancel->store(true);
        continue;
      }
      report();
    }
    worker.join();
  }
  report();
  RenderOutput out = done.get();  // rethrows a failure of the render
  r.result = make_result(*scene, o, std::move(out), tracer->build_seconds());
  return r;
}

/// A loaded scene: the built, baked hierarchy, shared by every render of it.
struct Scene {
  std::shared_ptr<const LoadedScene> scene;
  std::string spec;
  std::shared_ptr<RenderResult> last_result;
  std::mutex last_mutex;
  /// The tracer of `o`: amalgam's, or Embree's, built on first use and kept for later renders.
  std::shared_ptr<const Tracer> embree;
  std::mutex embree_mutex;

  std::shared_ptr<const Tracer> tracer_for(const RenderOptions& o) {
    if (o.tracer == TracerKind::kAmalgam) return make_tracer(*scene, o);
    std::lock_guard<std::mutex> lock(embree_mutex);
    if (!embree) {
      py::gil_scoped_release nogil;  // Embree's build takes a while on a large scene
      embree = make_tracer(*scene, o);
    }
    return embree;
  }

  std::shared_ptr<RenderResult> render(const py::args& args, const py::kwargs& kwargs) {
    const Args a(
        "Scene.render", args, kwargs,
        {keyword("width", py::int_(512)), keyword("height", py::int_(512)),
         keyword("spp", py::int_(4)), keyword("renderer", py::str("scale-sensitive")),
         keyword("opacity", py::str("stochastic")), keyword("level"), keyword("footprint"),
         keyword("order", py::str("sorted")), keyword("seed", py::int_(0)),
         keyword("threads", py::int_(0)), keyword("sampler", py::str("independent")),
         keyword("camera"), keyword("eye"), keyword("look_at"), keyword("up"), keyword("fov"),
         keyword("light_samples"), keyword("tracer", py::str("amalgam")), keyword("progress")});
    const Options opt =
        options_of(a, static_cast<int>(a.integer("spp", 1, INT_MAX)),
                   static_cast<int>(a.integer("threads", 0, INT_MAX)), a.text("sampler"));
    const py::object& progress = a["progress"];
    if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
      a.wrong_type("progress", "callable or None");  // progress(spp_done, spp)
    check_options(*scene, opt.o, OptionSpelling::kKeywords);
    std::shared_ptr<const Tracer> tracer = tracer_for(opt.o);
    // Another view of the same built, baked scene: only the environment is new.
    CameraChoice view;
    view.spelling = OptionSpelling::kKeywords;  // messages name keywords
    for (const char* key : {"camera", "eye", "look_at", "up", "fov", "light_samples"})
      if (!a[key].is_none()) view_keyword(key, a[key], view);
    auto env = std::make_shared<const Environment>(chosen_view(*scene, view));
    Rendered result = render_interruptibly(scene, tracer, env, opt.o, progress);
    {
      std::lock_guard<std::mutex> lock(last_mutex);
      last_result = result.result;
    }
    if (result.interrupt) {
      // The partial result (the completed passes) travels with the exception.
      if (result.interrupt->value())
        py::setattr(result.interrupt->value(), "partial", py::cast(result.result));
      throw *result.interrupt;
    }
    return result.result;
  }

  py::dict trace(const py::args& args, const py::kwargs& kwargs) {
    const Args a("Scene.trace", args, kwargs,
                 {positional("origin"), positional("direction"), keyword("width", py::int_(512)),
                  keyword("height", py::int_(512)), keyword("renderer", py::str("scale-sensitive")),
                  keyword("opacity", py::str("stochastic")), keyword("level"), keyword("footprint"),
                  keyword("order", py::str("sorted")), keyword("seed", py::int_(0)),
                  keyword("tracer", py::str("amalgam"))});
    const Options opt = options_of(a, 1, 1, "independent");
    check_options(*scene, opt.o, OptionSpelling::kKeywords);
    std::shared_ptr<const Tracer> tracer = tracer_for(opt.o);
    Ray ray = scene->env.camera.centre_ray(opt.o.width, opt.o.height);
    auto vec = [&](const char* what) {
      const std::string message = std::string(what) + "=: expected three numbers x,y,z";
      std::vector<float> v;
      try {
        v = a[what].cast<std::vector<float>>();
      } catch (const py::cast_error&) {
        throw InputError(message);
      }
      if (v.size() != 3 || !is_finite(Vec3{v[0], v[1], v[2]})) throw InputError(message);
      return Vec3{v[0], v[1], v[2]};
    };
    if (!a["origin"].is_none() || !a["direction"].is_none()) {
      const Vec3 o = a["origin"].is_none() ? ray.origin : vec("origin");
      const Vec3 d = a["direction"].is_none() ? ray.dir : vec("direction");
      if (length(d) == 0.0f) throw InputError("direction=: must not be the zero vector");
      const float spread = ray.cone_spread;
      ray = Ray::make(o, normalize(d));
      ray.cone_spread = spread;
    }
    TraceOutput t;
    double secs = 0;
    {
      py::gil_scoped_release nogil;
      const auto t0 = std::chrono::steady_clock::now();
      t = tracer->trace(opt.o, ray);
      secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return to_python(trace_json(*scene, opt.o, t, secs, tracer->build_seconds()));
  }
};

/// A scene dict as the text of a scene file: json.dumps, with paths (os.PathLike) as str and
/// NumPy arrays and scalars as what their tolist() gives. A value JSON cannot hold (a set, a
/// NaN) is a TypeError or ValueError naming the dict.
std::string scene_text(const py::handle& dict) {
  const py::cpp_function plain([](const py::handle& x) -> py::object {
    if (auto p = as_path(x); p && !PyBytes_Check(x.ptr()))
      return py::module_::import("os").attr("fspath")(x);
    if (py::hasattr(x, "tolist")) return x.attr("tolist")();
    throw py::type_error("Object of type " + type_name(x) + " is not JSON serializable");
  });
  try {
    return py::module_::import("json")
        .attr("dumps")(dict, py::arg("allow_nan") = false, py::arg("default") = plain)
        .cast<std::string>();
  } catch (py::error_already_set& e) {
    const std::string why = py::str(e.value()).cast<std::string>();
    if (e.matches(PyExc_TypeError))
      throw py::type_error("the dict: " + why + " (a scene dict holds what a scene file does)");
    if (e.matches(PyExc_ValueError)) throw InputError("the dict: " + why);
    throw;
  }
}

std::shared_ptr<Scene> load(const py::args& args, const py::kwargs& kwargs) {
  // The keywords that name no parameter are the builtin's (the CLI's --set key=value).
  const Args a(
      "load", args, kwargs,
      {required("scene"), keyword("camera"), keyword("eye"), keyword("look_at"), keyword("up"),
       keyword("fov"), keyword("light_samples"), keyword("volumetric", py::bool_(false)),
       keyword("smooth_normals", py::bool_(false))},
      true);
  const py::object& arg = a["scene"];
  const bool is_dict = PyDict_Check(arg.ptr()) != 0;
  std::string spec = "the dict", text;
  if (is_dict)
    text = scene_text(arg);
  else if (auto path = as_path(arg))
    spec = *path;
  else
    a.wrong_type("scene", "str, os.PathLike or dict");
  Params p(spec, ParamSpelling::kKeywords);  // messages name load()'s keywords
  for (const auto& [key, value] : a.extra()) p.set(key, py::str(value).cast<std::string>());
  CameraChoice view;
  view.spelling = OptionSpelling::kKeywords;
  for (const char* key : {"camera", "eye", "look_at", "up", "fov", "light_samples"})
    if (!a[key].is_none()) view_keyword(key, a[key], view);
  SceneFileConfig config;
  config.objects = a.flag("volumetric");  // load for the volumetric renderer
  config.smooth_normals = a.flag("smooth_normals");
  auto s = std::make_shared<Scene>();
  s->spec = spec;
  {
    py::gil_scoped_release nogil;
    if (is_dict) p.check_all_used();  // a dict takes no parameters
    LoadedScene loaded =
        is_dict ? load_scene_text(text, spec, config) : load_scene(spec, p, config);
    if (config.objects && !loaded.volumes)  // the CLI refuses it when it renders
      throw InputError("volumetric=True: " + spec +
                       " has no meshes, which are what the volumetric renderer prefilters into "
                       "cells (spheres, boxes, loose triangles and builtin scenes have none)");
    choose_camera(loaded, view);
    s->scene = std::make_shared<const LoadedScene>(std::move(loaded));
  }
  return s;
}

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<Scene, std::shared_ptr<Scene>>(
      m, "Scene", "A loaded scene (amalgam.load): its built, baked hierarchy, reused by renders.")
      .def("render", &Scene::render, doc::kRender)
      .def("trace", &Scene::trace, doc::kTrace)
      .def_property_readonly(
          "last_result",
          [](Scene& s) {
            std::lock_guard<std::mutex> lock(s.last_mutex);
            return s.last_result;
          },
          "The result of the latest render that returned or was interrupted (None before)")
      .def_property_readonly(
          "levels", [](const Scene& s) { return s.scene->info().levels; },
          "levels of the hierarchy (a level option is < levels)")
      .def_property_readonly("name", [](const Scene& s) { return s.scene->name; })
      .def_property_readonly(
          "warnings", [](const Scene& s) { return s.scene->warnings; },
          "what the scene file holds that is not rendered")
      .def("__repr__", [](const Scene& s) { return "<amalgam.Scene " + s.spec + ">"; });
  m.def("load", &load, doc::kLoad);
}

}  // namespace amalgam::python

/// \file The Python module `amalgam` (docs/python.md): the library's scene loader, renderer,
/// experiments and image metrics, with images as NumPy arrays. Wraps the library, not the CLI;
/// the option names and error messages follow the CLI's (docs/cli.md).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "amalgam/analysis/experiments.h"
#include "amalgam/analysis/metrics.h"
#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "amalgam/io/srgb.h"
#include "amalgam/io/stats_json.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/option_rules.h"
#include "amalgam/render/render.h"
#include "amalgam/render/tracer.h"
#include "amalgam/util/error.h"
#include "amalgam/util/version.h"
#include "support.h"

using namespace amalgam;

using namespace amalgam::python;

namespace {

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

  std::shared_ptr<RenderResult> render(
      Strict<int> width, Strict<int> height, Strict<int> spp, const std::string& renderer,
      const std::string& opacity, std::optional<Strict<int>> level, std::optional<float> footprint,
      const std::string& order, Strict<std::uint64_t> seed, Strict<int> threads,
      const std::string& sampler, const py::object& camera, const py::object& eye,
      const py::object& look_at, const py::object& up, const py::object& fov,
      const py::object& light_samples, const std::string& tracer_name, const py::object& progress) {
    const Options opt = make_options(width, height, spp, renderer, opacity, level, footprint, order,
                                     seed, threads, sampler, tracer_name);
    if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
      throw InputError("progress=: expected a callable progress(spp_done, spp), or None");
    check_options(*scene, opt.o, OptionSpelling::kKeywords);
    std::shared_ptr<const Tracer> tracer = tracer_for(opt.o);
    // Another view of the same built, baked scene: only the environment is new.
    CameraChoice view;
    view.spelling = OptionSpelling::kKeywords;  // messages name keywords
    const std::pair<const char*, const py::object*> keys[] = {
        {"camera", &camera}, {"eye", &eye}, {"look_at", &look_at},
        {"up", &up},         {"fov", &fov}, {"light_samples", &light_samples}};
    for (const auto& [key, value] : keys)
      if (!value->is_none()) view_keyword(key, *value, view);
    auto env = std::make_shared<const Environment>(chosen_view(*scene, view));
    // The render runs on its own thread while this one, without the GIL, waits for it and
    // every 50 ms takes the GIL to run Python's signal handlers (PyErr_CheckSignals): a
    // KeyboardInterrupt cancels the render at its next tile (RenderControl::cancel).
    // progress(spp_done, spp) is called from this thread too, with the GIL, when a pass of
    // samples has completed since the last call, and once at the end.
    auto cancel = std::make_shared<std::atomic<bool>>(false);
    auto passes = std::make_shared<std::atomic<int>>(0);
    std::shared_ptr<const LoadedScene> keep = scene;
    const RenderOptions o = opt.o;
    std::packaged_task<RenderOutput()> task([keep, tracer, env, o, cancel, passes] {
      RenderControl control;
      control.cancel = cancel.get();
      control.on_pass = [passes](const FilmState& st) { passes->store(st.spp_done); };
      return tracer->render_view(*env, o, nullptr, control);
    });
    std::optional<py::error_already_set> interrupt;
    int reported = 0;
    auto report = [&] {  // with the GIL
      const int done_spp = passes->load();
      if (progress.is_none() || interrupt || done_spp == reported) return;
      reported = done_spp;
      try {
        progress(done_spp, o.spp);
      } catch (py::error_already_set& e) {  // the callback's exception stops the render
        interrupt.emplace(std::move(e));
        cancel->store(true);
      }
    };
    std::future<RenderOutput> done = task.get_future();
    {
      py::gil_scoped_release nogil;
      std::thread worker(std::move(task));
      while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
        if (interrupt) continue;
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) {
          interrupt.emplace();  // fetches the exception the handler raised
          cancel->store(true);
          continue;
        }
        report();
      }
      worker.join();
    }
    report();
    RenderOutput out = done.get();  // rethrows a failure of the render
    auto result = make_result(*scene, o, std::move(out), tracer->build_seconds());
    {
      std::lock_guard<std::mutex> lock(last_mutex);
      last_result = result;
    }
    if (interrupt) {
      // The partial result (the completed passes) travels with the exception.
      if (interrupt->value()) py::setattr(interrupt->value(), "partial", py::cast(result));
      throw *interrupt;
    }
    return result;
  }

  py::dict trace(std::optional<std::vector<float>> origin,
                 std::optional<std::vector<float>> direction, Strict<int> width, Strict<int> height,
                 const std::string& renderer, const std::string& opacity,
                 std::optional<Strict<int>> level, std::optional<float> footprint,
                 const std::string& order, Strict<std::uint64_t> seed,
                 const std::string& tracer_name) {
    const Options opt = make_options(width, height, 1, renderer, opacity, level, footprint, order,
                                     seed, 1, "independent", tracer_name);
    check_options(*scene, opt.o, OptionSpelling::kKeywords);
    std::shared_ptr<const Tracer> tracer = tracer_for(opt.o);
    Ray ray = scene->env.camera.centre_ray(width, height);
    auto vec = [](const std::vector<float>& v, const char* what) {
      if (v.size() != 3) throw InputError(std::string(what) + ": expected three numbers x,y,z");
      const Vec3 r{v[0], v[1], v[2]};
      if (!is_finite(r)) throw InputError(std::string(what) + ": expected three numbers x,y,z");
      return r;
    };
    if (origin || direction) {
      const Vec3 o = origin ? vec(*origin, "origin=") : ray.origin;
      const Vec3 d = direction ? vec(*direction, "direction=") : ray.dir;
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

std::shared_ptr<Scene> load(const std::string& spec, const py::kwargs& params) {
  // The view keywords are the CLI's view options (no builtin has a parameter of these names);
  // the others are builtin parameters (--set key=value).
  Params p(spec);
  CameraChoice view;
  view.spelling = OptionSpelling::kKeywords;  // messages name keywords
  SceneFileConfig config;
  for (auto item : params) {
    const std::string key = py::str(item.first).cast<std::string>();
    if (key == "volumetric") {  // load for the volumetric renderer (--renderer volumetric)
      config.objects = py::cast<bool>(item.second);
      continue;
    }
    if (key == "smooth_normals") {  // --smooth-normals
      config.smooth_normals = py::cast<bool>(item.second);
      continue;
    }
    if (!view_keyword(key, item.second, view)) p.set(key, py::str(item.second).cast<std::string>());
  }
  auto s = std::make_shared<Scene>();
  s->spec = spec;
  {
    py::gil_scoped_release nogil;
    LoadedScene loaded = load_scene(spec, p, config);
    if (config.objects && !loaded.volumes)  // the CLI refuses it when it renders
      throw InputError("volumetric=True: " + spec +
                       " has no meshes, which are what the volumetric renderer prefilters into "
                       "cells (spheres, boxes, loose triangles and builtin scenes have none)");
    choose_camera(loaded, view);
    s->scene = std::make_shared<const LoadedScene>(std::move(loaded));
  }
  return s;
}

/// An image argument of `compare`: a RenderResult or an H x W x 3 array.
std::vector<Vec3> pixels(const py::object& x, const char* name, int& w, int& h) {
  py::object a = x;
  if (py::isinstance<RenderResult>(x)) a = x.cast<RenderResult&>().image;
  auto arr = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!arr || arr.ndim() != 3 || arr.shape(2) != 3)
    throw InputError(std::string(name) + ": expected an H x W x 3 image (array or RenderResult)");
  h = static_cast<int>(arr.shape(0));
  w = static_cast<int>(arr.shape(1));
  std::vector<Vec3> v(static_cast<std::size_t>(w) * h);
  const float* d = arr.data();
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = {d[3 * i], d[3 * i + 1], d[3 * i + 2]};
  return v;
}

/// `amalgam.save_image`: an image through the CLI's writers (render --out), by extension.
void save_image(const std::string& path, const py::object& image) {
  int w = 0, h = 0;
  const std::vector<Vec3> px = pixels(image, "image", w, h);
  if (w == 0 || h == 0) throw InputError("image: the image is empty");
  if (!is_image_path(path))
    throw InputError(one_line(path, 200) + ": expected a .png, .exr or .pfm path");
  py::gil_scoped_release nogil;
  write_image(path, w, h, px);
}

/// `amalgam.to_srgb`: linear RGB as the 8-bit sRGB a PNG stores (the same rounding).
py::array_t<std::uint8_t> to_srgb(const py::object& image) {
  int w = 0, h = 0;
  const std::vector<Vec3> px = pixels(image, "image", w, h);
  py::array_t<std::uint8_t> out(
      {static_cast<py::ssize_t>(h), static_cast<py::ssize_t>(w), py::ssize_t{3}});
  std::uint8_t* d = out.mutable_data();
  for (std::size_t i = 0; i < px.size(); ++i)
    for (int k = 0; k < 3; ++k) d[3 * i + static_cast<std::size_t>(k)] = encode_srgb8(px[i][k]);
  return out;
}

py::dict compare(const py::object& a, const py::object& b) {
  int wa = 0, ha = 0, wb = 0, hb = 0;
  const std::vector<Vec3> pa = pixels(a, "a", wa, ha), pb = pixels(b, "b", wb, hb);
  if (wa != wb || ha != hb)
    throw InputError("a is " + std::to_string(wa) + "x" + std::to_string(ha) + " but b is " +
                     std::to_string(wb) + "x" + std::to_string(hb) +
                     ": compare needs images of the same size");
  if (wa == 0 || ha == 0) throw InputError("a: the image is empty");
  for (const auto& [name, image] : {std::pair{"a", &pa}, std::pair{"b", &pb}})
    if (const std::string why = non_finite_pixels(*image); !why.empty())
      throw InputError(std::string(name) + ": " + why);
  ImageComparison c;
  {
    py::gil_scoped_release nogil;
    c = compare_images(pa, pb, wa, ha);
  }
  py::dict d;
  d["width"] = wa;
  d["height"] = ha;
  for (const auto& [name, value] : c.named()) d[name] = value;  // the CLI's JSON names
  return d;
}

py::object experiment(const std::string& name, bool quick, Strict<int> threads, bool frame) {
  const auto& names = experiments::names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string all;
    for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
    throw InputError("experiment " + one_line(name, 40) + ": unknown (one of: " + all + ")");
  }
  if (threads < 0)
    throw InputError("--threads " + std::to_string(threads) + ": expected an integer >= 0");
  experiments::ExperimentResult r;
  experiments::Config config;
  config.quick = quick;
  config.threads = threads;
  config.load = [](const std::string& path) { return load_scene(path, Params(path)); };
  {
    py::gil_scoped_release nogil;
    r = experiments::run(name, config);
  }
  py::list rows;
  for (const auto& row : r.table.rows) {
    py::dict d;
    for (std::size_t i = 0; i < r.table.columns.size() && i < row.size(); ++i)
      d[py::str(r.table.columns[i])] = row[i];
    rows.append(d);
  }
  if (!frame) return rows;
  // pandas is optional: imported only when a DataFrame is asked for (ImportError otherwise).
  py::object pandas = py::module_::import("pandas");
  py::list columns;
  for (const auto& c : r.table.columns) columns.append(py::str(c));
  return pandas.attr("DataFrame")(rows, py::arg("columns") = columns);
}

}  // namespace

PYBIND11_MODULE(amalgam, m) {
  m.doc() =
      "amalgam: a ray tracer after Thompson & Fussell 1991, 'Time Costs of Ray Tracing with\n"
      "Amalgams', with exact cost statistics.\n\n"
      "  scene = amalgam.load('builtin:line', n=4)        # built and baked once\n"
      "  r = scene.render(width=256, height=256, spp=4)   # r.image: float32 H x W x 3\n"
      "  r.cost, r.stats                                  # tests per pixel, stats dict\n"
      "  amalgam.compare(r, reference)                    # rmse, psnr_db, ssim, ...\n"
      "  amalgam.experiment('expected', quick=True)       # the table as a list of dicts\n\n"
      "Bad input raises ValueError, runtime failures RuntimeError, each with the CLI's\n"
      "one-line message (a bug of amalgam's: RuntimeError 'internal error: ...'). See\n"
      "docs/python.md.";
  m.attr("__version__") = version();
  m.attr("has_embree") = have_embree();  // tracer="embree" is available

  // The CLI's classification (util/error.h, error_kind): bad input -> ValueError (exit 2),
  // a failed run and a bug of ours -> RuntimeError (exit 1). Other exceptions (out of memory,
  // Python's own from a callback) keep pybind11's translation.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const RuntimeError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const std::logic_error& e) {  // InternalError and every other logic_error
      PyErr_SetString(PyExc_RuntimeError, (std::string("internal error: ") + e.what()).c_str());
    }
  });

  py::class_<RenderResult, std::shared_ptr<RenderResult>>(
      m, "RenderResult",
      "The outputs of Scene.render (docs/outputs.md). Pixel (x, y) is [y, x], row 0 at the top.")
      .def_readonly("image", &RenderResult::image,
                    "float32 H x W x 3: linear RGB, mean over the samples (the CLI's PFM image)")
      .def_readonly("cost", &RenderResult::cost,
                    "float64 H x W: exact intersection tests per pixel (all rays) / spp")
      .def_readonly("tests", &RenderResult::tests,
                    "uint64 H x W: exact intersection tests per pixel, total over its samples")
      .def_readonly("depth", &RenderResult::depth,
                    "float32 H x W: mean distance of the primary hits (inf: none)")
      .def_readonly("level", &RenderResult::level,
                    "float32 H x W: level of the rendered amalgams (-2: primitives, -1: nothing)")
      .def_readonly("normal", &RenderResult::normal, "float32 H x W x 3: mean shading normal")
      .def_readonly("albedo", &RenderResult::albedo, "float32 H x W x 3: mean diffuse colour")
      .def_readonly("stats", &RenderResult::stats,
                    "dict: the CLI's stats JSON (--stats) for this render")
      .def_readonly("width", &RenderResult::width)
      .def_readonly("height", &RenderResult::height)
      .def_readonly("spp", &RenderResult::spp, "samples per pixel the image holds")
      .def_readonly("spp_requested", &RenderResult::spp_requested)
      .def_readonly("interrupted", &RenderResult::interrupted,
                    "True when a KeyboardInterrupt stopped the render before spp_requested")
      .def_readonly("seconds", &RenderResult::seconds, "render time")
      .def(
          "save", [](const py::object& self, const std::string& path) { save_image(path, self); },
          py::arg("path"), "Writes the image as amalgam.save_image(path, self) does.")
      .def("__repr__", [](const RenderResult& r) {
        return "<amalgam.RenderResult " + std::to_string(r.width) + "x" + std::to_string(r.height) +
               ", " + std::to_string(r.spp) + " spp" + (r.interrupted ? ", interrupted" : "") + ">";
      });

  py::class_<Scene, std::shared_ptr<Scene>>(
      m, "Scene", "A loaded scene (amalgam.load): its built, baked hierarchy, reused by renders.")
      .def("render", &Scene::render, py::kw_only(), py::arg("width") = 512, py::arg("height") = 512,
           py::arg("spp") = 4, py::arg("renderer") = "scale-sensitive",
           py::arg("opacity") = "stochastic", py::arg("level") = py::none(),
           py::arg("footprint") = py::none(), py::arg("order") = "sorted", py::arg("seed") = 0,
           py::arg("threads") = 0, py::arg("sampler") = "independent",
           py::arg("camera") = py::none(), py::arg("eye") = py::none(),
           py::arg("look_at") = py::none(), py::arg("up") = py::none(), py::arg("fov") = py::none(),
           py::arg("light_samples") = py::none(), py::arg("tracer") = "amalgam",
           py::arg("progress") = py::none(),
           "Renders the scene's camera view; the options are the CLI's (docs/cli.md). camera=\n"
           "(name or index), eye=, look_at=, up= (x, y, z) and fov= (degrees) change the view\n"
           "of this render only, as --camera, --eye, --look-at, --up and --fov do, starting from\n"
           "the view `load` chose; the scene is not rebuilt or rebaked. light_samples= is\n"
           "--light-samples (shadow rays per sized light). tracer='embree' renders at full\n"
           "detail with Intel Embree 3 (--tracer embree; its BVHs are built on first use and\n"
           "kept by the scene). The same\n"
           "seed gives the same image as `amalgam render ... --out x.pfm`, bit for bit, on any\n"
           "number of threads. The GIL is released. Ctrl-C (KeyboardInterrupt) stops the render\n"
           "at its next tile; the exception's `partial` attribute (and scene.last_result) holds\n"
           "the completed samples. progress=f calls f(spp_done, spp) on this thread as passes\n"
           "of samples complete (and once at the end); an exception it raises stops the render\n"
           "as Ctrl-C does. Raises ValueError on bad options (e.g. level beyond l_max).")
      .def("trace", &Scene::trace, py::arg("origin") = py::none(),
           py::arg("direction") = py::none(), py::kw_only(), py::arg("width") = 512,
           py::arg("height") = 512, py::arg("renderer") = "scale-sensitive",
           py::arg("opacity") = "stochastic", py::arg("level") = py::none(),
           py::arg("footprint") = py::none(), py::arg("order") = "sorted", py::arg("seed") = 0,
           py::arg("tracer") = "amalgam",
           "Traces one primary ray with its shadow rays (`amalgam trace`): by default the\n"
           "camera's centre ray. Returns the CLI's trace JSON as a dict: 'hit' (None or t,\n"
           "object {kind, id, level}, point), 'colour', 'rays', 'tests', ...")
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

  m.def("load", &load, py::arg("scene"),
        "load(scene, **params) -> Scene\n\n"
        "Loads, builds and bakes a scene: 'builtin:NAME' with its parameters as keyword\n"
        "arguments (the CLI's --set key=value, e.g. load('builtin:line', n=4)), a scene .json,\n"
        "or a mesh path. The view keywords camera= (name or index), eye=, look_at=, up=\n"
        "(x, y, z) and fov= (degrees) are the CLI's --camera, --eye, --look-at, --up, --fov.\n"
        "volumetric=True loads it for renderer='volumetric' (every mesh an object with its\n"
        "volumetric amalgams baked); smooth_normals=True is --smooth-normals (meshes without\n"
        "vertex normals get smooth ones). Raises ValueError with the CLI's message on bad input.");
  m.def("save_image", &save_image, py::arg("path"), py::arg("image"),
        "save_image(path, image)\n\n"
        "Writes an H x W x 3 linear RGB image (an array or a RenderResult) as `render --out`\n"
        "does, by the extension of `path`: .png (8-bit sRGB), .exr (float32), .pfm (float32).\n"
        "Raises ValueError on a bad image or extension, RuntimeError when writing fails.");
  m.def("to_srgb", &to_srgb, py::arg("image"),
        "to_srgb(image) -> uint8 H x W x 3\n\n"
        "Linear RGB (an array or a RenderResult) encoded as the PNG output stores it: clamped\n"
        "to [0, 1], the sRGB transfer function (IEC 61966-2-1), rounded to 8 bits.");
  m.def("compare", &compare, py::arg("a"), py::arg("b"),
        "compare(a, b) -> dict\n\n"
        "Image metrics of `amalgam compare` for two H x W x 3 images (arrays or RenderResults),\n"
        "b the reference: width, height, rmse, psnr_db, ssim, mean_abs_error, max_abs_error,\n"
        "rel_mse (the names of `amalgam compare --json`).");
  m.def("experiment", &experiment, py::arg("name"), py::arg("quick") = true, py::arg("threads") = 0,
        py::arg("frame") = false,
        "experiment(name, quick=True, threads=0, frame=False) -> list[dict] | pandas.DataFrame\n\n"
        "Runs one of the paper's analyses (`amalgam experiment NAME`) and returns its table\n"
        "(the CSV's rows) as a list of dicts keyed by column, or with frame=True as a pandas\n"
        "DataFrame with the CSV's columns in order (ImportError when pandas is not installed).\n"
        "The GIL is released.");
  m.def(
      "experiment_names", [] { return experiments::names(); },
      "The experiment names in report order.");
}

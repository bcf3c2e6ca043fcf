/// \file The Python module `amalgam` (docs/python.md): the library's scene loader, renderer,
/// experiments and image metrics, with images as NumPy arrays. Wraps the library, not the CLI;
/// the option names and error messages follow the CLI's (docs/cli.md).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <climits>
#include <string>
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
#include "arguments.h"
#include "docstrings.h"
#include "support.h"

using namespace amalgam;

using namespace amalgam::python;

namespace {

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

/// An image through the CLI's writers (render --out), by extension.
void write(const std::string& path, const py::object& image) {
  int w = 0, h = 0;
  const std::vector<Vec3> px = pixels(image, "image", w, h);
  if (w == 0 || h == 0) throw InputError("image: the image is empty");
  if (!is_image_path(path))
    throw InputError(one_line(path, 200) + ": expected a .png, .exr or .pfm path");
  py::gil_scoped_release nogil;
  write_image(path, w, h, px);
}

/// `amalgam.save_image(path, image)`.
void save_image(const py::args& args, const py::kwargs& kwargs) {
  const Args a("save_image", args, kwargs, {required("path"), required("image")});
  write(a.path("path"), a["image"]);
}

/// `RenderResult.save(path)`.
void save(const py::object& self, const py::args& args, const py::kwargs& kwargs) {
  const Args a("RenderResult.save", args, kwargs, {required("path")});
  write(a.path("path"), self);
}

/// `RenderResult.__array__(dtype=None, copy=None)`: NumPy's protocol (copy= since NumPy 2).
py::array array(const RenderResult& r, const py::args& args, const py::kwargs& kwargs) {
  const Args a("RenderResult.__array__", args, kwargs, {positional("dtype"), positional("copy")});
  const py::object& copy = a["copy"];
  if (!copy.is_none() && !PyBool_Check(copy.ptr())) a.wrong_type("copy", "bool or None");
  const bool always = copy.ptr() == Py_True, never = copy.ptr() == Py_False;
  const py::dtype want = a["dtype"].is_none() ? r.image.dtype() : py::dtype::from_args(a["dtype"]);
  if (want.is(r.image.dtype()) || want.equal(r.image.dtype()))
    return always ? py::array(r.image.attr("copy")()) : r.image;
  if (never)
    throw InputError("copy=False: the image is float32; dtype=" +
                     py::str(py::handle(want)).cast<std::string>() + " needs a copy");
  return r.image.attr("astype")(want);
}

/// `amalgam.to_srgb`: linear RGB as the 8-bit sRGB a PNG stores (the same rounding).
py::array_t<std::uint8_t> to_srgb(const py::args& args, const py::kwargs& kwargs) {
  const Args a("to_srgb", args, kwargs, {required("image")});
  int w = 0, h = 0;
  const std::vector<Vec3> px = pixels(a["image"], "image", w, h);
  py::array_t<std::uint8_t> out(
      {static_cast<py::ssize_t>(h), static_cast<py::ssize_t>(w), py::ssize_t{3}});
  std::uint8_t* d = out.mutable_data();
  for (std::size_t i = 0; i < px.size(); ++i)
    for (int k = 0; k < 3; ++k) d[3 * i + static_cast<std::size_t>(k)] = encode_srgb8(px[i][k]);
  return out;
}

py::dict compare(const py::args& args, const py::kwargs& kwargs) {
  const Args arg("compare", args, kwargs, {required("a"), required("b")});
  int wa = 0, ha = 0, wb = 0, hb = 0;
  const std::vector<Vec3> pa = pixels(arg["a"], "a", wa, ha), pb = pixels(arg["b"], "b", wb, hb);
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

py::object experiment(const py::args& args, const py::kwargs& kwargs) {
  const Args a("experiment", args, kwargs,
               {required("name"), positional("quick", py::bool_(true)),
                positional("threads", py::int_(0)), positional("frame", py::bool_(false))});
  const std::string name = a.text("name");
  const auto& names = experiments::names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string all;
    for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
    throw InputError("experiment " + one_line(name, 40) + ": unknown (one of: " + all + ")");
  }
  experiments::ExperimentResult r;
  experiments::Config config;
  config.quick = a.flag("quick");
  config.threads = static_cast<int>(a.integer("threads", 0, INT_MAX));
  const bool frame = a.flag("frame");
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

/// The library's classification (util/error.h, error_kind), as the CLI's exit status follows
/// it: bad input -> ValueError (exit 2), a failed run and a bug of ours -> RuntimeError
/// (exit 1); a builtin parameter no builtin reads -> TypeError, as Python raises for an
/// unexpected keyword argument. Other exceptions (out of memory, Python's own from a
/// callback, the TypeErrors of arguments.h) keep pybind11's translation.
void translate(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const UnknownParameter& e) {
    PyErr_SetString(PyExc_TypeError, e.what());
  } catch (const InputError& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
  } catch (const RuntimeError& e) {
    PyErr_SetString(PyExc_RuntimeError, e.what());
  } catch (const std::logic_error& e) {  // InternalError and every other logic_error
    PyErr_SetString(PyExc_RuntimeError, (std::string("internal error: ") + e.what()).c_str());
  }
}

void bind_result(py::module_& m) {
  py::class_<RenderResult, std::shared_ptr<RenderResult>>(
      m, "RenderResult",
      "The outputs of Scene.render (docs/outputs.md). Pixel (x, y) is [y, x], row 0 at the top.\n"
      "numpy.asarray(result) is the image.")
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
      .def("save", &save, doc::kSave)
      .def("__array__", &array, doc::kArray)
      .def("__repr__", [](const RenderResult& r) {
        return "<amalgam.RenderResult " + std::to_string(r.width) + "x" + std::to_string(r.height) +
               ", " + std::to_string(r.spp) + " spp" + (r.interrupted ? ", interrupted" : "") + ">";
      });
}

}  // namespace

PYBIND11_MODULE(amalgam, m) {
  m.doc() =
      "amalgam: a ray tracer after Thompson & Fussell 1991, 'Time Costs of Ray Tracing with\n"
      "Amalgams', with exact cost statistics.\n\n"
      "  scene = amalgam.load('builtin:line', n=4)        # built and baked once\n"
      "  r = scene.render(width=256, height=256, spp=4)   # r.image: float32 H x W x 3\n"
      "  r.cost, r.stats                                  # tests per pixel, stats dict\n"
      "  numpy.asarray(r)                                 # the image, no copy\n"
      "  amalgam.compare(r, reference)                    # rmse, psnr_db, ssim, ...\n"
      "  amalgam.experiment('expected', quick=True)       # the table as a list of dicts\n\n"
      "Paths are str or os.PathLike; load() also takes a scene dict. Bad input raises\n"
      "ValueError, runtime failures RuntimeError, each with the CLI's one-line message (a\n"
      "bug of amalgam's: RuntimeError 'internal error: ...'); an unknown keyword or a value\n"
      "of the wrong type raises TypeError, as Python's own functions do. See docs/python.md.";
  m.attr("__version__") = version();
  m.attr("has_embree") = have_embree();  // tracer="embree" is available
  py::register_exception_translator(&translate);
  // The functions bind their own arguments (arguments.h); their docstrings begin with their
  // signatures (docstrings.h), so pybind11's (*args, **kwargs) ones are left out.
  py::options options;
  options.disable_function_signatures();
  bind_result(m);
  bind_scene(m);
  m.def("save_image", &save_image, doc::kSaveImage);
  m.def("to_srgb", &to_srgb, doc::kToSrgb);
  m.def("compare", &compare, doc::kCompare);
  m.def("experiment", &experiment, doc::kExperiment);
  m.def(
      "experiment_names",
      [](const py::args& args, const py::kwargs& kwargs) {
        Args("experiment_names", args, kwargs, {});  // no arguments
        return experiments::names();
      },
      doc::kExperimentNames);
}

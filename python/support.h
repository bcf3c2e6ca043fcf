#pragma once
/// \file What the Python module's bindings (amalgam_module.cpp, scene.cpp) are built from:
/// NumPy views of the library's vectors, checked render options, the converted result of a
/// render, and the view keywords (the CLI's --eye, --fov, ...).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "amalgam/io/stats_json.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"

namespace py = pybind11;

namespace amalgam::python {

static_assert(sizeof(Vec3) == 3 * sizeof(float), "images are viewed as float32 H x W x 3");

/// A NumPy array viewing `v`'s data without a copy: the vector moves onto the heap and the
/// array's base (a capsule) frees it with the last reference.
template <typename Elem, typename T>
py::array view(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* owner = new std::vector<T>(std::move(v));
  py::capsule base(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  std::vector<py::ssize_t> strides(shape.size());
  py::ssize_t s = sizeof(Elem);
  for (std::size_t i = shape.size(); i-- > 0;) {
    strides[i] = s;
    s *= shape[i];
  }
  return py::array(py::dtype::of<Elem>(), shape, strides,
                   reinterpret_cast<const Elem*>(owner->data()), base);
}

/// nlohmann::json -> Python objects (through the json module: the same numbers and nulls).
py::object to_python(const nlohmann::json& j);

/// Render options, checked.
struct Options {
  RenderOptions o;
};

Options make_options(int width, int height, int spp, const std::string& renderer,
                     const std::string& opacity, std::optional<int> level,
                     std::optional<float> footprint, const std::string& order, std::uint64_t seed,
                     int threads, const std::string& sampler = "independent",
                     const std::string& tracer = "amalgam");

/// What `Scene.render` returns: the image and the other outputs as NumPy arrays, and the stats.
struct RenderResult {
  int width = 0, height = 0, spp = 0, spp_requested = 0;
  bool interrupted = false;
  double seconds = 0;
  py::array image, cost, tests, depth, level, normal, albedo;
  py::object stats;
};

/// Converts a finished (or interrupted) render; needs the GIL.
std::shared_ptr<RenderResult> make_result(const LoadedScene& scene, const RenderOptions& o,
                                          RenderOutput&& r, double embree_build = 0.0);

/// A view keyword (eye=, look_at=, up=) as a Vec3; the CLI's message otherwise, naming the
/// keyword (`option` is the CLI's flag).
Vec3 view_vec(const py::handle& v, const std::string& option);

/// One view keyword (camera=, eye=, look_at=, up=, fov=: the CLI's --camera, --eye, --look-at,
/// --up, --fov) into `view`; false when `key` is not one of them.
bool view_keyword(const std::string& key, const py::handle& value, CameraChoice& view);

/// Defines `amalgam.load` and `amalgam.Scene` (scene.cpp) in `m`.
void bind_scene(py::module_& m);

}  // namespace amalgam::python

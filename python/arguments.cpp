#include "arguments.h"

#include <algorithm>

#include "amalgam/util/error.h"

namespace amalgam::python {

Param required(const char* name) {
  return Param{name, py::none(), true, true};
}
Param positional(const char* name, py::object def) {
  return Param{name, std::move(def), true};
}
Param keyword(const char* name, py::object def) {
  return Param{name, std::move(def), false};
}

std::string type_name(const py::handle& value) {
  return py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>();
}

std::optional<std::string> as_path(const py::handle& value) {
  // os.fsencode: str, bytes and os.PathLike, as the file system names them (a str's
  // surrogate escapes back to their bytes); a TypeError for anything else.
  const bool pathlike = PyUnicode_Check(value.ptr()) || PyBytes_Check(value.ptr()) ||
                        py::hasattr(py::type::handle_of(value), "__fspath__");
  if (!pathlike) return std::nullopt;
  py::object bytes = py::module_::import("os").attr("fsencode")(value);
  if (!PyBytes_Check(bytes.ptr())) return std::nullopt;
  return std::string(bytes.cast<py::bytes>());
}

namespace {

std::string plural(std::size_t n, const char* what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

}  // namespace

Args::Args(std::string name, const py::args& args, const py::kwargs& kwargs,
           std::initializer_list<Param> params, bool extra_keywords)
    : function_(std::move(name)), params_(params) {
  values_.reserve(params_.size());
  for (const Param& p : params_) values_.push_back(p.def);
  given_.assign(params_.size(), false);
  const auto n_positional = static_cast<std::size_t>(
      std::count_if(params_.begin(), params_.end(), [](const Param& p) { return p.positional; }));
  const auto n_required = static_cast<std::size_t>(std::count_if(
      params_.begin(), params_.end(), [](const Param& p) { return p.positional && p.required; }));
  if (args.size() > n_positional) {
    const std::string takes = n_required == n_positional
                                  ? plural(n_positional, "positional argument")
                                  : "from " + std::to_string(n_required) + " to " +
                                        plural(n_positional, "positional argument");
    throw py::type_error(function() + " takes " + takes + " but " + std::to_string(args.size()) +
                         (args.size() == 1 ? " was" : " were") + " given");
  }
  for (std::size_t i = 0; i < args.size(); ++i) {  // the positional parameters come first
    values_[i] = py::reinterpret_borrow<py::object>(args[i]);
    given_[i] = true;
  }
  for (auto item : kwargs) {
    const std::string key = py::str(item.first).cast<std::string>();
    const auto it =
        std::find_if(params_.begin(), params_.end(), [&](const Param& p) { return key == p.name; });
    if (it == params_.end()) {
      if (!extra_keywords)
        throw py::type_error(function() + " got an unexpected keyword argument '" + key + "'");
      extra_.emplace_back(key, py::reinterpret_borrow<py::object>(item.second));
      continue;
    }
    const auto i = static_cast<std::size_t>(it - params_.begin());
    if (given_[i])
      throw py::type_error(function() + " got multiple values for argument '" + key + "'");
    values_[i] = py::reinterpret_borrow<py::object>(item.second);
    given_[i] = true;
  }
  for (std::size_t i = 0; i < params_.size(); ++i)
    if (params_[i].required && !given_[i])
      throw py::type_error(function() + " missing 1 required " +
                           (params_[i].positional ? "positional" : "keyword-only") +
                           " argument: '" + params_[i].name + "'");
}

std::size_t Args::index(std::string_view name) const {
  for (std::size_t i = 0; i < params_.size(); ++i)
    if (name == params_[i].name) return i;
  throw std::logic_error(function_ + ": no parameter " + std::string(name));
}

const py::object& Args::operator[](std::string_view name) const {
  return values_[index(name)];
}

bool Args::given(std::string_view name) const {
  return given_[index(name)];
}

void Args::wrong_type(std::string_view name, std::string_view want) const {
  throw py::type_error(function() + " argument '" + std::string(name) + "' must be " +
                       std::string(want) + ", not " + type_name((*this)[name]));
}

namespace {

std::string str(const py::handle& x) {
  return py::str(x).cast<std::string>();
}

/// `v` (an int) within [lo, hi], compared as Python ints; InputError naming `name` otherwise.
void check_range(std::string_view name, const py::int_& v, const py::int_& lo, const py::int_& hi) {
  if (v < lo || v > hi)
    throw InputError(std::string(name) + "=" + one_line(str(v), 40) + ": expected an integer in [" +
                     str(lo) + ", " + str(hi) + "]");
}

}  // namespace

py::int_ Args::index_in(std::string_view name, const py::int_& lo, const py::int_& hi) const {
  const py::object& v = (*this)[name];
  if (PyBool_Check(v.ptr()) || !PyIndex_Check(v.ptr())) wrong_type(name, "int");
  const auto i = py::reinterpret_steal<py::int_>(PyNumber_Index(v.ptr()));
  if (!i) throw py::error_already_set();
  check_range(name, i, lo, hi);
  return i;
}

std::int64_t Args::integer(std::string_view name, std::int64_t lo, std::int64_t hi) const {
  return index_in(name, py::int_(lo), py::int_(hi)).cast<std::int64_t>();
}

std::uint64_t Args::unsigned_integer(std::string_view name, std::uint64_t lo,
                                     std::uint64_t hi) const {
  return index_in(name, py::int_(lo), py::int_(hi)).cast<std::uint64_t>();
}

std::optional<std::int64_t> Args::optional_integer(std::string_view name, std::int64_t lo,
                                                   std::int64_t hi) const {
  const py::object& v = (*this)[name];
  if (v.is_none()) return std::nullopt;
  if (PyBool_Check(v.ptr()) || !PyIndex_Check(v.ptr())) wrong_type(name, "int or None");
  return integer(name, lo, hi);
}

std::optional<double> Args::optional_number(std::string_view name) const {
  const py::object& v = (*this)[name];
  if (v.is_none()) return std::nullopt;
  const PyNumberMethods* n = Py_TYPE(v.ptr())->tp_as_number;
  const bool real = PyFloat_Check(v.ptr()) || PyIndex_Check(v.ptr()) || (n && n->nb_float);
  if (PyBool_Check(v.ptr()) || !real) wrong_type(name, "a number or None");
  const double x = PyFloat_AsDouble(v.ptr());
  if (x == -1.0 && PyErr_Occurred()) throw py::error_already_set();
  return x;
}

std::string Args::text(std::string_view name) const {
  const py::object& v = (*this)[name];
  if (!PyUnicode_Check(v.ptr())) wrong_type(name, "str");
  return v.cast<std::string>();
}

bool Args::flag(std::string_view name) const {
  const py::object& v = (*this)[name];
  if (PyBool_Check(v.ptr())) return v.ptr() == Py_True;
  if (py::isinstance(v, py::module_::import("numpy").attr("bool_"))) return v.cast<bool>();
  wrong_type(name, "bool");
}

std::string Args::path(std::string_view name) const {
  if (auto p = as_path((*this)[name])) return *p;
  wrong_type(name, "str or os.PathLike");
}

}  // namespace amalgam::python

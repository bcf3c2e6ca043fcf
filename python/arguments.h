#pragma once
/// \file The arguments of a call into the module, bound and converted as Python binds a def's:
/// every function takes (*args, **kwargs) and binds them here, so that a misspelt keyword or a
/// value of the wrong type or range is one line naming the function and the keyword
/// (`Scene.render() got an unexpected keyword argument 'sed'`, `seed=-1: expected an integer
/// in [0, 18446744073709551615]`), not pybind11's list of the overloads it tried.
///
/// Wrong types are TypeError (py::type_error), wrong values ValueError (InputError, the
/// library's bad input: the module translates it), as Python's own functions raise them.

#include <pybind11/pybind11.h>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace py = pybind11;

namespace amalgam::python {

/// One parameter of a function: its name and default. `required` has none; `positional` may
/// also be passed by position (in the order declared), else it is keyword-only.
struct Param {
  const char* name;
  py::object def = py::none();
  bool positional = false;
  bool required = false;
};

/// A required parameter that may be passed by position.
Param required(const char* name);
/// An optional parameter that may be passed by position.
Param positional(const char* name, py::object def = py::none());
/// A keyword-only parameter.
Param keyword(const char* name, py::object def = py::none());

/// A call's arguments bound to its function's parameters. Throws py::type_error with Python's
/// words on an unexpected keyword, a missing argument, too many positional arguments or an
/// argument given twice.
class Args {
 public:
  /// `name`: the function as messages name it ("load", "Scene.render"). With `extra_keywords`,
  /// keywords that name no parameter are collected (extra()) instead of refused: load's **params.
  Args(std::string name, const py::args& args, const py::kwargs& kwargs,
       std::initializer_list<Param> params, bool extra_keywords = false);

  /// The value given for `name`, else its default.
  const py::object& operator[](std::string_view name) const;
  /// True when `name` was given (by position or keyword).
  bool given(std::string_view name) const;
  /// The keywords that name no parameter, in the order given (with extra_keywords).
  const std::vector<std::pair<std::string, py::object>>& extra() const { return extra_; }
  /// "Scene.render()": the function as messages name it.
  std::string function() const { return function_ + "()"; }

  /// An integer in [lo, hi] (int or any object with __index__, such as numpy.int64; never a
  /// bool): TypeError for another type, ValueError "name=v: expected an integer in [lo, hi]".
  std::int64_t integer(std::string_view name, std::int64_t lo, std::int64_t hi) const;
  std::uint64_t unsigned_integer(std::string_view name, std::uint64_t lo, std::uint64_t hi) const;
  /// The same, None allowed (nullopt).
  std::optional<std::int64_t> optional_integer(std::string_view name, std::int64_t lo,
                                               std::int64_t hi) const;
  /// A real number (int, float or anything with __float__; not a bool), or None (nullopt).
  std::optional<double> optional_number(std::string_view name) const;
  /// A str.
  std::string text(std::string_view name) const;
  /// True or False (numpy.bool_ too).
  bool flag(std::string_view name) const;
  /// A path: str or os.PathLike (pathlib.Path), as os.fspath gives it (bytes decoded as the
  /// file system encodes names).
  std::string path(std::string_view name) const;

  /// py::type_error "F() argument 'name' must be WANT, not TYPE".
  [[noreturn]] void wrong_type(std::string_view name, std::string_view want) const;

 private:
  /// The integer given for `name` (the checks of `integer`) within [lo, hi].
  py::int_ index_in(std::string_view name, const py::int_& lo, const py::int_& hi) const;
  std::string function_;
  std::vector<Param> params_;
  std::vector<py::object> values_;
  std::vector<bool> given_;
  std::vector<std::pair<std::string, py::object>> extra_;
  std::size_t index(std::string_view name) const;
};

/// `value` as a path (str, bytes or os.PathLike), or nullopt when it is none of them.
std::optional<std::string> as_path(const py::handle& value);

/// The name of `value`'s type, as Python's messages give it ("float", "NoneType").
std::string type_name(const py::handle& value);

}  // namespace amalgam::python

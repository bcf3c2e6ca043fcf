#pragma once
/// \file `--set key=value` parameters of the builtin scenes (Python: keyword arguments of
/// `amalgam.load`), checked and typed.

#include <cstdint>
#include <map>
#include <set>
#include <string>

#include "amalgam/util/error.h"

namespace amalgam {

/// How messages name a parameter: the CLI's `--set key=value`, or a keyword argument of the
/// Python module's `load()` (`key=value`).
enum class ParamSpelling : std::uint8_t { kSet, kKeywords };

/// A key that no builtin reads (Params::check_all_used). The CLI reports it as any InputError;
/// the Python module raises TypeError, as Python does for an unexpected keyword argument.
struct UnknownParameter : InputError {
  using InputError::InputError;
};

/// The key=value pairs given with --set. Each builtin reads the keys it knows with a default
/// and then calls `check_all_used`, so a misspelt key is an error, not silently ignored.
class Params {
 public:
  Params() = default;
  explicit Params(std::string scene, ParamSpelling spelling = ParamSpelling::kSet)
      : scene_(std::move(scene)), spelling_(spelling) {}
  /// Parses "key=value"; throws InputError naming the text when it is not of that form.
  void set(const std::string& key_value);
  void set(const std::string& key, const std::string& value) { values_[key] = value; }

  std::int64_t get_int(const std::string& key, std::int64_t def, std::int64_t lo,
                       std::int64_t hi) const;
  double get_double(const std::string& key, double def, double lo, double hi) const;
  std::string get_choice(const std::string& key, const std::string& def,
                         const std::set<std::string>& allowed) const;
  /// Throws UnknownParameter for any key never read by a get_*.
  void check_all_used() const;
  /// The parameters as applied (a later --set of a key replaces an earlier one), sorted by
  /// key: "k1=v1 k2=v2".
  std::string applied() const;

 private:
  /// "<scene>: --set key=value" or "<scene>: key=value", as the messages name a value.
  std::string where(const std::string& key, const std::string& value) const;

  std::string scene_;
  ParamSpelling spelling_ = ParamSpelling::kSet;
  std::map<std::string, std::string> values_;
  mutable std::set<std::string> used_;
};

}  // namespace amalgam

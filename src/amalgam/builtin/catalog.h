#pragma once
/// \file The builtin scenes by name: `builtin:line`, `builtin:poisson`, `builtin:prisms`,
/// `builtin:demo`, their `--set` parameters and their documentation (`amalgam scenes`).

#include <string>
#include <variant>
#include <vector>

#include "amalgam/builtin/params.h"
#include "amalgam/builtin/prisms.h"
#include "amalgam/builtin/tube.h"

namespace amalgam {

/// A builtin scene: its implicit hierarchy and its lights and camera.
struct BuiltinScene {
  std::string name;  ///< as given, e.g. "builtin:prisms"
  std::variant<TubeHierarchy, PrismsHierarchy> hierarchy;
  Environment env;
};

/// A builtin scene's documentation, for `amalgam scenes`.
struct BuiltinDoc {
  std::string name;
  std::string summary;
  std::vector<std::string> params;  ///< "key (default d, range): meaning"
};
const std::vector<BuiltinDoc>& builtin_docs();

/// Makes builtin scene `spec` ("builtin:NAME" or "NAME") with `params` (every key must be
/// used). Throws InputError (one line naming the scene and the problem) on bad input.
BuiltinScene make_builtin(const std::string& spec, const Params& params);

}  // namespace amalgam

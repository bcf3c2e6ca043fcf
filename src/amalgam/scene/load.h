#pragma once
/// \file Turning a SCENE argument (`builtin:NAME` + --set parameters, or a path) into a
/// hierarchy and an environment.

#include <string>
#include <variant>
#include <vector>

#include "amalgam/builtin/params.h"
#include "amalgam/builtin/prisms.h"
#include "amalgam/builtin/tube.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"

namespace amalgam {

/// Every hierarchy a scene can load into; render.cpp's dispatch instantiates the traversal
/// for each alternative and every policy combination.
using AnyHierarchy =
    std::variant<ExplicitHierarchy, TubeHierarchy, PrismsHierarchy, InstancedHierarchy>;

struct LoadedScene {
  std::string name;
  AnyHierarchy hierarchy;
  Environment env;
  double load_seconds = 0.0;
  double build_seconds = 0.0;

  HierarchyInfo info() const {
    return std::visit([](const auto& h) { return h.info(); }, hierarchy);
  }
};

/// A builtin scene's documentation, for `amalgam scenes`.
struct BuiltinDoc {
  std::string name;
  std::string summary;
  std::vector<std::string> params;  ///< "key (default d, range): meaning"
};
const std::vector<BuiltinDoc>& builtin_docs();

/// Loads `spec`. Throws InputError (one line naming the scene and the problem) on bad input.
LoadedScene load_scene(const std::string& spec, const Params& params);

}  // namespace amalgam

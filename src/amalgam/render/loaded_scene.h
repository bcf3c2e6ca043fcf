#pragma once
/// \file What `render` and `trace` take: a built, baked hierarchy of any form with its
/// environment. Made by the front end's loader (load/load_scene.h) or, for the builtin scenes
/// alone, by `load_builtin`.

#include <string>
#include <variant>

#include "amalgam/builtin/catalog.h"
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

/// A builtin scene (builtin/catalog.h) ready to render; sets load_seconds.
LoadedScene load_builtin(const std::string& spec, const Params& params);

}  // namespace amalgam

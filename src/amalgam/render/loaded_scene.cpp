#include "amalgam/render/loaded_scene.h"

#include <chrono>

namespace amalgam {

LoadedScene load_builtin(const std::string& spec, const Params& params) {
  const auto t0 = std::chrono::steady_clock::now();
  BuiltinScene b = make_builtin(spec, params);
  LoadedScene s;
  s.name = std::move(b.name);
  std::visit([&](auto& h) { s.hierarchy = std::move(h); }, b.hierarchy);
  s.env = std::move(b.env);
  s.load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

}  // namespace amalgam

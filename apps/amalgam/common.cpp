#include "common.h"

#include <sstream>

namespace amalgam::cli {

void CommonOptions::add_to(CLI::App& app) {
  app.add_option("scene", scene, "builtin:NAME, a scene .json or a mesh file")->required();
  app.add_option("--set", sets, "builtin scene parameter key=value (repeatable)");
  app.add_option("--renderer", renderer, "scale-sensitive (default) or traditional")
      ->check(CLI::IsMember({"scale-sensitive", "traditional"}));
  app.add_option("--opacity", opacity, "stochastic (default) or deterministic")
      ->check(CLI::IsMember({"stochastic", "deterministic"}));
  app.add_option("--level", level, "scale-sensitive: render the amalgams met on level L")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--footprint", footprint,
                 "scale-sensitive without --level: render an amalgam once it is smaller than K "
                 "pixels of ray footprint (default 1)")
      ->check(CLI::PositiveNumber);
  app.add_option("--order", order, "sorted (default): nearest child first; unsorted: stored order")
      ->check(CLI::IsMember({"sorted", "unsorted"}));
  app.add_option("--seed", seed, "seed of all randomness (default 0)");
  app.add_option("--threads", threads, "worker threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
}

void CommonOptions::finish() {
  options.renderer =
      renderer == "traditional" ? RendererKind::kTraditional : RendererKind::kScaleSensitive;
  options.opacity =
      opacity == "deterministic" ? OpacityKind::kDeterministic : OpacityKind::kStochastic;
  options.sorted = order == "sorted";
  options.level = level >= 0 ? std::optional<int>(level) : std::nullopt;
  options.footprint = footprint;
  options.seed = static_cast<std::uint64_t>(seed);
  options.threads = threads;
}

Params CommonOptions::params() const {
  Params p(scene);
  for (const auto& s : sets) p.set(s);
  return p;
}

Vec3 parse_vec3(const std::string& text, const std::string& option) {
  Vec3 v;
  std::istringstream in(text);
  char c1 = 0, c2 = 0;
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() ||
      !is_finite(v))
    throw InputError(option + " '" + text + "': expected three numbers x,y,z");
  return v;
}

}  // namespace amalgam::cli

#include "amalgam/builtin/catalog.h"

#include <cmath>

namespace amalgam {
namespace {

constexpr double kMaxIndex = 0x1.0p58;  // node indices are packed into 58 bits

int read_lights(const Params& p) {
  return static_cast<int>(p.get_int("lights", 1, 1, 64));
}

BuiltinScene make_tube(const std::string& name, const Params& p, TubeHierarchy::Mode mode) {
  TubeHierarchy::Config c;
  c.mode = mode;
  c.n = static_cast<int>(p.get_int("n", mode == TubeHierarchy::Mode::kLine ? 3 : 2, 2, 64));
  c.depth = static_cast<int>(
      p.get_int("depth", mode == TubeHierarchy::Mode::kLine ? 6 : 10, 1, kMaxLevels - 2));
  if (std::pow(static_cast<double>(c.n), c.depth) >= kMaxIndex)
    throw InputError(name + ": n^depth = " + std::to_string(c.n) + "^" + std::to_string(c.depth) +
                     " exceeds 2^58 primitives");
  if (mode == TubeHierarchy::Mode::kLine) {
    c.alpha = p.get_double("alpha", 0.0, 0.0, 1.0);
  } else {
    c.p = p.get_double("p", 64.0, 1e-9, 1e15);
    c.seed = static_cast<std::uint64_t>(p.get_int("seed", 0, 0, INT64_MAX));
  }
  c.m = static_cast<int>(p.get_int("m", 0, 0, kMaxChildren - c.n));
  if (std::pow(static_cast<double>(c.n), c.depth) * (1 + c.m) >= kMaxIndex)
    throw InputError(name + ": n^depth (1 + m) objects exceed 2^58");
  const int lights = read_lights(p);
  p.check_all_used();
  TubeHierarchy h(c);
  Environment env = h.environment(lights);
  return BuiltinScene{name, std::move(h), std::move(env)};
}

BuiltinScene make_prisms(const std::string& name, const Params& p, int default_depth,
                         const std::string& default_view) {
  PrismsHierarchy::Config c;
  c.split = static_cast<int>(p.get_int("split", 2, 2, 4));
  c.depth = static_cast<int>(p.get_int("depth", default_depth, 1, 40));
  c.leaf = static_cast<int>(p.get_int("leaf", 2, 1, kMaxChildren));
  c.fill = p.get_double("fill", 0.8, 0.01, 1.0);
  const std::string view = p.get_choice("view", default_view, {"front", "corner"});
  const int lights = read_lights(p);
  p.check_all_used();
  const double cells = std::pow(static_cast<double>(c.split), c.depth - 1);
  if (cells * c.leaf >= 0x1.0p19)
    throw InputError(name + ": split^(depth-1) * leaf = " + std::to_string(cells * c.leaf) +
                     " cells along an axis exceeds 2^19");
  PrismsHierarchy h(c);
  Environment env = h.environment(view, lights);
  return BuiltinScene{name, std::move(h), std::move(env)};
}

}  // namespace

const std::vector<BuiltinDoc>& builtin_docs() {
  static const std::vector<BuiltinDoc> docs = {
      {"line",
       "The paper's Figure 3: all bounding volumes and the light lie on the default primary "
       "ray, which examines every object and hits only the last primitive it tests.",
       {"n (default 3, 2..64): children a ray meets per amalgam",
        "depth (default 6): l_max; primitives (n^depth of them) are on level l_max",
        "alpha (default 0, 0..1): opacity of every amalgam that does not hold the hit "
        "primitive (those that do are opaque)",
        "m (default 0, 0..64-n): failed objects per node, tested and missed by the default "
        "ray (\"A Second Look\")",
        "lights (default 1, 1..64): point lights, all at the camera on the line"}},
      {"prisms",
       "The paper's Figure 2: nested rectangular-prism amalgams, split^3 children each; "
       "rays orthogonal to a face meet split children per amalgam.",
       {"split (default 2, 2..4): children per axis",
        "depth (default 6): amalgam levels 0..depth-1; primitives on level depth",
        "leaf (default 2): box primitives in each bottom amalgam, stacked along z",
        "fill (default 0.8): primitive size relative to its cell; amalgam opacity = fill^2",
        "view (default front): front (down -z, centre ray orthogonal to a face) or corner",
        "lights (default 1, 1..64): directional lights"}},
      {"poisson",
       "The expected-case model (Eq. 9): hits along the default ray form a Poisson process; "
       "a level-l node is passed without a hit with probability exp(-p / n^l).",
       {"n (default 2)", "depth (default 10): l_max",
        "p (default 64): expected hits along the ray through the whole scene",
        "seed (default 0): which realisation of the process",
        "m (default 0): failed objects per node, as for line", "lights (default 1, 1..64)"}},
      {"demo",
       "The demo: builtin:prisms seen from a corner, 9 levels (33.5 million primitives); with "
       "--footprint the far amalgams are rendered as primitives.",
       {"same as prisms, with depth 9 and view corner by default"}},
  };
  return docs;
}

BuiltinScene make_builtin(const std::string& spec, const Params& params) {
  const std::string prefix = "builtin:";
  const std::string name = spec.rfind(prefix, 0) == 0 ? spec.substr(prefix.size()) : spec;
  if (name == "line") return make_tube(spec, params, TubeHierarchy::Mode::kLine);
  if (name == "poisson") return make_tube(spec, params, TubeHierarchy::Mode::kPoisson);
  if (name == "prisms") return make_prisms(spec, params, 6, "front");
  if (name == "demo") return make_prisms(spec, params, 9, "corner");
  std::string list;
  for (const auto& d : builtin_docs()) list += (list.empty() ? "" : ", ") + d.name;
  throw InputError(spec + ": unknown builtin scene (expected one of " + list + ")");
}

}  // namespace amalgam

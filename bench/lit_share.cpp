// Which surfaces a light reaches, without rendering: of the points of one mesh seen from a
// direction, the share lit from a light at angle theta from the viewer, through the triangles
// and as the volumetric cells estimate it (docs/volumetric/lit-share.md, scripts/lit_share.py).
//
//   build/bench/amalgam_lit_share scenes/volumetric/tree.json [--mesh 0] [--views 48]
//       [--lines 1500] [--lines-per-cell 4] [--elevation DEG]
//
// Per view direction v (uniform over the sphere, or looking down at --elevation degrees with a
// random azimuth, y up) lines along v across the mesh's bounding
// sphere; each first hit p is a point seen from v. For each angle theta between the direction
// back to the viewer (-v) and the light l (random azimuth about -v), one shadow ray from p
// through the triangles gives the truth (seen and lit; beside it the same weighted by the
// Lambert term of the side seen); per cell level, the cell holding p gives
// - lit share: its surfaces' lit share toward l, from the bake (CellGrid::lit_share: what a
//   closed object's cells are shaded with);
// - corrected: the same corrected by the mesh's seen-and-lit correction at that level
//   and angle (CellGrid::seen_lit, traverse/lit_ratio.h, baked from other lines and
//   directions): the volumetric renderer's `lit-share` model of an open object's own shadow;
// - march from p: the transmittance through the mesh's cells from p toward l (as
//   shadow_march with no hot spot: the cell holding the origin by the share of its mean chord
//   ahead);
// - march from space: the same from a random point of that cell (the volumetric renderer's
//   shadow origin is a point in space, the mean depth of a segment);
// - triangles from space: the shadow ray from that random point through the triangles.
// Deterministic: the same JSON for any thread count. Writes JSON to stdout.

#include <tbb/parallel_for.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "amalgam/load/load_scene.h"
#include "amalgam/math/random.h"
#include "amalgam/render/lights.h"
#include "amalgam/traverse/lit_ratio.h"
#include "amalgam/traverse/traverse.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

constexpr int kAngles = 13;  // 0, 15, ..., 180 degrees

struct Sums {
  // [angle]: seen points, of them lit through the triangles.
  std::vector<double> seen, lit, lambert, lit_lambert;
  // [level * kAngles + angle]: lit share, march from p, march from space, triangles from space,
  // and the points that had a cell at that level.
  std::vector<double> share, model, march_p, march_q, tri_q, counted;
  explicit Sums(int levels)
      : seen(kAngles),
        lit(kAngles),
        lambert(kAngles),
        lit_lambert(kAngles),
        share(levels * kAngles),
        model(levels * kAngles),
        march_p(levels * kAngles),
        march_q(levels * kAngles),
        tri_q(levels * kAngles),
        counted(levels * kAngles) {}
  void add(const Sums& o) {
    auto acc = [](std::vector<double>& a, const std::vector<double>& b) {
      for (std::size_t i = 0; i < a.size(); ++i) a[i] += b[i];
    };
    acc(seen, o.seen), acc(lit, o.lit), acc(lambert, o.lambert), acc(lit_lambert, o.lit_lambert),
        acc(share, o.share), acc(model, o.model), acc(march_p, o.march_p);
    acc(march_q, o.march_q), acc(tri_q, o.tri_q), acc(counted, o.counted);
  }
};

using Trav = Traversal<ExplicitHierarchy, TraditionalLod, StochasticOpacity, SortedOrder>;

class Measure {
 public:
  Measure(const ExplicitHierarchy& h, const CellGrid& g) : h_(h), g_(g) {}
  float elevation_deg = -100.0f;  ///< >= -90: every view looks down at this angle

  /// Transmittance through the cells of `level` from `o` toward unit `l` (no hot spot).
  float march(int level, Vec3 o, Vec3 l) const {
    float t0 = 0.0f, t1 = kInfinity;
    if (!clip_to_grid(g_, o, l, t0, t1)) return 1.0f;
    const Vec3 cs = g_.cell_size(level);
    const float chord = cs.x * cs.y * cs.z / g_.projected_area(level, l);
    const OctahedralLerp lerp = g_.lerp(-l);
    const bool inside = t0 == 0.0f;
    float tr = 1.0f;
    march_cells(g_, level, o, l, t0, t1, [&](std::uint32_t cell, float a, float b) {
      const float share = inside && a == t0 ? std::min(1.0f, (b - a) / chord) : 1.0f;
      tr *= std::pow(1.0f - g_.coverage_of(cell, lerp), share);
      return tr > 1e-4f;
    });
    return tr;
  }

  /// One view direction (index `i` of `views`): `lines` lines, every angle and level.
  void view(int i, int lines, Sums& s) const {
    Sampler u(hash_combine(0x7365656e, static_cast<std::uint64_t>(i)));  // not the bake's
    float z = 1.0f - 2.0f * u.next();
    const float phi = 2.0f * std::numbers::pi_v<float> * u.next();
    if (elevation_deg >= -90.0f) z = -std::sin(elevation_deg * std::numbers::pi_v<float> / 180.0f);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    // y is up in the scenes: a view `elevation_deg` down has v.y = z.
    const Vec3 v = elevation_deg >= -90.0f ? Vec3{r * std::cos(phi), z, r * std::sin(phi)}
                                           : Vec3{r * std::cos(phi), r * std::sin(phi), z};
    Counters counters;
    Trav trav(h_, {}, counters);
    for (int k = 0; k < lines; ++k) {
      const float u1 = u.next(), u2 = u.next();
      const TraceHit hit =
          trav.intersect(line_across(g_, v, u1, u2), static_cast<std::uint64_t>(k));
      if (hit.kind != TraceHit::Kind::kPrimitive) continue;
      for (int j = 0; j < kAngles; ++j) {
        const float theta = static_cast<float>(j) * std::numbers::pi_v<float> / (kAngles - 1);
        const Vec3 l = in_cone(-v, std::cos(theta), 1.0f, u.next());  // on the cone's rim
        s.seen[j] += 1.0;
        const float lit = shadow(trav, hit.surf.p, hit.surf.p_error, hit.surf.normal, l, k);
        s.lit[j] += lit;
        // Lambert on the side seen: what the point returns toward the viewer.
        const Vec3 seen_side = dot(hit.surf.normal, v) < 0.0f ? hit.surf.normal : -hit.surf.normal;
        const float lambert = std::max(0.0f, dot(seen_side, l));
        s.lambert[j] += lambert;
        s.lit_lambert[j] += lit * lambert;
        for (int level = 0; level < g_.levels; ++level) {
          Vec3 corner;
          const std::uint32_t c = cell_holding(g_, level, hit.surf.p, &corner);
          if (c == 0) continue;
          const Vec3 cs = g_.cell_size(level);
          const Vec3 q = corner + Vec3{cs.x * u.next(), cs.y * u.next(), cs.z * u.next()};
          const std::size_t at = static_cast<std::size_t>(level * kAngles + j);
          s.counted[at] += 1.0;
          const float sh = g_.lit_share(level, c - 1, l);
          s.share[at] += sh;
          s.model[at] += g_.seen_lit(level, v.y, std::cos(theta), sh);
          s.march_p[at] += march(level, hit.surf.p, l);
          s.march_q[at] += march(level, q, l);
          s.tri_q[at] += trav.transmittance(Ray::make(q, l), static_cast<std::uint64_t>(k));
        }
      }
    }
  }

  /// 1 when the shadow ray from surface point `p` (normal `n`) toward `l` meets no triangle.
  static float shadow(Trav& trav, Vec3 p, Vec3 err, Vec3 n, Vec3 l, int key) {
    const Vec3 side = dot(n, l) >= 0.0f ? n : -n;
    return trav.transmittance(Ray::make(offset_ray_origin(p, err, side), l),
                              static_cast<std::uint64_t>(key));
  }

 private:
  const ExplicitHierarchy& h_;
  const CellGrid& g_;
};

nlohmann::json run(const ExplicitHierarchy& h, const CellGrid& g, int views, int lines,
                   float elevation) {
  std::vector<Sums> per(static_cast<std::size_t>(views), Sums(g.levels));
  Measure m(h, g);
  m.elevation_deg = elevation;
  tbb::parallel_for(0, views, [&](int i) { m.view(i, lines, per[static_cast<std::size_t>(i)]); });
  Sums all(g.levels);
  for (const Sums& s : per) all.add(s);  // in order: the same sums for any thread count
  nlohmann::json out;
  out["levels"] = g.levels;
  out["grain"] = g.grain;
  for (int j = 0; j < kAngles; ++j) {
    nlohmann::json row;
    row["angle_deg"] = 180.0 * j / (kAngles - 1);
    row["seen"] = all.seen[j];
    row["seen_and_lit"] = all.lit[j] / std::max(all.seen[j], 1.0);
    // The same weighted by the Lambert term of the side seen (what shading returns).
    row["seen_and_lit_lambert"] = all.lit_lambert[j] / std::max(all.lambert[j], 1e-30);
    for (int level = 0; level < g.levels; ++level) {
      const std::size_t at = static_cast<std::size_t>(level * kAngles + j);
      const double n = std::max(all.counted[at], 1.0);
      row["cells"].push_back({{"level", level},
                              {"points", all.counted[at]},
                              {"lit_share", all.share[at] / n},
                              {"lit_share_corrected", all.model[at] / n},
                              {"march_from_surface", all.march_p[at] / n},
                              {"march_from_space", all.march_q[at] / n},
                              {"triangles_from_space", all.tri_q[at] / n}});
    }
    out["angles"].push_back(row);
  }
  return out;
}

}  // namespace
}  // namespace amalgam

int main(int argc, char** argv) {
  using namespace amalgam;
  CLI::App app{"The share of a mesh's seen points a light reaches, through triangles and cells"};
  std::string scene;
  int mesh = 0, views = 48, lines = 1500, lines_per_cell = 4;
  float elevation = -100.0f;
  app.add_option("scene", scene, "scene file whose mesh is measured")->required();
  app.add_option("--mesh", mesh, "the mesh's index in the scene");
  app.add_option("--views", views, "view directions")->check(CLI::Range(1, 100000));
  app.add_option("--lines", lines, "lines per view direction")->check(CLI::Range(1, 10000000));
  app.add_option("--lines-per-cell", lines_per_cell, "the bake's lines per finest-cell width")
      ->check(CLI::Range(1, 64));
  LitRatioConfig ratio;
  app.add_option("--ratio-views", ratio.views, "the seen-and-lit bake's view directions")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--ratio-lines", ratio.lines, "the seen-and-lit bake's lines per view")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--elevation", elevation,
                 "views looking down at this angle (degrees), random azimuth; default: any");
  CLI11_PARSE(app, argc, argv);
  try {
    SceneFileConfig c;
    c.objects = true;
    c.volume.lines = lines_per_cell;
    c.volume.world = false;
    LoadedScene s = load_scene_path(scene, c);
    const auto* h = std::get_if<InstancedHierarchy>(&s.hierarchy);
    if (h == nullptr || !s.volumes || mesh < 0 ||
        static_cast<std::size_t>(mesh) >= h->meshes.size() ||
        s.volumes->grid(static_cast<std::size_t>(mesh)) == nullptr)
      throw InputError(scene + ": no mesh " + std::to_string(mesh) + " with cells");
    const auto m = static_cast<std::size_t>(mesh);
    CellGrid g = *s.volumes->grid(m);
    bake_lit_ratio(h->meshes[m], g, ratio);
    nlohmann::json out = run(h->meshes[m], g, views, lines, elevation);
    out["scene"] = scene;
    out["mesh"] = mesh;
    out["views"] = views;
    out["lines"] = lines;
    out["lines_per_cell"] = lines_per_cell;
    std::cout << out.dump(1) << "\n";
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}

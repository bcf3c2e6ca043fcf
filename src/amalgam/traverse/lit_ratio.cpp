#include "amalgam/traverse/lit_ratio.h"

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/math/random.h"
#include "amalgam/traverse/traverse.h"

namespace amalgam {
namespace {

constexpr int kAngles = CellGrid::kLitAngles;
using LitTrav = Traversal<ExplicitHierarchy, TraditionalLod, StochasticOpacity, SortedOrder>;

/// Per level and angle bin: the points, those lit, the sum of their cells' lit shares.
struct LitSums {
  std::vector<double> points, lit, share;
};

void lit_view(const ExplicitHierarchy& mesh, const CellGrid& g, const LitRatioConfig& config,
              int view, LitSums& s) {
  Sampler u(hash_combine(config.seed, static_cast<std::uint64_t>(view)));
  const float z = 1.0f - 2.0f * u.next(), phi = 2.0f * std::numbers::pi_v<float> * u.next();
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const Vec3 v{r * std::cos(phi), r * std::sin(phi), z};
  Vec3 p, q;  // across -v, for the light's azimuth
  perpendiculars(-v, p, q);
  Counters counters;
  LitTrav trav(mesh, {}, counters);
  for (int k = 0; k < config.lines; ++k) {
    const float u1 = u.next(), u2 = u.next();
    const TraceHit hit = trav.intersect(line_across(g, v, u1, u2), static_cast<std::uint64_t>(k));
    if (hit.kind != TraceHit::Kind::kPrimitive) continue;
    const SurfaceHit& sh = hit.surf;
    for (int j = 0; j < kAngles; ++j) {
      // A light direction at angle j * pi / (kAngles - 1) from -v, random azimuth.
      const float theta = static_cast<float>(j) * std::numbers::pi_v<float> / (kAngles - 1);
      const float turn = 2.0f * std::numbers::pi_v<float> * u.next();
      const Vec3 l = normalize(-v * std::cos(theta) +
                               (p * std::cos(turn) + q * std::sin(turn)) * std::sin(theta));
      const Vec3 side = dot(sh.normal, l) >= 0.0f ? sh.normal : -sh.normal;
      const float lit = trav.transmittance(Ray::make(offset_ray_origin(sh.p, sh.p_error, side), l),
                                           static_cast<std::uint64_t>(k));
      for (int level = 0; level < g.levels; ++level) {
        const std::uint32_t c = cell_holding(g, level, sh.p);
        if (c == 0) continue;
        const std::size_t at = static_cast<std::size_t>(
            (level * CellGrid::kLitRises + CellGrid::rise_bin(v.y)) * kAngles + j);
        s.points[at] += 1.0;
        s.lit[at] += lit;
        s.share[at] += g.lit_share(level, c - 1, l);
      }
    }
  }
}

}  // namespace

Ray line_across(const CellGrid& g, Vec3 v, float u1, float u2) {
  Vec3 a, b;
  perpendiculars(v, a, b);
  const float radius = 0.5f * length(g.size);
  const Vec3 centre = g.lo + g.size * 0.5f;
  const Vec3 o = centre + a * ((2.0f * u1 - 1.0f) * radius) + b * ((2.0f * u2 - 1.0f) * radius);
  return Ray::make(o - v * (2.0f * radius), v);
}

std::uint32_t cell_holding(const CellGrid& g, int level, Vec3 p, Vec3* corner) {
  const Vec3 cs = g.cell_size(level);
  const int n = 1 << level;
  int c[3];
  for (int a = 0; a < 3; ++a)
    c[a] = std::clamp(static_cast<int>(std::floor((p[a] - g.lo[a]) / cs[a])), 0, n - 1);
  if (corner) *corner = g.lo + Vec3{cs.x * c[0], cs.y * c[1], cs.z * c[2]};
  return g.at(level, c[0], c[1], c[2]);
}

void bake_lit_ratio(const ExplicitHierarchy& mesh, CellGrid& g, const LitRatioConfig& config) {
  const std::size_t bins = static_cast<std::size_t>(g.levels) * CellGrid::kLitRises * kAngles;
  const std::vector<double> zero(bins);
  std::vector<LitSums> per(static_cast<std::size_t>(config.views), LitSums{zero, zero, zero});
  tbb::parallel_for(0, config.views,
                    [&](int i) { lit_view(mesh, g, config, i, per[static_cast<std::size_t>(i)]); });
  LitSums all{zero, zero, zero};
  for (const LitSums& s : per)  // in view order: the same sums for any thread count
    for (std::size_t i = 0; i < bins; ++i)
      all.points[i] += s.points[i], all.lit[i] += s.lit[i], all.share[i] += s.share[i];
  g.lit_ratio.assign(bins, 0.0f);
  for (std::size_t i = 0; i < bins; ++i) {
    if (!(all.points[i] > 0.0)) continue;
    const double seen_lit = all.lit[i] / all.points[i], share = all.share[i] / all.points[i];
    const double k = seen_lit >= share ? (seen_lit - share) / std::max(1.0 - share, 1e-9)
                                       : seen_lit / share - 1.0;
    g.lit_ratio[i] = static_cast<float>(std::clamp(k, -1.0, 1.0));
  }
}

}  // namespace amalgam

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

/// An orthonormal pair perpendicular to unit `w`.
void lit_basis(Vec3 w, Vec3& a, Vec3& b) {
  a = normalize(cross(std::fabs(w.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0}, w));
  b = cross(w, a);
}

/// The level-`level` cell (id + 1, or 0) holding point `p`.
std::uint32_t cell_holding(const CellGrid& g, int level, Vec3 p) {
  const Vec3 cs = g.cell_size(level);
  const int n = 1 << level;
  int c[3];
  for (int a = 0; a < 3; ++a)
    c[a] = std::clamp(static_cast<int>(std::floor((p[a] - g.lo[a]) / cs[a])), 0, n - 1);
  return g.at(level, c[0], c[1], c[2]);
}

/// Per level and angle bin: the points lit, and each point's lit share.
struct LitSums {
  std::vector<double> lit;
  std::vector<std::vector<float>> shares;
};

void lit_view(const ExplicitHierarchy& mesh, const CellGrid& g, const LitRatioConfig& config,
              int view, LitSums& s) {
  Sampler u(hash_combine(config.seed, static_cast<std::uint64_t>(view)));
  const float z = 1.0f - 2.0f * u.next(), phi = 2.0f * std::numbers::pi_v<float> * u.next();
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const Vec3 v{r * std::cos(phi), r * std::sin(phi), z};
  Vec3 a, b;
  lit_basis(v, a, b);
  const Vec3 centre = g.lo + g.size * 0.5f;
  const float radius = 0.5f * length(g.size);
  Counters counters;
  LitTrav trav(mesh, {}, counters);
  for (int k = 0; k < config.lines; ++k) {
    const float x = (2.0f * u.next() - 1.0f) * radius, y = (2.0f * u.next() - 1.0f) * radius;
    const TraceHit hit = trav.intersect(Ray::make(centre + a * x + b * y - v * (2.0f * radius), v),
                                        static_cast<std::uint64_t>(k));
    if (hit.kind != TraceHit::Kind::kPrimitive) continue;
    const SurfaceHit& sh = hit.surf;
    for (int j = 0; j < kAngles; ++j) {
      // A light direction at angle j * pi / (kAngles - 1) from -v, random azimuth.
      const float theta = static_cast<float>(j) * std::numbers::pi_v<float> / (kAngles - 1);
      const float turn = 2.0f * std::numbers::pi_v<float> * u.next();
      Vec3 p, q;
      lit_basis(-v, p, q);
      const Vec3 l = normalize(-v * std::cos(theta) +
                               (p * std::cos(turn) + q * std::sin(turn)) * std::sin(theta));
      const Vec3 side = dot(sh.normal, l) >= 0.0f ? sh.normal : -sh.normal;
      const float lit = trav.transmittance(Ray::make(offset_ray_origin(sh.p, sh.p_error, side), l),
                                           static_cast<std::uint64_t>(k));
      for (int level = 0; level < g.levels; ++level) {
        const std::uint32_t c = cell_holding(g, level, sh.p);
        if (c == 0) continue;
        const std::size_t at = static_cast<std::size_t>(level * kAngles + j);
        s.lit[at] += lit;
        s.shares[at].push_back(g.lit_share(level, c - 1, l));
      }
    }
  }
}

/// The ratio r with sum(min(1, r x share)) = lit over `shares` (the cap applied as the
/// renderer applies it): bisection, r in [0, 64].
float solve_ratio(double lit, const std::vector<float>& shares) {
  double lo = 0.0, hi = 64.0;
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    double sum = 0.0;
    for (const float x : shares) sum += std::min(1.0, mid * x);
    (sum < lit ? lo : hi) = mid;
  }
  return static_cast<float>(0.5 * (lo + hi));
}

}  // namespace

void bake_lit_ratio(const ExplicitHierarchy& mesh, CellGrid& g, const LitRatioConfig& config) {
  const std::size_t bins = static_cast<std::size_t>(g.levels) * kAngles;
  std::vector<LitSums> per(
      static_cast<std::size_t>(config.views),
      LitSums{std::vector<double>(bins), std::vector<std::vector<float>>(bins)});
  tbb::parallel_for(0, config.views,
                    [&](int i) { lit_view(mesh, g, config, i, per[static_cast<std::size_t>(i)]); });
  g.lit_ratio.assign(bins, 1.0f);
  tbb::parallel_for(std::size_t{0}, bins, [&](std::size_t i) {
    double lit = 0.0;
    std::vector<float> shares;
    for (const LitSums& s : per) {  // in view order: the same for any thread count
      lit += s.lit[i];
      shares.insert(shares.end(), s.shares[i].begin(), s.shares[i].end());
    }
    if (lit > 0.0 && !shares.empty()) g.lit_ratio[i] = solve_ratio(lit, shares);
  });
}

}  // namespace amalgam

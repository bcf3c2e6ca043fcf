// Volumetric amalgams (hierarchy/volume/cells.h): the bake and the cone march together.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/math/random.h"
#include "amalgam/traverse/cone_march.h"
#include "amalgam/traverse/traverse.h"
#include "leaves.h"

namespace amalgam {
namespace {

/// `n` small random quads (two triangles each) in a ball of radius 1: foliage.
std::vector<Primitive> sphere(float r, int level) {
  std::vector<std::array<Vec3, 3>> f = {
      {Vec3{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},    {Vec3{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}},
      {Vec3{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}},  {Vec3{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
      {Vec3{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},   {Vec3{-1, 0, 0}, {0, 1, 0}, {0, 0, -1}},
      {Vec3{0, -1, 0}, {-1, 0, 0}, {0, 0, -1}}, {Vec3{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}};
  for (int l = 0; l < level; ++l) {
    std::vector<std::array<Vec3, 3>> g;
    for (const auto& t : f) {
      const Vec3 ab = normalize(t[0] + t[1]), bc = normalize(t[1] + t[2]),
                 ca = normalize(t[2] + t[0]);
      g.push_back({t[0], ab, ca});
      g.push_back({t[1], bc, ab});
      g.push_back({t[2], ca, bc});
      g.push_back({ab, bc, ca});
    }
    f = g;
  }
  std::vector<Primitive> out;
  for (const auto& t : f) out.push_back({PrimKind::kTriangle, 0, t[0] * r, t[1] * r, t[2] * r});
  return out;
}

/// Over `lines` random lines parallel to unit `d` through the disc that holds the cube's
/// silhouette, per level: the mean of 1 - the product of (1 - coverage) over the cells each
/// crosses (what the cone march composites), the mean of the sum of their first-hit
/// coverages; and the fraction of the lines that hit a triangle.
struct ColumnSums {
  std::vector<double> occluded, sum;  ///< per level
  double hit = 0;
};
ColumnSums column_sums(const CellGrid& g, const ExplicitHierarchy& h, Vec3 d, int lines) {
  ColumnSums out;
  out.sum.assign(static_cast<std::size_t>(g.levels), 0.0);
  out.occluded.assign(static_cast<std::size_t>(g.levels), 0.0);
  Vec3 u = normalize(cross(std::fabs(d.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0}, d));
  const Vec3 v = cross(d, u);
  const Vec3 centre = g.lo + g.size * 0.5f;
  const float radius = 0.5f * length(g.size);
  Sampler s(77);
  const OctahedralLerp lerp = g.lerp(d);
  Counters counters;
  Traversal<ExplicitHierarchy, TraditionalLod, StochasticOpacity, SortedOrder> trav(h, {},
                                                                                    counters);
  for (int i = 0; i < lines; ++i) {
    const float x = (2 * s.next() - 1) * radius, y = (2 * s.next() - 1) * radius;
    const Vec3 o = centre + u * x + v * y - d * (2 * radius);
    const Ray ray = Ray::make(o, d);
    out.hit += trav.intersect(ray, static_cast<std::uint64_t>(i)).kind != TraceHit::Kind::kNone;
    for (int L = 0; L < g.levels; ++L) {
      float t0 = 0, t1 = kInfinity;
      if (!clip_to_grid(g, o, d, t0, t1)) continue;
      double sum = 0, through = 1;
      march_cells(g, L, o, d, t0, t1, [&](std::uint32_t c, float, float) {
        sum += g.first_hit_of(c, lerp);
        through *= 1.0 - g.coverage_of(c, lerp);
        return true;
      });
      out.sum[static_cast<std::size_t>(L)] += sum;
      out.occluded[static_cast<std::size_t>(L)] += 1.0 - through;
    }
  }
  out.hit /= lines;
  for (double& x : out.sum) x /= lines;
  for (double& x : out.occluded) x /= lines;
  return out;
}

void expect_sums_match(const std::vector<Primitive>& prims, const char* what) {
  VolumeConfig cfg;
  cfg.levels = 6;
  const ExplicitHierarchy h = build_explicit(prims, {Surface{}});
  const CellGrid g = bake_cells(h, cfg);
  ASSERT_GT(g.cells(), 0u);
  for (Vec3 d : {normalize(Vec3{0.3f, -0.8f, 0.5f}), normalize(Vec3{1, 0.02f, 0.01f}),
                 octahedral_bin_dir(27, g.dir_res), normalize(Vec3{0, -0.573f, -0.819f})}) {
    const ColumnSums c = column_sums(g, h, d, 20000);
    for (int L = 0; L < g.levels; ++L) {
      SCOPED_TRACE(std::string(what) + " level " + std::to_string(L) + " d = " +
                   std::to_string(d.x) + "," + std::to_string(d.y) + "," + std::to_string(d.z));
      EXPECT_NEAR(c.sum[static_cast<std::size_t>(L)], c.hit, 0.015 * c.hit + 0.003);
      // The finest level has the fewest lines per cell in the bake (16 across a face): there a
      // cell's coverage is more often clamped to 1 (more first hits than the march leaves of
      // its lines), measured 2-5 % low for the leaves; 0.3-1 % on the levels between. On the
      // two coarsest levels a direction near an axis and an edge of the octahedral map (its
      // four bins on both sides of a fold) gives up to 3.6 % too much.
      const double tol = L + 1 == g.levels ? 0.06 : L <= 1 ? 0.04 : 0.015;
      EXPECT_NEAR(c.occluded[static_cast<std::size_t>(L)], c.hit, tol * c.hit + 0.003);
    }
  }
}

// The property the volumetric renderer's mean rests on: along parallel lines, the coverages of
// the cells a line crosses, composited front to back, occlude on average as often as the mesh
// itself, on every level; and the first-hit coverages add up to the same (cells.h).
TEST(VolumeCells, CoverageAlongLinesMatchesTheHitProbability) {
  expect_sums_match(leaves(3000, 5), "leaves");
  expect_sums_match(sphere(0.7f, 4), "sphere");
}

}  // namespace
}  // namespace amalgam

namespace amalgam {
namespace {

/// The area-weighted mean normal of cell 0 (the root) of `g`, from its normal histogram.
Vec3 root_mean_normal(const CellGrid& g) {
  Vec3 sum{};
  for (int k = 0; k < g.normal_bins(); ++k)
    sum += g.normal_dirs[static_cast<std::size_t>(k)] *
           static_cast<float>(g.normals[static_cast<std::size_t>(k)]);
  return normalize(sum);
}

// The cells' normal distribution holds the normals the triangles are shaded with: a flat quad
// whose vertex normals all lean 45 degrees puts its area at the leaning normal.
TEST(VolumeCells, NormalHistogramsHoldTheInterpolatedNormals) {
  const std::vector<Primitive> quad = {Primitive::triangle({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, 0),
                                       Primitive::triangle({0, 0, 0}, {1, 1, 0}, {0, 1, 0}, 0)};
  VertexNormals lean;
  for (Vec3& n : lean.n) n = normalize(Vec3{1, 0, 1});
  const ExplicitHierarchy smooth = build_explicit(quad, {Surface{}}, {}, {}, {}, {lean, lean});
  const ExplicitHierarchy flat = build_explicit(quad, {Surface{}});
  const Vec3 s = root_mean_normal(bake_cells(smooth)), f = root_mean_normal(bake_cells(flat));
  EXPECT_GT(std::fabs(dot(s, lean.n[0])), 0.99f) << s.x << " " << s.y << " " << s.z;
  EXPECT_GT(std::fabs(f.z), 0.99f) << f.x << " " << f.y << " " << f.z;
}

}  // namespace
}  // namespace amalgam

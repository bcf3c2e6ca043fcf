// The bake's opacity against expectations that do not come from the bake: values worked by
// hand with Cauchy's formula, and an independent Monte Carlo over isotropic lines written here
// (a uniform direction and a uniform point on a disc across it: the motion-invariant line
// measure, not the bake's face-and-cosine sampling of bake/lines.h). Both bakes, "exact"
// (lines traced against the subtree) and "combined" (children's appearances composed), must
// meet them; comparing the two with each other alone would pass if both were wrong alike.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/hierarchy/explicit.h"

namespace amalgam {
namespace {

/// An axis-aligned square {x_axis = at, |other coordinates| <= half} as two triangles.
void add_square(std::vector<Primitive>& out, int axis, float at, float half = 1.0f) {
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  Vec3 p[4];
  for (int k = 0; k < 4; ++k) {
    p[k][axis] = at;
    p[k][i] = (k == 1 || k == 2) ? half : -half;
    p[k][j] = k >= 2 ? half : -half;
  }
  out.push_back(Primitive::triangle(p[0], p[1], p[2]));
  out.push_back(Primitive::triangle(p[0], p[2], p[3]));
}

/// Tiny triangles at two opposite corners: they make the box [-1, 1]^3 and block (almost) no
/// line.
void add_corners(std::vector<Primitive>& out) {
  out.push_back(Primitive::triangle({-1, -1, -1}, {-1, -1, -0.999f}, {-1, -0.999f, -1}));
  out.push_back(Primitive::triangle({1, 1, 1}, {1, 1, 0.999f}, {1, 0.999f, 1}));
}

struct Square {
  int axis;
  float at, half;
};

/// Monte Carlo, independent of the bake: the fraction of isotropic random lines meeting `box`
/// that cross at least one of `squares`.
double line_hit_fraction(const Bbox& box, const std::vector<Square>& squares, int lines,
                         std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double cx = 0.5 * (box.lo.x + box.hi.x), cy = 0.5 * (box.lo.y + box.hi.y),
               cz = 0.5 * (box.lo.z + box.hi.z);
  const double c[3] = {cx, cy, cz};
  const double radius =
      0.5 * std::sqrt(std::pow(box.hi.x - box.lo.x, 2) + std::pow(box.hi.y - box.lo.y, 2) +
                      std::pow(box.hi.z - box.lo.z, 2));
  int met = 0, hit = 0;
  while (met < lines) {
    // Direction uniform on the sphere; an orthonormal frame across it.
    const double z = 1 - 2 * u(rng), phi = 2 * std::numbers::pi * u(rng);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const double d[3] = {r * std::cos(phi), r * std::sin(phi), z};
    const double a[3] = {std::fabs(d[0]) < 0.9 ? 1.0 : 0.0, std::fabs(d[0]) < 0.9 ? 0.0 : 1.0, 0};
    double e1[3] = {a[1] * d[2] - a[2] * d[1], a[2] * d[0] - a[0] * d[2],
                    a[0] * d[1] - a[1] * d[0]};
    const double n1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (double& v : e1) v /= n1;
    const double e2[3] = {d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2],
                          d[0] * e1[1] - d[1] * e1[0]};
    // A uniform point on the disc of the bounding sphere's radius across the direction.
    double s, t;
    do {
      s = 2 * u(rng) - 1, t = 2 * u(rng) - 1;
    } while (s * s + t * t > 1);
    double p[3];
    for (int k = 0; k < 3; ++k) p[k] = c[k] + radius * (s * e1[k] + t * e2[k]);
    // Does the line p + t d meet the box (slabs)?
    double t0 = -1e300, t1 = 1e300;
    const double lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
    for (int k = 0; k < 3; ++k) {
      if (d[k] == 0) {
        if (p[k] < lo[k] || p[k] > hi[k]) t0 = 1, t1 = 0;
        continue;
      }
      const double ta = (lo[k] - p[k]) / d[k], tb = (hi[k] - p[k]) / d[k];
      t0 = std::max(t0, std::min(ta, tb));
      t1 = std::min(t1, std::max(ta, tb));
    }
    if (t0 > t1) continue;
    ++met;
    for (const Square& sq : squares) {
      if (d[sq.axis] == 0) continue;
      const double tt = (sq.at - p[sq.axis]) / d[sq.axis];
      const int i = (sq.axis + 1) % 3, j = (sq.axis + 2) % 3;
      if (std::fabs(p[i] + tt * d[i]) <= sq.half && std::fabs(p[j] + tt * d[j]) <= sq.half) {
        ++hit;
        break;
      }
    }
  }
  return static_cast<double>(hit) / lines;
}

/// Four standard errors of a fraction q estimated from n lines, plus `extra`.
double tolerance(double q, int n, double extra = 0) {
  return 4 * std::sqrt(q * (1 - q) / n) + extra;
}

BuildConfig exact_bake(int rays) {
  BuildConfig c;
  c.bake.exact_prims = 1000;  // every node traced against its whole subtree
  c.bake.rays = rays;
  return c;
}

// A square filling one face of the box [-1, 1]^3. Every line crossing a convex box enters and
// leaves it once through its surface, uniformly by area under the isotropic measure (Cauchy):
// it crosses a given face of the cube with probability 2 x 4 / 24 = 1/3. The square lies on
// the box's boundary, where the bake's lines start: a hit there must count.
TEST(BakeOpacity, SquareFillingABoxFaceIsOneThirdByCauchy) {
  const int rays = 4096;
  for (const auto& [axis, at] : {std::pair{0, -1.0f}, std::pair{1, 1.0f}, std::pair{2, -1.0f}}) {
    std::vector<Primitive> prims;
    add_square(prims, axis, at);
    add_corners(prims);
    const ExplicitHierarchy h = build_explicit(prims, {Surface{}}, exact_bake(rays));
    ASSERT_EQ(h.nodes[0].bounds, (Bbox{{-1, -1, -1}, {1, 1, 1}}));
    const double want = 1.0 / 3.0;
    EXPECT_NEAR(h.appearances[0].opacity, want, tolerance(want, rays))
        << "square on the face " << (at < 0 ? "-" : "+") << "xyz"[axis];
  }
  // The independent Monte Carlo agrees with Cauchy's 1/3 (so it can judge the cases below).
  EXPECT_NEAR(line_hit_fraction({{-1, -1, -1}, {1, 1, 1}}, {{0, -1.0f, 1.0f}}, 200000, 1),
              1.0 / 3.0, tolerance(1.0 / 3.0, 200000));
}

// Two parallel squares filling the x-faces of the box [-0.5, 0.5] x [-1, 1]^2, one per leaf:
// the combined bake composes two opaque flat children and must give the union's probability,
// as the exact bake does; the truth comes from the Monte Carlo (by Cauchy each face alone is
// crossed with probability 2 x 4 / 16 = 1/2; the union is less than 1).
TEST(BakeOpacity, CombinedAndExactBakesOfTwoParallelSquaresMeetTheMonteCarlo) {
  std::vector<Primitive> prims;
  add_square(prims, 0, -0.5f);
  add_square(prims, 0, 0.5f);
  const Bbox box{{-0.5f, -1, -1}, {0.5f, 1, 1}};
  const double truth = line_hit_fraction(box, {{0, -0.5f, 1}, {0, 0.5f, 1}}, 200000, 2);
  EXPECT_NEAR(line_hit_fraction(box, {{0, -0.5f, 1}}, 200000, 3), 0.5, tolerance(0.5, 200000))
      << "Cauchy: one x-face of this box is crossed by half of the lines";
  const int rays = 4096;
  BuildConfig combined = exact_bake(rays);
  combined.bake.exact_prims = 2;  // each square (2 triangles) exact; the root composes them
  combined.leaf_size = 2;
  const ExplicitHierarchy c = build_explicit(prims, {Surface{}}, combined);
  ASSERT_FALSE(c.nodes[0].leaf);
  ASSERT_EQ(c.nodes[0].count, 2u) << "one child per square";
  for (std::uint32_t k = 0; k < 2; ++k)
    EXPECT_GT(c.appearances[c.nodes[0].first + k].opacity, 0.99f) << "a square fills its box";
  const ExplicitHierarchy e = build_explicit(prims, {Surface{}}, exact_bake(rays));
  const double mc_error = tolerance(truth, 200000);
  EXPECT_NEAR(e.appearances[0].opacity, truth, tolerance(truth, rays, mc_error)) << "exact";
  EXPECT_NEAR(c.appearances[0].opacity, truth, tolerance(truth, rays, mc_error)) << "combined";
  EXPECT_GT(truth, 0.5);
  EXPECT_LT(truth, 1.0);
}

// Three orthogonal full squares through the centre of [-1, 1]^3 (a line misses them only
// inside one octant): the exact bake meets the Monte Carlo; the combined bake, which treats the
// overlapping children as independent, stays within its documented error of 0.12.
TEST(BakeOpacity, ThreeOrthogonalSquaresMeetTheMonteCarlo) {
  std::vector<Primitive> prims;
  for (int axis = 0; axis < 3; ++axis) add_square(prims, axis, 0.0f);
  const double truth =
      line_hit_fraction({{-1, -1, -1}, {1, 1, 1}}, {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}}, 200000, 4);
  const int rays = 4096;
  const ExplicitHierarchy e = build_explicit(prims, {Surface{}}, exact_bake(rays));
  EXPECT_NEAR(e.appearances[0].opacity, truth, tolerance(truth, rays, tolerance(truth, 200000)));
  BuildConfig combined;
  combined.bake.rays = rays;
  const ExplicitHierarchy c = build_explicit(prims, {Surface{}}, combined);
  EXPECT_NEAR(c.appearances[0].opacity, truth, 0.12);
}

}  // namespace
}  // namespace amalgam

#include "amalgam/geometry/intersect.h"

#include <gtest/gtest.h>

#include <random>

#include "amalgam/scene/scene.h"

namespace amalgam {
namespace {

const Bbox kUnit{{0, 0, 0}, {1, 1, 1}};

TEST(RayBox, HitsThroughTheMiddle) {
  auto s = intersect_box(Ray::make({0.5f, 0.5f, -1}, {0, 0, 1}), kUnit);
  ASSERT_TRUE(s);
  EXPECT_FLOAT_EQ(s->t0, 1.0f);
  EXPECT_NEAR(s->t1, 2.0f, 1e-6);
}

TEST(RayBox, MissesBesideTheBox) {
  EXPECT_FALSE(intersect_box(Ray::make({1.5f, 0.5f, -1}, {0, 0, 1}), kUnit));
  EXPECT_FALSE(intersect_box(Ray::make({0.5f, 0.5f, -1}, {0, 0, -1}), kUnit)) << "behind";
}

TEST(RayBox, AxisParallelRayOnAFacePlaneCountsAsInside) {
  // Origin exactly on the slab planes x = 0 and y = 1, direction along z: 0 * inf must not
  // poison the test.
  EXPECT_TRUE(intersect_box(Ray::make({0, 1, -1}, {0, 0, 1}), kUnit));
  EXPECT_TRUE(intersect_box(Ray::make({1, 0, -1}, {0, 0, 1}), kUnit));
}

TEST(RayBox, RaysThroughCornersAndAlongEdgesHit) {
  // Diagonal through two opposite corners.
  EXPECT_TRUE(intersect_box(Ray::make({-1, -1, -1}, normalize({1, 1, 1})), kUnit));
  // Grazing the edge x = 1, z = 0 at 45 degrees in the xz plane.
  EXPECT_TRUE(intersect_box(Ray::make({2, 0.5f, -1}, normalize({-1, 0, 1})), kUnit));
  // Many random rays through random corners of a box far from the origin.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  const Bbox far{{1000.125f, -3.5f, 77.25f}, {1003.5f, 2.0f, 80.0f}};
  for (int i = 0; i < 20000; ++i) {
    const Vec3 corner{(i & 1) ? far.hi.x : far.lo.x, (i & 2) ? far.hi.y : far.lo.y,
                      (i & 4) ? far.hi.z : far.lo.z};
    const Vec3 o = corner + Vec3{u(rng), u(rng), u(rng)} * 50.0f;
    ASSERT_TRUE(intersect_box(Ray::make(o, corner - o), far)) << i;
  }
}

TEST(RayBox, TIntervalIsRespected) {
  Ray r = Ray::make({0.5f, 0.5f, -1}, {0, 0, 1}, 0.0f, 0.5f);
  EXPECT_FALSE(intersect_box(r, kUnit)) << "box beyond tmax";
  r.tmax = 10;
  r.tmin = 3;
  EXPECT_FALSE(intersect_box(r, kUnit)) << "box before tmin";
}

TEST(RayTriangle, HitsInsideMissesOutside) {
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  auto h = intersect_triangle(Ray::make({0.25f, 0.25f, 1}, {0, 0, -1}), a, b, c);
  ASSERT_TRUE(h);
  EXPECT_FLOAT_EQ(h->t, 1.0f);
  EXPECT_FLOAT_EQ(h->normal.z, 1.0f) << "normal faces the ray";
  EXPECT_NEAR(h->p.x, 0.25f, 1e-6);
  EXPECT_FALSE(intersect_triangle(Ray::make({0.75f, 0.75f, 1}, {0, 0, -1}), a, b, c));
}

TEST(RayTriangle, SharedEdgesAndVerticesAreWatertight) {
  // A square of two triangles sharing the diagonal, and a fan of 8 triangles around a vertex.
  const Vec3 p00{0, 0, 0}, p10{1, 0, 0}, p01{0, 1, 0}, p11{1, 1, 0};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0, 1);
  for (int i = 0; i < 100000; ++i) {
    const float s = u(rng);
    const Vec3 on_diagonal{s, 1 - s, 0};
    const Vec3 o = on_diagonal + Vec3{u(rng) - 0.5f, u(rng) - 0.5f, 1.0f + u(rng)};
    const Ray r = Ray::make(o, on_diagonal - o);
    const bool hit = intersect_triangle(r, p00, p10, p01) || intersect_triangle(r, p10, p11, p01);
    ASSERT_TRUE(hit) << "ray " << i << " slipped through the shared edge";
  }
  const Vec3 centre{0.3f, 0.7f, 0.1f};
  Vec3 ring[8];
  for (int k = 0; k < 8; ++k) {
    const float ang = 2.0f * 3.14159265f * k / 8;
    ring[k] = centre + Vec3{std::cos(ang), std::sin(ang), 0.05f * k};
  }
  for (int i = 0; i < 20000; ++i) {
    const Vec3 o = centre + Vec3{u(rng) - 0.5f, u(rng) - 0.5f, 2.0f};
    const Ray r = Ray::make(o, centre - o);
    bool hit = false;
    for (int k = 0; k < 8; ++k)
      hit |= bool(intersect_triangle(r, centre, ring[k], ring[(k + 1) % 8]));
    ASSERT_TRUE(hit) << "ray " << i << " slipped through the shared vertex";
  }
}

TEST(RayTriangle, SmallTriangleFarAwayIsHit) {
  // Half-millimetre triangles 240 m from the origin, as a subdivided Wuson seen across
  // scenes/demo-field-fine.json: every ray aimed well inside one hits it. (The rounding bound on
  // t, which grows with the distance, used to exceed t itself and reject them.)
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  const Vec3 origin{0, 14, 135};
  int hits = 0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    const Vec3 centre{200.0f * (u(rng) - 0.5f), 0.5f * u(rng), -100.0f - 10.0f * u(rng)};
    const Vec3 a = centre, b = centre + Vec3{5e-4f, 1e-4f * u(rng), 0},
               c = centre + Vec3{1.5e-4f * u(rng), 5e-4f, 2.5e-4f * (u(rng) - 0.5f)};
    const float s = 0.2f + 0.3f * u(rng), t = 0.2f + 0.3f * u(rng);
    const Vec3 target = a + (b - a) * s + (c - a) * t;
    const auto h = intersect_triangle(Ray::make(origin, normalize(target - origin)), a, b, c);
    if (h) {
      ++hits;
      EXPECT_NEAR(h->t, length(target - origin), 1e-3f);
    }
  }
  EXPECT_EQ(hits, n);
}

TEST(RayTriangle, DegenerateTriangleNeverHitsNorCrashes) {
  const Vec3 a{0, 0, 0};
  EXPECT_FALSE(intersect_triangle(Ray::make({0, 0, 1}, {0, 0, -1}), a, a, a));
  EXPECT_FALSE(intersect_triangle(Ray::make({0.5f, 0, 1}, {0, 0, -1}), a, {1, 0, 0}, {2, 0, 0}));
}

TEST(RaySphere, HitsNearSideFirstAndFromInside) {
  auto h = intersect_sphere(Ray::make({0, 0, -5}, {0, 0, 1}), {0, 0, 0}, 1.0f);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, 4.0f, 1e-6);
  EXPECT_NEAR(h->normal.z, -1.0f, 1e-6);
  auto inside = intersect_sphere(Ray::make({0, 0, 0}, {1, 0, 0}), {0, 0, 0}, 2.0f);
  ASSERT_TRUE(inside);
  EXPECT_NEAR(inside->t, 2.0f, 1e-6);
  EXPECT_FALSE(intersect_sphere(Ray::make({0, 1.01f, -5}, {0, 0, 1}), {0, 0, 0}, 1.0f));
  EXPECT_TRUE(intersect_sphere(Ray::make({0, 0.999f, -5}, {0, 0, 1}), {0, 0, 0}, 1.0f));
}

TEST(RaySphere, FarAwaySphereIsAccurate) {
  // The reprojected hit point lies on the sphere even when the ray comes from far away.
  auto h = intersect_sphere(Ray::make({-1e7f, 0.1f, 0}, {1, 0, 0}), {0, 0, 0}, 0.5f);
  ASSERT_TRUE(h);
  EXPECT_NEAR(length(h->p), 0.5f, 1e-6);
}

TEST(SolidBox, EntryFaceAndOriginInside) {
  auto h = intersect_solid_box(Ray::make({0.5f, 0.5f, 3}, {0, 0, -1}), kUnit);
  ASSERT_TRUE(h);
  EXPECT_FLOAT_EQ(h->t, 2.0f);
  EXPECT_EQ(h->p.z, 1.0f) << "snapped onto the face";
  EXPECT_EQ(h->normal.z, 1.0f);
  auto in = intersect_solid_box(Ray::make({0.5f, 0.5f, 0.5f}, {1, 0, 0}), kUnit);
  ASSERT_TRUE(in);
  EXPECT_NEAR(in->t, 0.5f, 1e-6);
}

TEST(OffsetOrigin, LeavesTheSurfaceOnTheNormalSide) {
  const Vec3 p{1e6f, 3.0f, -2.0f};
  const Vec3 o = offset_ray_origin(p, {0, 0, 0}, {1, 0, 0});
  EXPECT_GT(o.x, p.x);
  EXPECT_EQ(o.y, p.y);
  const Vec3 q = offset_ray_origin(p, {0.5f, 0, 0}, {-1, 0, 0});
  EXPECT_LT(q.x, p.x - 0.5f);
}

}  // namespace
}  // namespace amalgam

// scene/instance_patterns.h, scene/subdivide.h and scene/framing.h: the pure functions a scene
// file's "grid", "scatter" and "subdivide" and a bare mesh's default view are made of.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "amalgam/scene/framing.h"
#include "amalgam/scene/instance_patterns.h"
#include "amalgam/scene/subdivide.h"

namespace amalgam {
namespace {

TEST(InstancePatterns, GridIsCentredOnItsOriginXFastest) {
  const std::vector<AffineD> g = grid_placements({3, 2, 1.5, {1, 2, 3}});
  ASSERT_EQ(g.size(), 6u);
  EXPECT_EQ(g[0].point({0, 0, 0}), (Vec3{-0.5f, 2, 2.25f}));
  EXPECT_EQ(g[1].point({0, 0, 0}), (Vec3{1, 2, 2.25f}));
  EXPECT_EQ(g[5].point({0, 0, 0}), (Vec3{2.5f, 2, 3.75f}));
  for (const AffineD& a : g) EXPECT_EQ(a.vector({1, 2, 3}), (Vec3{1, 2, 3})) << "translations";
}

TEST(InstancePatterns, ScatterStaysOnItsDiscAndEachPlacementDependsOnlyOnSeedAndIndex) {
  const ScatterPattern p{200, 5.0, 7, {1, -2, 1}, true};
  const std::vector<AffineD> s = scatter_placements(p);
  ASSERT_EQ(s.size(), 200u);
  bool turned = false;
  for (const AffineD& a : s) {
    const Vec3 c = a.point({0, 0, 0});
    EXPECT_EQ(c.y, -2.0f);
    EXPECT_LE(std::hypot(c.x - 1.0, c.z - 1.0), 5.0 + 1e-5);
    EXPECT_NEAR(std::fabs(a.det()), 1.0, 1e-12) << "a rotation";
    turned = turned || a.vector({1, 0, 0}) != Vec3{1, 0, 0};
  }
  EXPECT_TRUE(turned);
  ScatterPattern fewer = p;
  fewer.count = 10;
  const std::vector<AffineD> f = scatter_placements(fewer);
  for (std::size_t i = 0; i < f.size(); ++i)
    EXPECT_EQ(f[i].point({1, 2, 3}), s[i].point({1, 2, 3}));
  ScatterPattern still = p;
  still.rotate = false;
  for (const AffineD& a : scatter_placements(still))
    EXPECT_EQ(a.vector({1, 0, 0}), (Vec3{1, 0, 0}));
  ScatterPattern other = p;
  other.seed = 8;
  EXPECT_NE(scatter_placements(other)[0].point({0, 0, 0}), s[0].point({0, 0, 0}));
}

double area(const std::vector<Primitive>& tris) {
  double a = 0;
  for (const Primitive& t : tris) a += 0.5 * length(cross(t.b - t.a, t.c - t.a));
  return a;
}

TEST(Subdivide, FourTimesTheTrianglesPerLevelOnTheSameSurface) {
  const std::vector<Primitive> one = {Primitive::triangle({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, 3)};
  EXPECT_EQ(subdivide(one, 0).size(), 1u);
  const std::vector<Primitive> fine = subdivide(one, 3);
  ASSERT_EQ(fine.size(), 64u);
  EXPECT_NEAR(area(fine), area(one), 1e-5);
  for (const Primitive& t : fine) {
    EXPECT_EQ(t.material, 3u);
    EXPECT_EQ(t.a.z, 0.0f);
    EXPECT_GE(std::min({t.a.x, t.b.x, t.c.x, t.a.y, t.b.y, t.c.y}), 0.0f);
    EXPECT_LE(std::max({t.a.x + t.a.y, t.b.x + t.b.y, t.c.x + t.c.y}), 4.0f);
  }
}

TEST(Framing, TheDefaultCameraSeesTheWholeBoundsAndTheFillLightSitsAtIt) {
  const Bbox b{{-1, 0, -2}, {3, 2, 2}};
  const Camera c = frame_camera(b);
  EXPECT_EQ(c.look_at, b.center());
  EXPECT_GT(c.position.y, b.center().y) << "from above";
  // The bounding sphere fits in the vertical field of view.
  const float d = length(c.position - b.center());
  EXPECT_LE(std::asin(0.5f * b.diagonal() / d) * 180.0f / 3.14159265f, c.vfov_deg / 2.0f + 1e-3f);
  const std::vector<Light> l = default_lights(b, c);
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[0].kind, LightKind::kDirectional);
  EXPECT_EQ(l[1].kind, LightKind::kPoint);
  EXPECT_EQ(l[1].position, c.position);
}

}  // namespace
}  // namespace amalgam

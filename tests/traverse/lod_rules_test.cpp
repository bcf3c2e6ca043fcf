// The LOD rules for a ray that starts inside an amalgam (docs/architecture.md; traverse/lod.h,
// traverse/state.h `renders`): under --footprint an amalgam that contains a ray's origin (a
// shadow ray leaving a surface inside it) is descended, not rendered, because its opacity
// describes rays that cross it; every other amalgam the ray meets is rendered as usual. Under
// --level L the level is never passed: the amalgam is rendered even then. Checked on the fast
// traversal and on the scalar reference, closest hit and shadow rays alike.

#include <gtest/gtest.h>

#include <string>

#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/traverse/lod.h"
#include "amalgam/traverse/reference.h"
#include "amalgam/traverse/traverse.h"

namespace amalgam {
namespace {

/// Two tiny triangles at opposite corners of `box`: they make its bounds and block no ray
/// through its middle.
void add_corners(std::vector<Primitive>& out, Vec3 lo, Vec3 hi) {
  const float e = 0.001f;
  out.push_back(Primitive::triangle(lo, lo + Vec3{e, 0, 0}, lo + Vec3{0, e, 0}));
  out.push_back(Primitive::triangle(hi, hi - Vec3{e, 0, 0}, hi - Vec3{0, e, 0}));
}

/// Two opaque amalgams side by side, A = [-2, -1] x [-1, 1]^2 (node 1) and B = [1, 2] x
/// [-1, 1]^2 (node 2), under a root amalgam (node 0, level 0); every appearance fully opaque,
/// so a rendered amalgam stops any ray. Built by hand, with the SIMD boxes of the fast path.
ExplicitHierarchy two_amalgams() {
  ExplicitHierarchy h;
  add_corners(h.prims.edit(), {-2, -1, -1}, {-1, 1, 1});
  add_corners(h.prims.edit(), {1, -1, -1}, {2, 1, 1});
  h.nodes = {{{{-2, -1, -1}, {2, 1, 1}}, 1, 2, false},
             {{{-2, -1, -1}, {-1, 1, 1}}, 0, 2, true},
             {{{1, -1, -1}, {2, 1, 1}}, 2, 2, true}};
  h.materials = {Surface{}};
  h.appearances.assign(3, Appearance{});  // opacity 1, face shading
  h.levels = 3;
  build_wide(h);
  return h;
}

/// A ray along +x from `origin` with a wide cone: every amalgam it meets is small enough for
/// the footprint policy to render.
Ray wide_ray(Vec3 origin) {
  Ray r = Ray::make(origin, {1, 0, 0});
  r.cone_width = 100.0f;
  r.cone_spread = 1.0f;
  return r;
}

struct Outcome {
  float transmittance;
  TraceHit hit;
};

/// Shadow ray and closest hit along `ray`, on the fast traversal or the scalar reference.
template <class Lod>
Outcome run(bool reference, const ExplicitHierarchy& h, const Lod& lod, const Ray& ray) {
  Counters c;
  if (reference) {
    ReferenceTraversal<ExplicitHierarchy, Lod, StochasticOpacity> t(h, lod, c);
    const float tr = t.transmittance(ray, 1);
    return {tr, t.intersect(ray, 1)};
  }
  Traversal<ExplicitHierarchy, Lod, StochasticOpacity, SortedOrder, Counters> t(h, lod, c);
  const float tr = t.transmittance(ray, 1);
  return {tr, t.intersect(ray, 1)};
}

TEST(LodRules, FootprintDescendsTheAmalgamHoldingTheRayOriginAndRendersTheOthers) {
  const ExplicitHierarchy h = two_amalgams();
  ASSERT_NE(h.wide_nodes(), nullptr) << "the fast traversal's SIMD path";
  const NodeId right = 2;
  const auto lod = ScaleSensitiveLod::by_footprint(1.0f);
  for (bool reference : {false, true}) {
    SCOPED_TRACE(reference ? "reference traversal" : "fast traversal");
    // From outside everything: the root itself is met first and rendered (opaque).
    const Outcome outside = run(reference, h, lod, wide_ray({-5, 0, 0}));
    EXPECT_EQ(outside.transmittance, 0.0f);
    ASSERT_EQ(outside.hit.kind, TraceHit::Kind::kAmalgam);
    EXPECT_EQ(outside.hit.id, 0u) << "the root, entered at x = -2";
    EXPECT_FLOAT_EQ(outside.hit.t, 3.0f);
    // From inside the left amalgam (so inside the root too): both are descended, and the
    // right amalgam, which the ray crosses, is rendered.
    const Outcome in_left = run(reference, h, lod, wide_ray({-1.5f, 0, 0}));
    EXPECT_EQ(in_left.transmittance, 0.0f) << "the right amalgam should stop the shadow ray";
    ASSERT_EQ(in_left.hit.kind, TraceHit::Kind::kAmalgam)
        << "an amalgam holding the origin was rendered, or the right one was not";
    EXPECT_EQ(in_left.hit.id, right);
    EXPECT_FLOAT_EQ(in_left.hit.t, 2.5f) << "entered at x = 1";
    // From inside the right amalgam, going away from the left one: nothing is rendered, the
    // contents (tiny corner triangles) are missed.
    const Outcome in_right = run(reference, h, lod, wide_ray({1.5f, 0, 0}));
    EXPECT_EQ(in_right.transmittance, 1.0f) << "the amalgam holding the shadow ray's origin "
                                               "must be descended, not rendered";
    EXPECT_EQ(in_right.hit.kind, TraceHit::Kind::kNone);
    // Between the two, inside the root only: the root is descended, the right one rendered.
    const Outcome between = run(reference, h, lod, wide_ray({0, 0, 0}));
    EXPECT_EQ(between.transmittance, 0.0f);
    EXPECT_EQ(between.hit.id, right);
  }
}

TEST(LodRules, FixedLevelRendersTheAmalgamHoldingTheRayOrigin) {
  const ExplicitHierarchy h = two_amalgams();
  for (bool reference : {false, true}) {
    SCOPED_TRACE(reference ? "reference traversal" : "fast traversal");
    // Level 1 (the two amalgams): a ray starting inside the right one renders it, at once.
    const Outcome in_right =
        run(reference, h, ScaleSensitiveLod::on_level(1), wide_ray({1.5f, 0, 0}));
    EXPECT_EQ(in_right.transmittance, 0.0f) << "--level never passes the level";
    ASSERT_EQ(in_right.hit.kind, TraceHit::Kind::kAmalgam);
    EXPECT_LE(in_right.hit.t, 0.0f + 1e-6f);
    // The traditional renderer never renders: the same ray passes.
    EXPECT_EQ(run(reference, h, TraditionalLod{}, wide_ray({1.5f, 0, 0})).transmittance, 1.0f);
  }
}

}  // namespace
}  // namespace amalgam

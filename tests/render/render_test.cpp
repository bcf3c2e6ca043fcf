// Differential and statistical tests of whole renders.

#include "amalgam/render/render.h"

#include <gtest/gtest.h>

#include <cmath>

#include "amalgam/hierarchy/flatten.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

LoadedScene prisms(int depth, const std::string& view = "corner") {
  Params p("builtin:prisms");
  p.set("depth", std::to_string(depth));
  p.set("view", view);
  return load_scene("builtin:prisms", p);
}

RenderOptions small(int w = 48, int h = 40, int spp = 2) {
  RenderOptions o;
  o.width = w, o.height = h, o.spp = spp;
  return o;
}

TEST(Render, DeepestLevelEqualsTraditional) {
  const LoadedScene s = prisms(4);
  RenderOptions trad = small();
  trad.lod = FullDetail{};
  RenderOptions deepest = small();
  deepest.lod = OnLevel{s.info().levels - 1};  // l_max: no amalgam is ever rendered
  for (OpacityKind op : {OpacityKind::kStochastic, OpacityKind::kDeterministic}) {
    trad.opacity = deepest.opacity = op;
    const RenderOutput a = render(s, trad), b = render(s, deepest);
    ASSERT_EQ(a.image.size(), b.image.size());
    for (std::size_t i = 0; i < a.image.size(); ++i) ASSERT_EQ(a.image[i], b.image[i]) << i;
    EXPECT_EQ(a.counters.total(), b.counters.total());
    EXPECT_EQ(a.counters.tests_of(ObjectKind::kPrimitive),
              b.counters.tests_of(ObjectKind::kPrimitive));
  }
}

TEST(Render, ThreadCountDoesNotChangeTheImage) {
  const LoadedScene s = prisms(5);
  for (bool level : {false, true}) {
    RenderOptions o = small(64, 48, 3);
    o.seed = 1234;
    if (level) o.lod = OnLevel{2};
    o.threads = 1;
    const RenderOutput one = render(s, o);
    o.threads = 2;
    const RenderOutput two = render(s, o);
    ASSERT_EQ(one.image.size(), two.image.size());
    for (std::size_t i = 0; i < one.image.size(); ++i) {
      ASSERT_EQ(one.image[i], two.image[i]) << "pixel " << i;
      ASSERT_EQ(one.cost[i], two.cost[i]) << "pixel " << i;
    }
    EXPECT_EQ(one.counters.total(), two.counters.total());
    EXPECT_EQ(one.counters.by_level, two.counters.by_level);
  }
}

TEST(Render, SeedChangesStochasticImage) {
  const LoadedScene s = prisms(5);
  RenderOptions o = small(32, 32, 1);
  o.lod = OnLevel{3};
  const RenderOutput a = render(s, o);
  o.seed = 99;
  const RenderOutput b = render(s, o);
  int differ = 0;
  for (std::size_t i = 0; i < a.image.size(); ++i) differ += !(a.image[i] == b.image[i]);
  EXPECT_GT(differ, 0);
}

TEST(Render, FixedLevelMeanCostIsIndependentOfDepth) {
  RenderOptions o = small(40, 40, 2);
  o.lod = OnLevel{3};
  const LoadedScene shallow = prisms(6, "front"), deep = prisms(12, "front");
  const RenderOutput a = render(shallow, o), b = render(deep, o);
  EXPECT_EQ(a.per_primary.mean(), b.per_primary.mean());
  EXPECT_EQ(a.counters.total(), b.counters.total());
  RenderOptions t = small(8, 8, 1);
  t.lod = FullDetail{};
  EXPECT_LT(render(prisms(4, "front"), t).per_primary.mean(),
            render(prisms(6, "front"), t).per_primary.mean());
}

TEST(Render, CountsAddUp) {
  const LoadedScene s = prisms(5);
  RenderOptions o = small();
  o.lod = ByFootprint{2.0f};
  const RenderOutput r = render(s, o);
  const Counters& c = r.counters;
  std::uint64_t levels = 0;
  for (auto v : c.by_level) levels += v;
  EXPECT_EQ(c.tests_of(RayKind::kPrimary) + c.tests_of(RayKind::kShadow), c.total());
  EXPECT_EQ(c.tests_of(ObjectKind::kPrimitive) + c.tests_of(ObjectKind::kBoundingVolume) +
                c.tests_of(ObjectKind::kAmalgam),
            c.total());
  EXPECT_EQ(levels, c.total());
  EXPECT_EQ(c.rays[0], static_cast<std::uint64_t>(o.width) * o.height * o.spp);
  EXPECT_EQ(r.per_primary.count(), c.rays[0]);
  EXPECT_NEAR(r.per_primary.mean() * static_cast<double>(c.rays[0]), static_cast<double>(c.total()),
              1e-6 * c.total());
}

// One amalgam of opacity a and colour C_a in front of the background, filling the view:
// stochastic opacity must converge to a * C_amalgam + (1 - a) * C_background, which
// deterministic opacity gives in a single sample.
TEST(Render, StochasticOpacityIsUnbiased) {
  for (float a : {0.2f, 0.5f, 0.85f}) {
    ExplicitHierarchy h;
    h.levels = 3;
    const Bbox box{{-1, -1, -1}, {1, 1, 1}};
    h.nodes = {{box, 1, 1, false}, {box, 0, 1, true}};
    h.prims = std::vector<Primitive>{Primitive::sphere({0, 0, 0}, 0.5f)};
    h.materials = {Surface{}};
    Appearance root, amalgam;
    amalgam.opacity = a;
    amalgam.surface.colour = {0.9f, 0.4f, 0.1f};
    h.appearances = {root, amalgam};
    build_wide(h);  // a traversal refuses a hierarchy without its SIMD form
    LoadedScene s{"unbiased", std::move(h), Environment{}};
    s.env.camera.position = {0, 0, 5};
    s.env.camera.look_at = {0, 0, 0};
    s.env.camera.vfov_deg = 1.0f;  // the one pixel sees only the amalgam's front face
    s.env.background = {0.1f, 0.2f, 0.7f};
    Light l;
    l.kind = LightKind::kDirectional;
    l.direction = {0, 0, -1};
    l.intensity = {3, 3, 3};
    s.env.lights = {l};

    RenderOptions det = small(1, 1, 1);
    det.lod = OnLevel{1};
    det.opacity = OpacityKind::kDeterministic;
    const Vec3 expected = render(s, det).image[0];
    const Vec3 c_amalgam = amalgam.surface.colour * (3.0f / 3.14159265f);
    EXPECT_NEAR(expected.x, a * c_amalgam.x + (1 - a) * s.env.background.x, 1e-4);

    RenderOptions sto = det;
    sto.opacity = OpacityKind::kStochastic;
    sto.spp = 20000;
    sto.seed = 7;
    const Vec3 mean = render(s, sto).image[0];
    // Bernoulli(a) per sample: standard error sqrt(a (1 - a) / N) |C_a - C_bg|; allow 4 of them.
    for (int ch = 0; ch < 3; ++ch) {
      const double spread = std::fabs(c_amalgam[ch] - s.env.background[ch]);
      const double tol = 4.0 * std::sqrt(a * (1 - a) / 20000.0) * spread + 1e-6;
      EXPECT_NEAR(mean[ch], expected[ch], tol) << "a=" << a << " channel " << ch;
    }
  }
}

TEST(Render, ExplicitFlattenMatchesImplicit) {
  Params p("builtin:line");
  p.set("n", "3");
  p.set("depth", "4");
  p.set("alpha", "0.4");
  const LoadedScene implicit = load_scene("builtin:line", p);
  ExplicitHierarchy flat_h = flatten(std::get<TubeHierarchy>(implicit.hierarchy), 5);
  build_wide(flat_h);
  LoadedScene flat{"flat", std::move(flat_h), implicit.env};
  for (RendererKind r : {RendererKind::kTraditional, RendererKind::kScaleSensitive}) {
    RenderOptions o;
    o.lod =
        r == RendererKind::kTraditional ? LevelOfDetail{FullDetail{}} : LevelOfDetail{OnLevel{2}};
    o.opacity = OpacityKind::kDeterministic;
    const Ray ray = implicit.env.camera.centre_ray(o.width, o.height);
    const TraceOutput a = trace(implicit, o, ray), b = trace(flat, o, ray);
    EXPECT_EQ(a.counters.total(), b.counters.total());
    EXPECT_EQ(a.counters.by_level, b.counters.by_level);
    EXPECT_EQ(a.colour, b.colour);
  }
}

// The full-detail renderers never render a box amalgam: a scene loaded without the amalgams'
// appearances (SceneFileConfig::amalgams, what the CLI does for them) renders the same bytes
// and counts, and the scale-sensitive renderer refuses it.
TEST(Render, FullDetailNeedsNoAmalgamBake) {
  const std::string path = AMALGAM_SOURCE_DIR "/scenes/volumetric/wuson.json";
  const LoadedScene baked = load_scene(path, Params(path));
  SceneFileConfig bare_config;
  bare_config.amalgams = false;
  const LoadedScene bare = load_scene(path, Params(path), bare_config);
  EXPECT_TRUE(baked.amalgams);
  EXPECT_FALSE(bare.amalgams);
  RenderOptions o = small(40, 30, 2);
  o.lod = FullDetail{};
  const RenderOutput a = render(baked, o), b = render(bare, o);
  EXPECT_EQ(a.image, b.image);
  EXPECT_EQ(a.counters.total(), b.counters.total());
  EXPECT_EQ(a.counters.by_level, b.counters.by_level);
  o.lod = ByFootprint{1.0f};
  EXPECT_NO_THROW(render(baked, o));
  EXPECT_THROW(render(bare, o), InternalError);
}

}  // namespace
}  // namespace amalgam

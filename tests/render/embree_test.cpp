// --tracer embree (make_tracer, render/tracer.h): on every example scene, Embree's 1-spp image is
// the traditional renderer's (RMSE < 0.01: Embree's triangle test and ours may disagree on a ray
// through an edge or grazing a surface, so scenes of triangles, above all instanced ones, differ
// in a few pixels; scenes of spheres and boxes only are identical bit for bit).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "amalgam/analysis/metrics.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/tracer.h"

namespace amalgam {
namespace {

struct Case {
  std::string scene;
  std::vector<std::string> sets;  ///< builtin parameters, "key=value"
};

/// Every scene file of scenes/, the builtins (builtin:demo smaller: 33.5 million boxes take
/// Embree half a minute to list and build) and one real mesh.
std::vector<Case> cases() {
  std::vector<Case> out;
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(AMALGAM_SOURCE_DIR "/scenes"))
    if (e.path().extension() == ".json") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  for (const std::string& f : files) out.push_back({f, {}});
  out.push_back({"builtin:line", {}});
  out.push_back({"builtin:poisson", {}});
  out.push_back({"builtin:prisms", {}});
  out.push_back({"builtin:prisms", {"view=corner", "lights=3"}});
  out.push_back({"builtin:demo", {"depth=5"}});
  out.push_back({"/usr/share/assimp/models/PLY/Wuson.ply", {}});
  return out;
}

LoadedScene load(const Case& c) {
  Params p(c.scene);
  for (const std::string& s : c.sets) p.set(s);
  return load_scene(c.scene, p);
}

RenderOptions one_spp(TracerKind tracer) {
  RenderOptions o;
  o.width = 128, o.height = 96, o.spp = 1;
  o.lod = FullDetail{};
  o.tracer = tracer;
  return o;
}

TEST(Embree, EveryExampleSceneMatchesTheTraditionalRenderer) {
  const std::vector<Case> all = cases();
  ASSERT_GE(all.size(), 9u);  // the four scene files at least, builtins, the mesh
  for (const Case& c : all) {
    SCOPED_TRACE(c.scene);
    const LoadedScene scene = load(c);
    const RenderOutput ours = render(scene, one_spp(TracerKind::kAmalgam));
    const auto es = make_tracer(scene, one_spp(TracerKind::kEmbree));
    const RenderOutput theirs = es->render(one_spp(TracerKind::kEmbree));
    ASSERT_EQ(theirs.image.size(), ours.image.size());
    EXPECT_LT(rmse(theirs.image, ours.image), 0.01);
    // Embree counts rays, as amalgam does, and no tests.
    EXPECT_EQ(theirs.counters.rays[0], ours.counters.rays[0]);
    EXPECT_EQ(theirs.counters.total(), 0u);
    EXPECT_GT(ours.counters.total(), 0u);
    // Not a blank image: the scene was seen.
    double sum = 0;
    for (const Vec3& v : theirs.image) sum += v.x + v.y + v.z;
    EXPECT_GT(sum, 0.0);
  }
}

TEST(Embree, ShadowRaysAgreeWhereBothHitTheSamePrimitive) {
  // Where both tracers hit the same primitive, the surface is amalgam's and so is the shadow
  // ray: its answer must be the same. Embree's own transform of a shadow ray into an instance
  // put it behind the triangle it leaves (10 of about 27,000 here before the triangles'
  // occlusion filter; in the 512x384 render each was checked exactly: no occluder).
  const LoadedScene scene = load({AMALGAM_SOURCE_DIR "/scenes/field.json", {}});
  const auto es = make_tracer(scene, one_spp(TracerKind::kEmbree));
  const int w = 256, h = 192;
  std::size_t same = 0, differ = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Ray ray = scene.env.camera.generate(x + 0.5f, y + 0.5f, w, h);
      const TraceOutput ours = trace(scene, one_spp(TracerKind::kAmalgam), ray);
      const TraceOutput theirs = es->trace(one_spp(TracerKind::kEmbree), ray);
      if (ours.hit.kind != TraceHit::Kind::kPrimitive || theirs.hit.kind != ours.hit.kind ||
          theirs.hit.id != ours.hit.id)
        continue;
      ++same;
      if (!(theirs.colour == ours.colour)) ++differ;
    }
  EXPECT_GT(same, std::size_t(w) * h / 4);
  EXPECT_EQ(differ, 0u) << "of " << same;
}

TEST(Embree, SceneWithoutInstancesIsBitIdentical) {
  // Same primitives hit, same surfaces, same shadow rays: the same bits, not merely close.
  for (const Case& c : {Case{"builtin:prisms", {"view=corner"}},
                        Case{AMALGAM_SOURCE_DIR "/scenes/spheres.json", {}}}) {
    SCOPED_TRACE(c.scene);
    const LoadedScene scene = load(c);
    const RenderOutput ours = render(scene, one_spp(TracerKind::kAmalgam));
    const auto es = make_tracer(scene, one_spp(TracerKind::kEmbree));
    const RenderOutput theirs = es->render(one_spp(TracerKind::kEmbree));
    ASSERT_EQ(theirs.image.size(), ours.image.size());
    for (std::size_t i = 0; i < ours.image.size(); ++i) ASSERT_EQ(theirs.image[i], ours.image[i]);
    EXPECT_EQ(theirs.counters.rays, ours.counters.rays);
  }
}

TEST(Embree, ResumedEqualsUninterruptedAndThreadsDoNotMatter) {
  const LoadedScene scene = load({AMALGAM_SOURCE_DIR "/scenes/wuson-grid.json", {}});
  const auto es = make_tracer(scene, one_spp(TracerKind::kEmbree));
  RenderOptions o = one_spp(TracerKind::kEmbree);
  o.width = 40, o.height = 30, o.spp = 3;
  const RenderOutput whole = es->render(o);
  RenderOptions first = o;
  first.spp = 1;
  first.threads = 1;
  FilmState st;
  es->render(first, &st);
  ASSERT_EQ(st.spp_done, 1);
  const RenderOutput resumed = es->render(o, &st);
  ASSERT_EQ(resumed.spp, 3);
  for (std::size_t i = 0; i < whole.image.size(); ++i) ASSERT_EQ(resumed.image[i], whole.image[i]);
}

TEST(Embree, RefusesWhatItCannotDo) {
  const LoadedScene scene = load({"builtin:prisms", {"depth=3"}});
  const auto es = make_tracer(scene, one_spp(TracerKind::kEmbree));
  RenderOptions o = one_spp(TracerKind::kEmbree);
  o.lod = ByFootprint{};  // amalgams: not Embree's
  EXPECT_THROW(es->render(o), InputError);
  EXPECT_THROW(es->render(one_spp(TracerKind::kAmalgam)), InputError);
  EXPECT_THROW(render(scene, one_spp(TracerKind::kEmbree)), InputError);
  // An implicit builtin too large to list.
  Params p("builtin:line");
  p.set("depth=30");
  const LoadedScene huge = load_scene("builtin:line", p);
  EXPECT_THROW(make_tracer(huge, one_spp(TracerKind::kEmbree)), InputError);
  EXPECT_THROW(make_tracer(scene, o), InputError);  // the factory checks the options first
}

TEST(Embree, TheFactoryMakesTheTracerTheOptionsName) {
  const LoadedScene scene = load({AMALGAM_SOURCE_DIR "/scenes/spheres.json", {}});
  const auto ours = make_tracer(scene, one_spp(TracerKind::kAmalgam));
  EXPECT_TRUE(ours->counts_tests());
  EXPECT_EQ(ours->build_seconds(), 0.0);
  const RenderOutput direct = render(scene, one_spp(TracerKind::kAmalgam));
  const RenderOutput made = ours->render(one_spp(TracerKind::kAmalgam));
  EXPECT_EQ(made.image, direct.image);
  EXPECT_EQ(made.counters.total(), direct.counters.total());
  EXPECT_GT(made.counters.total(), 0u);
  // Embree counts rays, not tests, in whatever configuration its BVHs are built: spheres are
  // user geometry tested by amalgam's own code, so every build gives the traditional image.
  for (const EmbreeBuild b : {EmbreeBuild{}, EmbreeBuild{EmbreeBuild::Quality::kMedium, false},
                              EmbreeBuild{EmbreeBuild::Quality::kLow, true}}) {
    const auto theirs = make_tracer(scene, one_spp(TracerKind::kEmbree), b);
    EXPECT_FALSE(theirs->counts_tests());
    const RenderOutput e = theirs->render(one_spp(TracerKind::kEmbree));
    EXPECT_EQ(e.image, direct.image);
    EXPECT_EQ(e.counters.total(), 0u);
    EXPECT_EQ(e.counters.rays, direct.counters.rays);
  }
}

TEST(Embree, TraceFindsTheSameHitAsTheTraditionalRenderer) {
  const LoadedScene scene = load({"builtin:line", {}});
  RenderOptions o = one_spp(TracerKind::kAmalgam);
  const Ray ray = scene.env.camera.centre_ray(o.width, o.height);
  const TraceOutput ours = trace(scene, o, ray);
  const auto es = make_tracer(scene, one_spp(TracerKind::kEmbree));
  const TraceOutput theirs = es->trace(one_spp(TracerKind::kEmbree), ray);
  ASSERT_EQ(theirs.hit.kind, TraceHit::Kind::kPrimitive);
  EXPECT_EQ(theirs.hit.id, ours.hit.id);
  EXPECT_EQ(theirs.hit.t, ours.hit.t);
  EXPECT_EQ(theirs.colour, ours.colour);
}

}  // namespace
}  // namespace amalgam

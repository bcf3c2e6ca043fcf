// content_hash (render/loaded_scene.h): what a checkpoint is resumed against. It must tell
// apart scenes that render differently and agree on scenes that render the same.

#include <gtest/gtest.h>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/load/load_scene.h"

namespace amalgam {
namespace {

LoadedScene line(std::initializer_list<const char*> sets) {
  Params p("builtin:line");
  for (const char* s : sets) p.set(s);
  return load_builtin("builtin:line", p);
}

TEST(ContentHash, BuiltinParametersAsAppliedNotAsWritten) {
  // The last --set of a key wins: these two orders make different scenes.
  EXPECT_NE(content_hash(line({"n=2", "n=3"})), content_hash(line({"n=3", "n=2"})));
  // The same parameters in another order make the same scene.
  EXPECT_EQ(content_hash(line({"n=3", "depth=4"})), content_hash(line({"depth=4", "n=3"})));
  EXPECT_EQ(content_hash(line({"n=3"})), content_hash(line({"n=3"})));
}

TEST(ContentHash, EveryPartOfAStoredSceneCounts) {
  std::vector<Primitive> prims = {Primitive::triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}),
                                  Primitive::sphere({2, 0, 0}, 0.5f)};
  Environment env;
  env.lights.push_back(Light{});
  const LoadedScene a{"s", build_explicit(prims, {Surface{}}), env};
  const std::uint64_t h = content_hash(a);
  EXPECT_EQ(h, content_hash(LoadedScene{"s", build_explicit(prims, {Surface{}}), env}));
  auto moved = prims;
  moved[0].b.x = 1.0000001f;  // one vertex, one ulp
  EXPECT_NE(h, content_hash(LoadedScene{"s", build_explicit(moved, {Surface{}}), env}));
  Surface red;
  red.colour = {0.9f, 0.1f, 0.1f};
  EXPECT_NE(h, content_hash(LoadedScene{"s", build_explicit(prims, {red}), env}));
  Environment lit = env;
  lit.lights[0].intensity.x = 2.0f;
  EXPECT_NE(h, content_hash(LoadedScene{"s", build_explicit(prims, {Surface{}}), lit}));
  Environment seen = env;
  seen.camera.position.z = 6.0f;
  EXPECT_NE(h, content_hash(LoadedScene{"s", build_explicit(prims, {Surface{}}), seen}));
}

}  // namespace
}  // namespace amalgam

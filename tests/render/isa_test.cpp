// The AVX2 copy of the hot paths against the portable one (util/isa.h): the same image bits,
// the same cost per pixel and the same counts, for every hierarchy form and policy. The
// portable copy is itself checked against the scalar reference (tests/traverse/simd_test.cpp);
// that the portable copy runs on a CPU without AVX2 is checked by the ctest `isa_portable`
// (tests/isa_portable.sh, under qemu-user emulating a CPU without AVX).

#include "amalgam/util/isa.h"

#include <gtest/gtest.h>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/render/render_isa.h"

namespace amalgam {
namespace {

FilmState empty_film(const RenderOptions& o) {
  FilmState st;
  st.width = o.width;
  st.height = o.height;
  st.sum.assign(static_cast<std::size_t>(o.width) * o.height, Vec3{});
  st.tests.assign(st.sum.size(), 0);
  return st;
}

void expect_same(const LoadedScene& s, const RenderOptions& o, const std::string& what) {
  FilmState a = empty_film(o), b = empty_film(o);
  EXPECT_FALSE(detail::render_passes_portable(s, s.env, o, a, {}));
  EXPECT_FALSE(detail::render_passes_avx2(s, s.env, o, b, {}));
  ASSERT_EQ(a.sum.size(), b.sum.size());
  for (std::size_t i = 0; i < a.sum.size(); ++i) {
    ASSERT_EQ(a.sum[i], b.sum[i]) << what << ", pixel " << i;
    ASSERT_EQ(a.tests[i], b.tests[i]) << what << ", pixel " << i;
    ASSERT_EQ(a.aov[i], b.aov[i]) << what << ", auxiliary outputs of pixel " << i;
  }
  EXPECT_EQ(a.counters.tests, b.counters.tests) << what;
  EXPECT_EQ(a.counters.by_level, b.counters.by_level) << what;
  EXPECT_GT(a.counters.total(), 0u) << what;
}

std::vector<std::pair<std::string, RenderOptions>> policies(int levels) {
  std::vector<std::pair<std::string, RenderOptions>> out;
  for (OpacityKind op : {OpacityKind::kStochastic, OpacityKind::kDeterministic})
    for (bool sorted : {true, false}) {
      RenderOptions o;
      o.width = 40, o.height = 32, o.spp = 2, o.seed = 7;
      o.opacity = op;
      o.sorted = sorted;
      const std::string n = std::string(op == OpacityKind::kStochastic ? "stochastic" : "det") +
                            (sorted ? " sorted" : " stored");
      RenderOptions t = o;
      t.lod = FullDetail{};
      out.push_back({n + " traditional", t});
      RenderOptions f = o;
      f.lod = ByFootprint{4.0f};
      out.push_back({n + " footprint 4", f});
      RenderOptions l = o;
      l.lod = OnLevel{levels / 2};
      out.push_back({n + " level", l});
    }
  return out;
}

#if defined(AMALGAM_BUILD_AVX2_COPY)
TEST(Isa, Avx2CopyGivesThePortableBits) {
  ASSERT_TRUE(simd_avx2_built());
  if (!simd_avx2_supported()) GTEST_SKIP() << "this CPU has no AVX2";
  const std::string wuson = "/usr/share/assimp/models/PLY/Wuson.ply";
  std::vector<LoadedScene> scenes;
  scenes.push_back(load_scene("builtin:demo", Params("builtin:demo")));
  scenes.push_back(load_scene("builtin:line", Params("builtin:line")));
  // explicit, the default 8-wide nodes (the 8-lane box kernel) and leaves of up to 4
  // triangles (one pack)
  scenes.push_back(load_scene(wuson, Params(wuson)));
  scenes.push_back(load_scene(std::string(AMALGAM_SOURCE_DIR) + "/scenes/wuson-grid.json",
                              Params("grid")));  // instanced
  for (const int arity : {4, 13}) {
    // 4-wide nodes and leaves (one SSE-width block, one pack); 13: several kernel calls per
    // node (8 + 4 + 1 boxes) and per leaf (8 + 4 + 1 triangles: the 8-lane triangle kernel).
    LoadedScene w = load_scene(wuson, Params(wuson));
    const auto& e = std::get<ExplicitHierarchy>(w.hierarchy);
    BuildConfig c;
    c.arity = arity;
    c.leaf_size = arity;
    w.hierarchy = build_explicit(e.prims.to_vector(), e.materials, c);
    w.name += " (arity and leaves " + std::to_string(arity) + ")";
    scenes.push_back(std::move(w));
  }
  for (const LoadedScene& s : scenes)
    for (const auto& [name, o] : policies(s.info().levels)) expect_same(s, o, s.name + ", " + name);
}

#endif

TEST(Isa, GccAndClangBuildsForX86HoldTheAvx2Copy) {
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
  EXPECT_TRUE(simd_avx2_built());
#else
  EXPECT_FALSE(simd_avx2_built());
#endif
}

TEST(Isa, ChoiceFollowsTheEnvironment) {
  // The process's choice is made once; in the test run AMALGAM_SIMD is unset or "auto"
  // (tests/isa_portable.sh runs the CLI with the other values).
  const char* env = std::getenv("AMALGAM_SIMD");
  if (env == nullptr || std::string(env) == "auto") {
    EXPECT_EQ(active_simd(),
              simd_avx2_built() && simd_avx2_supported() ? Simd::kAvx2 : Simd::kPortable);
  }
  EXPECT_EQ(simd_name(Simd::kAvx2), "avx2");
  EXPECT_EQ(simd_name(Simd::kPortable), "portable");
}

}  // namespace
}  // namespace amalgam

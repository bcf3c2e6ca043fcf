// The oracle of the yardstick (bench/oracle.h): where no amalgam would be rendered it is the
// traditional renderer exactly; where amalgams are met it replaces those samples only.

#include "../../bench/oracle.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

#include "amalgam/load/load_scene.h"
#include "amalgam/render/passes.h"
#include "amalgam/render/render.h"

namespace amalgam {
namespace {

LoadedScene field() {
  SceneFileConfig config;
  config.expand_limit = 0;  // instanced, as the yardstick loads it
  return load_scene_path(std::string(AMALGAM_SOURCE_DIR) + "/scenes/field.json", config);
}

std::vector<Vec3> oracle_image(const LoadedScene& s, const RenderOptions& o, float k, bool box,
                               std::uint64_t& in_amalgam) {
  const auto& h = std::get<InstancedHierarchy>(s.hierarchy);
  FilmState st;
  st.width = o.width, st.height = o.height;
  st.sum.assign(static_cast<std::size_t>(o.width) * o.height, Vec3{});
  st.tests.assign(st.sum.size(), 0);
  std::atomic<std::uint64_t> count{0};
  render_passes(s.env.camera, o, st, RenderControl{}, [&](Counters& c) {
    return OracleIntegrator<InstancedHierarchy>(h, s.env, k, 8, box, c, count);
  });
  in_amalgam = count.load();
  return finish(st).image;
}

TEST(Oracle, IsTheTraditionalRendererWhereNoAmalgamRenders) {
  const LoadedScene s = field();
  RenderOptions o;
  o.width = 48, o.height = 36, o.spp = 2, o.seed = 4, o.sampler = PixelSampler::kStratified;
  o.lod = FullDetail{};
  const RenderOutput trad = render(s, o);
  std::uint64_t in_amalgam = 1;
  const std::vector<Vec3> tiny = oracle_image(s, o, 1e-6f, false, in_amalgam);
  EXPECT_EQ(in_amalgam, 0u) << "no amalgam is below 1e-6 pixels";
  ASSERT_EQ(tiny.size(), trad.image.size());
  for (std::size_t i = 0; i < tiny.size(); ++i) ASSERT_EQ(tiny[i], trad.image[i]) << "pixel " << i;

  // K = 4: some samples meet amalgams and only those change; the estimate stays finite.
  for (bool box : {false, true}) {
    const std::vector<Vec3> k4 = oracle_image(s, o, 4.0f, box, in_amalgam);
    EXPECT_GT(in_amalgam, 0u);
    EXPECT_LT(in_amalgam, static_cast<std::uint64_t>(o.width) * o.height * o.spp);
    std::size_t changed = 0;
    for (std::size_t i = 0; i < k4.size(); ++i) {
      ASSERT_TRUE(is_finite(k4[i]));
      changed += k4[i] != trad.image[i];
    }
    EXPECT_GT(changed, 0u);
    EXPECT_LE(changed, in_amalgam) << "a pixel changes only through a replaced sample";
  }
}

}  // namespace
}  // namespace amalgam

// render/option_rules.h: the one check of the renderer options, for the CLI and Python.

#include "amalgam/render/option_rules.h"

#include <gtest/gtest.h>

#include <string>

#include "amalgam/util/error.h"

namespace amalgam {
namespace {

std::string message(const OptionRequest& r, OptionSpelling s) {
  try {
    resolve_options(r, s);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(OptionRules, EachRendererGetsItsOwnLevelOfDetail) {
  OptionRequest r;
  RenderOptions o = resolve_options(r, OptionSpelling::kFlags);
  ASSERT_TRUE(std::holds_alternative<ByFootprint>(o.lod));
  EXPECT_EQ(std::get<ByFootprint>(o.lod).pixels, 1.0f);
  EXPECT_EQ(o.renderer(), RendererKind::kScaleSensitive);

  r.footprint = 3.0;
  EXPECT_EQ(std::get<ByFootprint>(resolve_options(r, OptionSpelling::kFlags).lod).pixels, 3.0f);
  r.renderer = "volumetric";
  o = resolve_options(r, OptionSpelling::kFlags);
  ASSERT_TRUE(std::holds_alternative<VolumetricCells>(o.lod));
  EXPECT_EQ(std::get<VolumetricCells>(o.lod).cone_widths, 3.0f);
  EXPECT_EQ(o.renderer(), RendererKind::kVolumetric);

  OptionRequest l;
  l.level = 4;
  o = resolve_options(l, OptionSpelling::kKeywords);
  ASSERT_TRUE(std::holds_alternative<OnLevel>(o.lod));
  EXPECT_EQ(std::get<OnLevel>(o.lod).level, 4);

  OptionRequest t;
  t.renderer = "traditional";
  EXPECT_TRUE(std::holds_alternative<FullDetail>(resolve_options(t, OptionSpelling::kFlags).lod));
  t.tracer = "embree";
  o = resolve_options(t, OptionSpelling::kFlags);
  EXPECT_EQ(o.tracer, TracerKind::kEmbree);
  EXPECT_TRUE(std::holds_alternative<FullDetail>(o.lod));
}

TEST(OptionRules, TheOtherOptionsPassThrough) {
  OptionRequest r;
  r.opacity = "composite", r.order = "unsorted", r.sampler = "stratified";
  r.width = 7, r.height = 5, r.spp = 3, r.threads = 2, r.seed = 99;
  const RenderOptions o = resolve_options(r, OptionSpelling::kFlags);
  EXPECT_EQ(o.opacity, OpacityKind::kComposite);
  EXPECT_FALSE(o.sorted);
  EXPECT_EQ(o.sampler, PixelSampler::kStratified);
  EXPECT_EQ(o.width, 7);
  EXPECT_EQ(o.height, 5);
  EXPECT_EQ(o.spp, 3);
  EXPECT_EQ(o.threads, 2);
  EXPECT_EQ(o.seed, 99u);
}

// One rule, two spellings: the CLI's flags and Python's keywords.
TEST(OptionRules, MessagesNameTheOptionAsTheUserSpelledIt) {
  OptionRequest both;
  both.level = 1, both.footprint = 2.0;
  EXPECT_EQ(message(both, OptionSpelling::kFlags),
            "--level and --footprint: give one (a fixed level, or render by footprint)");
  EXPECT_EQ(message(both, OptionSpelling::kKeywords),
            "level= and footprint=: give one (a fixed level, or render by footprint)");

  OptionRequest bad;
  bad.renderer = "fast";
  EXPECT_EQ(message(bad, OptionSpelling::kFlags),
            "--renderer fast: expected scale-sensitive, traditional or volumetric");
  EXPECT_EQ(message(bad, OptionSpelling::kKeywords),
            "renderer=fast: expected scale-sensitive, traditional or volumetric");

  OptionRequest spp;
  spp.spp = 0;
  EXPECT_EQ(message(spp, OptionSpelling::kKeywords), "spp=0: expected an integer >= 1");
  OptionRequest fp;
  fp.footprint = -2.5;
  EXPECT_EQ(message(fp, OptionSpelling::kFlags),
            "--footprint -2.5: expected a number in [1e-30, 1e30]");
}

TEST(OptionRules, OptionsThatDoNotApplyAreRefused) {
  auto refused = [](OptionRequest r, const std::string& start) {
    const std::string m = message(r, OptionSpelling::kFlags);
    EXPECT_EQ(m.rfind(start, 0), 0u) << m;
  };
  OptionRequest r;
  r.renderer = "traditional", r.level = 2;
  refused(r, "--renderer traditional renders no amalgam: --level");
  r = {}, r.renderer = "traditional", r.footprint = 2.0;
  refused(r, "--renderer traditional renders no amalgam: --footprint");
  r = {}, r.renderer = "volumetric", r.level = 2;
  refused(r, "--renderer volumetric chooses its cells by footprint: --level");
  r = {}, r.renderer = "volumetric", r.opacity = "deterministic";
  refused(r, "--renderer volumetric composites its cells by coverage: --opacity deterministic");
  r = {}, r.tracer = "embree", r.renderer = "scale-sensitive";
  refused(r, "--tracer embree renders at full detail: --renderer scale-sensitive");
  r = {}, r.tracer = "embree", r.order = "sorted";
  refused(r, "--tracer embree renders at full detail: --order");
  r = {}, r.tracer = "embree", r.opacity = "composite";
  refused(r, "--tracer embree renders at full detail: --opacity composite");
  // The stochastic default, given explicitly, is no conflict.
  r = {}, r.renderer = "volumetric", r.opacity = "stochastic";
  EXPECT_EQ(message(r, OptionSpelling::kFlags), "");
}

}  // namespace
}  // namespace amalgam

#include "amalgam/render/option_rules.h"

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string_view>
#include <tuple>

#include "amalgam/util/error.h"

namespace amalgam {

namespace {

class Names {
 public:
  explicit Names(OptionSpelling s) : s_(s) {}
  /// The option alone: `--level` or `level=`.
  std::string operator()(std::string_view flag) const { return option_text(flag, s_); }
  /// The option with its value: `--level 3` or `level=3`.
  std::string with(std::string_view flag, const std::string& value) const {
    return option_text(flag, s_, value);
  }

 private:
  OptionSpelling s_;
};

/// `x` as %g writes it: 2.5, 1e-300 (not std::to_string's 0.000000).
std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

}  // namespace

std::string option_text(std::string_view flag, OptionSpelling spelling, const std::string& value) {
  if (spelling == OptionSpelling::kFlags)
    return value.empty() ? std::string(flag) : std::string(flag) + " " + value;
  std::string k(flag.substr(std::min(flag.size(), flag.find_first_not_of('-'))));
  for (char& c : k)
    if (c == '-') c = '_';
  return k + "=" + value;
}

namespace {

/// Embree renders every primitive (full detail): the options that choose amalgams, blend
/// them or order amalgam's own traversal have no meaning there. Throws InputError naming the
/// first one given.
void refuse_for_embree(const OptionRequest& r, const Names& name, const std::string& renderer,
                       const std::string& opacity) {
  auto refuse = [&](const std::string& what) {
    throw InputError(name.with("--tracer", "embree") + " renders at full detail: " + what +
                     " does not apply");
  };
  if (r.renderer && renderer != "traditional") refuse(name.with("--renderer", renderer));
  if (r.level) refuse(name("--level"));
  if (r.footprint) refuse(name("--footprint"));
  if (r.opacity && opacity != "stochastic") refuse(name.with("--opacity", opacity));
  if (r.order) refuse(name("--order") + " (Embree orders its own)");
}

}  // namespace

RenderOptions resolve_options(const OptionRequest& r, OptionSpelling spelling) {
  const Names name(spelling);
  auto one_of = [&](const std::optional<std::string>& v, std::string_view flag,
                    std::initializer_list<std::string_view> allowed,
                    std::string_view expected) -> std::string {
    if (!v) return std::string(*allowed.begin());
    for (std::string_view a : allowed)
      if (*v == a) return *v;
    throw InputError(name.with(flag, one_line(*v, 40)) + ": expected " + std::string(expected));
  };
  const std::string renderer =
      one_of(r.renderer, "--renderer", {"scale-sensitive", "traditional", "volumetric"},
             "scale-sensitive, traditional or volumetric");
  const std::string opacity =
      one_of(r.opacity, "--opacity", {"stochastic", "deterministic", "prefiltered", "composite"},
             "stochastic, deterministic, prefiltered or composite");
  const std::string order =
      one_of(r.order, "--order", {"sorted", "unsorted"}, "sorted or unsorted");
  const std::string sampler =
      one_of(r.sampler, "--sampler", {"independent", "stratified"}, "independent or stratified");
  const std::string tracer =
      one_of(r.tracer, "--tracer", {"amalgam", "embree"}, "amalgam or embree");

  if (r.level && *r.level < 0)
    throw InputError(name.with("--level", std::to_string(*r.level)) + ": expected an integer >= 0");
  if (r.footprint && !(*r.footprint >= kMinFootprint && *r.footprint <= kMaxFootprint))
    throw InputError(name.with("--footprint", number(*r.footprint)) +
                     ": expected a number in [1e-30, 1e30]");
  for (const auto& [v, flag, least] :
       {std::tuple{r.width, "--width", 1}, std::tuple{r.height, "--height", 1},
        std::tuple{r.spp, "--spp", 1}, std::tuple{r.threads, "--threads", 0}})
    if (v && *v < least)
      throw InputError(name.with(flag, std::to_string(*v)) +
                       ": expected an integer >= " + std::to_string(least));
  if (r.level && r.footprint)
    throw InputError(name("--level") + " and " + name("--footprint") +
                     ": give one (a fixed level, or render by footprint)");

  RenderOptions o;
  if (tracer == "embree") {
    refuse_for_embree(r, name, renderer, opacity);
    o.tracer = TracerKind::kEmbree;
    o.lod = FullDetail{};
  } else if (renderer == "traditional") {
    if (r.level || r.footprint)
      throw InputError(name.with("--renderer", "traditional") + " renders no amalgam: " +
                       name(r.level ? "--level" : "--footprint") + " does not apply");
    o.lod = FullDetail{};
  } else if (renderer == "volumetric") {
    if (r.level)
      throw InputError(name.with("--renderer", "volumetric") +
                       " chooses its cells by footprint: " + name("--level") + " does not apply");
    if (r.opacity && opacity != "stochastic")
      throw InputError(name.with("--renderer", "volumetric") +
                       " composites its cells by coverage: " + name.with("--opacity", opacity) +
                       " does not apply");
    o.lod = VolumetricCells{r.footprint ? static_cast<float>(*r.footprint) : 1.0f};
  } else if (r.level) {
    o.lod = OnLevel{*r.level};
  } else {
    o.lod = ByFootprint{r.footprint ? static_cast<float>(*r.footprint) : 1.0f};
  }
  o.opacity = *parse_opacity(opacity);
  o.sorted = order == "sorted";
  o.sampler = sampler == "stratified" ? PixelSampler::kStratified : PixelSampler::kIndependent;
  o.seed = r.seed;
  if (r.width) o.width = *r.width;
  if (r.height) o.height = *r.height;
  if (r.spp) o.spp = *r.spp;
  if (r.threads) o.threads = *r.threads;
  return o;
}

}  // namespace amalgam

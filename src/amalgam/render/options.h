#pragma once
/// \file Renderer options shared by `render`, `trace` and `experiment` (docs/cli.md).

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace amalgam {

/// kVolumetric: every object (an instanced mesh) whose cells the ray's cone is wide enough for
/// is rendered as volumetric amalgams (hierarchy/volume/cells.h), the rest at full detail;
/// `footprint` is then the cells' size in cone widths. Needs a scene loaded with
/// SceneFileConfig::objects (io/scene_json.h).
enum class RendererKind : std::uint8_t { kScaleSensitive, kTraditional, kVolumetric };
/// The opacity models (traverse/opacity.h): the paper's two, and kPrefiltered, stochastic for
/// camera rays and deterministic (prefiltered) attenuation for shadow rays.
/// kComposite: deterministic for every ray, camera rays stopping when their coverage saturates,
/// one shadow computation per camera ray.
enum class OpacityKind : std::uint8_t { kStochastic, kDeterministic, kPrefiltered, kComposite };
/// The names of --opacity, indexed by OpacityKind.
inline constexpr std::array<std::string_view, 4> kOpacityNames = {"stochastic", "deterministic",
                                                                  "prefiltered", "composite"};
inline std::string_view opacity_name(OpacityKind k) {
  return kOpacityNames[static_cast<std::size_t>(k)];
}
/// The OpacityKind named `name`, if any.
inline std::optional<OpacityKind> parse_opacity(std::string_view name) {
  for (std::size_t i = 0; i < kOpacityNames.size(); ++i)
    if (kOpacityNames[i] == name) return static_cast<OpacityKind>(i);
  return std::nullopt;
}
/// What finds the hits: amalgam's traversal, or Intel Embree 3 at full detail
/// (render/embree_tracer.h; only the traditional renderer).
enum class TracerKind : std::uint8_t { kAmalgam, kEmbree };
/// Where in its pixel a primary sample goes. kIndependent: a uniform random point per sample
/// (the original sampling; every stored image and experiment uses it). kStratified: sample s
/// of a pixel is point s of a Sobol sequence scrambled per pixel (math/sobol.h): every prefix
/// of 2^m samples covers the pixel evenly, so edges converge faster.
enum class PixelSampler : std::uint8_t { kIndependent, kStratified };

struct RenderOptions {
  RendererKind renderer = RendererKind::kScaleSensitive;
  OpacityKind opacity = OpacityKind::kStochastic;
  std::optional<int> level;  ///< scale-sensitive: render the amalgams met on this level
  float footprint = 1.0f;    ///< scale-sensitive without level: pixels of ray footprint
  bool sorted = true;
  std::uint64_t seed = 0;
  PixelSampler sampler = PixelSampler::kIndependent;
  int threads = 0;  ///< 0: all cores
  int width = 512;
  int height = 512;
  int spp = 4;
  TracerKind tracer = TracerKind::kAmalgam;
};

}  // namespace amalgam

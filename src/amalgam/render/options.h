#pragma once
/// \file Renderer options shared by `render`, `trace` and `experiment` (docs/cli.md).

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <variant>

namespace amalgam {

/// The renderers (--renderer), as named in the stats JSON; which one a LevelOfDetail is.
enum class RendererKind : std::uint8_t { kScaleSensitive, kTraditional, kVolumetric };

/// The level-of-detail choice: one type per way of choosing, so that an option that does not
/// apply to a renderer cannot be set for it (render/option_rules.h turns the CLI's flags and
/// Python's keywords into one).
///
/// Scale-sensitive, by footprint (the default): render an amalgam once its box diagonal is
/// smaller than `pixels` widths of the ray's cone (--footprint K).
struct ByFootprint {
  float pixels = 1.0f;
};
/// Scale-sensitive on a fixed level: render the amalgams met on `level`, never deeper (--level).
struct OnLevel {
  int level = 0;
};
/// Traditional: every amalgam is a plain bounding volume, always traversed (full detail).
struct FullDetail {};
/// Volumetric: every object (an instanced mesh) whose cells the ray's cone is wide enough for is
/// rendered as volumetric amalgams (hierarchy/volume/cells.h), the rest at full detail; cells
/// of `cone_widths` widths of the ray's cone. Needs a scene loaded with
/// SceneFileConfig::objects (io/scene_json.h).
struct VolumetricCells {
  float cone_widths = 1.0f;
};
using LevelOfDetail = std::variant<ByFootprint, OnLevel, FullDetail, VolumetricCells>;

inline RendererKind renderer_of(const LevelOfDetail& l) {
  if (std::holds_alternative<FullDetail>(l)) return RendererKind::kTraditional;
  if (std::holds_alternative<VolumetricCells>(l)) return RendererKind::kVolumetric;
  return RendererKind::kScaleSensitive;
}
/// --renderer's name of each RendererKind.
inline std::string_view renderer_name(RendererKind k) {
  return k == RendererKind::kTraditional  ? "traditional"
         : k == RendererKind::kVolumetric ? "volumetric"
                                          : "scale-sensitive";
}
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

/// How messages name an option: kFlags `--level 3` (the CLI), kKeywords `level=3` (Python).
enum class OptionSpelling : std::uint8_t { kFlags, kKeywords };

struct RenderOptions {
  LevelOfDetail lod{};
  OpacityKind opacity = OpacityKind::kStochastic;
  bool sorted = true;
  std::uint64_t seed = 0;
  PixelSampler sampler = PixelSampler::kIndependent;
  int threads = 0;  ///< 0: all cores
  int width = 512;
  int height = 512;
  int spp = 4;
  TracerKind tracer = TracerKind::kAmalgam;

  RendererKind renderer() const { return renderer_of(lod); }
};

}  // namespace amalgam

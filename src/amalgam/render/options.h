#pragma once
/// \file Renderer options shared by `render`, `trace` and `experiment` (docs/cli.md).

#include <cstdint>
#include <optional>

namespace amalgam {

enum class RendererKind : std::uint8_t { kScaleSensitive, kTraditional };
enum class OpacityKind : std::uint8_t { kStochastic, kDeterministic };
/// What finds the hits: amalgam's traversal, or Intel Embree 3 at full detail
/// (render/embree_tracer.h; only the traditional renderer).
enum class TracerKind : std::uint8_t { kAmalgam, kEmbree };

struct RenderOptions {
  RendererKind renderer = RendererKind::kScaleSensitive;
  OpacityKind opacity = OpacityKind::kStochastic;
  std::optional<int> level;  ///< scale-sensitive: render the amalgams met on this level
  float footprint = 1.0f;    ///< scale-sensitive without level: pixels of ray footprint
  bool sorted = true;
  std::uint64_t seed = 0;
  int threads = 0;  ///< 0: all cores
  int width = 512;
  int height = 512;
  int spp = 4;
  TracerKind tracer = TracerKind::kAmalgam;
};

}  // namespace amalgam

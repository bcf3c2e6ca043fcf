#pragma once
/// \file Base-colour textures: an sRGB image sampled at a triangle's interpolated texture
/// coordinates (bilinear, repeating), and the per-triangle coordinates it is sampled with.

#include <cstdint>
#include <vector>

#include "amalgam/math/vec.h"

namespace amalgam {

/// Texture coordinates of one triangle's vertices a, b, c (OpenGL convention, as Assimp
/// gives them: v = 0 is the bottom row of the image).
struct TexCoords {
  float u[3] = {0, 0, 0};
  float v[3] = {0, 0, 0};
};

/// What a texture shows outside [0, 1] along one axis (glTF's sampler wrap modes).
enum class Wrap : std::uint8_t { kRepeat, kClamp, kMirror };

/// An 8-bit sRGB image (the alpha channel, if any, dropped), rows top to bottom.
struct Texture {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> texels;  ///< 3 bytes (R, G, B) per texel
  Wrap wrap_u = Wrap::kRepeat, wrap_v = Wrap::kRepeat;
  Vec3 mean{};  ///< linear mean over the texels (set by `finish_texture`)
};

/// Linear value of an 8-bit sRGB component (IEC 61966-2-1).
float srgb_to_linear(std::uint8_t c);

/// Sets `t.mean`: the mean of the linear colours over all texels (what an amalgam bakes).
void finish_texture(Texture& t);

/// The linear colour at (u, v): bilinear between the four nearest texel centres, each
/// converted to linear first; beyond the image as its wrap modes say (repeat, clamp to the
/// edge, mirrored repeat). Non-finite coordinates sample (0, 0). `t` must hold width * height
/// texels (> 0).
Vec3 sample(const Texture& t, float u, float v);

/// The mean linear colour of `t` over the triangle `c` covers in texture space (what an amalgam
/// bakes for a textured triangle): the midpoint rule over the n^2 equal sub-triangles of the
/// triangle cut n ways along each edge, n from 4 up to 64 as the triangle covers more texels
/// (about one sample per texel), each sample bilinear as `sample`.
Vec3 mean_over_triangle(const Texture& t, const TexCoords& c);

/// The coordinates of the point with barycentric weights (1 - b1 - b2, b1, b2).
inline void interpolate(const TexCoords& c, float b1, float b2, float& u, float& v) {
  const float b0 = 1.0f - b1 - b2;
  u = b0 * c.u[0] + b1 * c.u[1] + b2 * c.u[2];
  v = b0 * c.v[0] + b1 * c.v[1] + b2 * c.v[2];
}

}  // namespace amalgam

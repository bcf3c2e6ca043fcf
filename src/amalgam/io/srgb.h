#pragma once
/// \file The sRGB transfer function (IEC 61966-2-1), as the PNG codec and the colour map use
/// it.

#include <cmath>
#include <cstdint>

namespace amalgam {

/// Linear value in [0, 1] -> sRGB-encoded value in [0, 1].
inline double linear_to_srgb(double v) {
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

/// sRGB-encoded value in [0, 1] -> linear value in [0, 1].
inline double srgb_to_linear(double s) {
  return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

/// A linear value as an 8-bit sRGB sample: clamped to [0, 1] (NaN -> 0), encoded, rounded.
inline std::uint8_t encode_srgb8(float v) {
  if (!(v > 0.0f)) return 0;  // also NaN
  if (v >= 1.0f) return 255;
  return static_cast<std::uint8_t>(std::lround(linear_to_srgb(v) * 255.0));
}

}  // namespace amalgam

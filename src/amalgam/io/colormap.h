#pragma once
/// \file False colour for per-pixel figures (the cost image of `render`, the error image of
/// `compare`): the viridis colour map.

#include <vector>

#include "amalgam/math/vec.h"

namespace amalgam {

/// Maps non-negative values (e.g. intersection tests per pixel) to the viridis colour map, in
/// linear RGB (so write_image's sRGB encoding displays the published colours). Values are
/// normalised by the largest finite value, after log1p when log_scale is set; negative and NaN
/// values map to the low end, +inf to the high end. Luminance increases with the value.
/// Writes that largest finite value (0 if no value is positive) to *vmax_out when not null.
std::vector<Vec3> false_colour(const std::vector<double>& values, bool log_scale,
                               double* vmax_out = nullptr);

/// Viridis at t in [0, 1] (clamped), in linear RGB.
Vec3 viridis(double t);

/// A range of positive values shown on a log scale: `min` maps to the low end of the colour
/// map, `max` to the high end.
struct LogRange {
  double min = 1.0, max = 1.0;
};

/// The range of the values themselves: the smallest positive finite value and the largest
/// finite one ({1, 1} when no value is positive).
LogRange own_range(const std::vector<double>& values);

/// Position of `v` on the log scale of `r`: (ln v - ln min) / (ln max - ln min), clamped to
/// [0, 1]; values <= min (and NaN) give 0, values >= max give 1 (so does everything when
/// min == max).
double log_position(double v, const LogRange& r);

/// Viridis at log_position(v, r) for every value: the same value and range give the same
/// colour in any image.
std::vector<Vec3> log_colours(const std::vector<double>& values, const LogRange& r);

/// `image` (width x height) with a colour bar of `r` appended below it: one black row, then
/// max(6, height / 10) rows in which column x shows viridis((x + 0.5) / width), the colour of
/// the value exp(ln min + (x + 0.5) / width (ln max - ln min)). White ticks mark the powers of
/// ten inside the range in the top third of the bar. Sets `out_height`.
std::vector<Vec3> with_colour_bar(const std::vector<Vec3>& image, int width, int height,
                                  const LogRange& r, int& out_height);

}  // namespace amalgam

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

}  // namespace amalgam

#pragma once
/// \file The coordinates a described scene may use.

#include <string>

#include "amalgam/geometry/bbox.h"

namespace amalgam {

/// Coordinates beyond this are rejected: a few times 1e19 squared overflows float, and the
/// renderer (camera, distances, spheres) would silently produce a black image (issue 6,
/// tests/geometry/robust_test.cpp: Degenerate.SceneJsonRejectsOrRendersExtremeInput).
constexpr double kMaxCoordinate = 1e18;

/// Throws InputError "<where>: the geometry reaches a coordinate of X, beyond the supported
/// range [-1e18, 1e18]" when `bounds` reaches beyond +-kMaxCoordinate (or is not finite).
void check_extent(const Bbox& bounds, const std::string& where);

}  // namespace amalgam

#pragma once
/// \file The coordinates a described scene may use.

#include <string>

#include "amalgam/geometry/bbox.h"

namespace amalgam {

/// Coordinates beyond this are rejected: the watertight triangle test computes t as a sum of
/// products of three coordinates relative to the ray origin, which overflows float beyond
/// about 7e12 (a triangle there is never hit: a silently empty image). Measured: a cube of
/// size 1e12 seen from 6.5e12 renders correctly, one of size 1e13 does not
/// (tests/geometry/robust_test.cpp: Degenerate.HugeAndTinyCoordinatesRender,
/// Degenerate.SceneJsonRejectsOrRendersExtremeInput).
constexpr double kMaxCoordinate = 1e12;

/// Throws InputError "<where>: the geometry reaches a coordinate of X, beyond the supported
/// range [-1e12, 1e12]" when `bounds` reaches beyond +-kMaxCoordinate (or is not finite).
void check_extent(const Bbox& bounds, const std::string& where);

}  // namespace amalgam

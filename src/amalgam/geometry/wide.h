#pragma once
/// \file Structure-of-arrays blocks of four boxes and four triangles: what the SIMD kernels
/// (wide_kernels.h) test at once. Data only.

#include <cstdint>

#include "amalgam/geometry/bbox.h"

#if defined(__SSE2__) || defined(_M_X64)
#include <immintrin.h>
#define AMALGAM_WIDE_SSE 1
#endif

namespace amalgam {

/// Lanes per SoA block.
inline constexpr int kWideLanes = 4;

/// The boxes of up to four children, structure of arrays. Unused lanes hold empty boxes.
struct alignas(16) WideBox4 {
  float lo[3][kWideLanes];  ///< lo[axis][lane]
  float hi[3][kWideLanes];
};

/// The vertices of up to four triangles of one leaf, structure of arrays: v[vertex][axis][lane]
/// (vertex 0, 1, 2 = Primitive::a, b, c). The vertices are stored as they are, not as edges or
/// any other precomputed form: the watertight test shears `vertex - origin`, and only the
/// same float operations on the same inputs give bit-identical results to `triangle_test`.
/// Unused lanes hold NaN (never a hit, never the zero case of the test).
struct alignas(16) TrianglePack4 {
  float v[3][3][kWideLanes];
};

}  // namespace amalgam

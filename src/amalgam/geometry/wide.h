#pragma once
/// \file Structure-of-arrays blocks of eight boxes and four triangles: what the SIMD kernels
/// (wide_kernels.h) test at once. Data only.

#include <cstdint>

#include "amalgam/geometry/bbox.h"

#if defined(__SSE2__) || defined(_M_X64)
#include <immintrin.h>
#define AMALGAM_WIDE_SSE 1
#endif

namespace amalgam {

/// Lanes of an SSE register and of a triangle pack.
inline constexpr int kWideLanes = 4;
/// Lanes of a box block: the children of one node, tested at once (one AVX register, or two
/// SSE halves).
inline constexpr int kBoxLanes = 8;

/// Boxes in structure-of-arrays rows as the box kernels read them: the lo planes of axis a at
/// `rows + a * stride`, the hi planes at `rows + (3 + a) * stride`, lane i at `+ i`; `stride`
/// (4 or 8) is the number of lanes of a row.
struct BoxRows {
  const float* rows;
  int stride;
};

/// The boxes of up to eight children, structure of arrays (each axis's lanes one 32-byte row).
/// Unused lanes hold empty boxes.
struct alignas(32) WideBox8 {
  float lo[3][kBoxLanes];  ///< lo[axis][lane]
  float hi[3][kBoxLanes];
  BoxRows rows() const { return {lo[0], kBoxLanes}; }
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

#pragma once
// The AVX2 copy's 8-lane triangle kernel, compiled for AVX2 in avx2_kernels.cpp, for the
// differential test in simd_test.cpp (the rest of the tests run the portable copy). Defined
// only where the library has its AVX2 copy (AMALGAM_BUILD_AVX2_COPY).

#include "amalgam/geometry/ray.h"
#include "amalgam/geometry/wide.h"

namespace amalgam::test {

/// `triangle_test_lanes<Lanes8>` on the packs p[0], p[1] (first `n` lanes, 1..8): the
/// hit mask; out[0..4][lane] = t, u, v, w, det of each hit lane.
unsigned avx2_triangle_test8(const TrianglePack4 p[2], const Ray& ray, float tmin, float tmax,
                             int n, float out[5][8]);

/// `box_test_lanes<Lanes8, mode>` on the rows `b` (first `n` lanes) against `ray` over
/// [ray.tmin, ray.tmax]: the hit mask, entry t per lane. Mode kNonZero if `simple` (the caller
/// checked `box_rays_simple`), else kZeroAxes.
unsigned avx2_box_test8(BoxRows b, const Ray& ray, int n, float t_entry[8], bool simple);

}  // namespace amalgam::test

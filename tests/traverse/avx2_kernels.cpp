// The AVX2 copy's triangle kernel for simd_test.cpp, compiled as render/render_avx2.cpp
// compiles the library's AVX2 copy: the lower layers first, for the baseline, then the hot-path
// header between AMALGAM_AVX2_BEGIN and _END (util/isa.h), in the inline namespace isa_avx2.
#include "avx2_kernels.h"

#if defined(AMALGAM_BUILD_AVX2_COPY)
#define AMALGAM_ISA_AVX2 1  // before any include: util/isa.h reads it once

#include <bit>

#include "amalgam/geometry/intersect.h"
#include "amalgam/geometry/wide.h"
#include "amalgam/util/isa.h"

AMALGAM_AVX2_BEGIN
#include "amalgam/geometry/wide_kernels.h"

namespace amalgam::test {

unsigned avx2_triangle_test8(const TrianglePack4 p[2], const Ray& ray, float tmin, float tmax,
                             int n, float out[5][8]) {
  TrianglePackHitsN<8> h;
  const unsigned mask = triangle_test_lanes<Lanes8>(p, WideRay::of(ray), tmin, tmax, n, h);
  for (int i = 0; i < 8; ++i)
    out[0][i] = h.t[i], out[1][i] = h.u[i], out[2][i] = h.v[i], out[3][i] = h.w[i],
    out[4][i] = h.det[i];
  return mask;
}

unsigned avx2_box_test8(BoxRows b, const Ray& ray, int n, float t_entry[8], bool simple) {
  const WideRay wr = WideRay::of(ray);
  return simple
             ? box_test_lanes<Lanes8, BoxRays::kNonZero>(b, 0, wr, ray.tmin, ray.tmax, n, t_entry)
             : box_test_lanes<Lanes8, BoxRays::kZeroAxes>(b, 0, wr, ray.tmin, ray.tmax, n, t_entry);
}

}  // namespace amalgam::test
AMALGAM_AVX2_END

#endif

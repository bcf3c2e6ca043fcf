#pragma once
/// \file Structure-of-arrays child boxes of an explicit hierarchy, for testing all children of
/// a wide node at once (SSE, or AVX2 when built with AMALGAM_AVX2; scalar otherwise).
///
/// `WideNodes` is derived data: `build_wide` fills it from `ExplicitHierarchy::nodes` (called
/// at the end of `bake`, so `build_explicit` always has it). The traversal uses it only when
/// it has one header per node (`ExplicitHierarchy::wide_nodes`); a hierarchy whose nodes are
/// edited afterwards must call `build_wide` again.
///
/// The box kernel below is the SIMD form of the scalar robust slab test `intersect_box`
/// (intersect.h), written to give bit-identical results lane by lane, NaNs, signed zeros and
/// zero direction components included (see the comments at each step); tests/traverse/
/// simd_test.cpp checks this against the scalar traversal.

#include <cstdint>
#include <vector>

#include "amalgam/geometry/intersect.h"

#if defined(__SSE2__) || defined(_M_X64)
#include <immintrin.h>
#define AMALGAM_WIDE_SSE 1
#endif

namespace amalgam {

class ExplicitHierarchy;

/// Lanes per SoA block.
inline constexpr int kWideLanes = 4;

/// The boxes of up to four children, structure of arrays. Unused lanes hold empty boxes.
struct alignas(16) WideBox4 {
  float lo[3][kWideLanes];  ///< lo[axis][lane]
  float hi[3][kWideLanes];
};

/// A node as the fast traversal reads it (12 bytes instead of ExplicitNode's 32).
struct WideHeader {
  std::uint32_t first = 0;  ///< first child (node or primitive), as ExplicitNode::first
  std::uint32_t block = 0;  ///< interior nodes: first of ceil(count / 4) blocks in `blocks`
  std::uint16_t count = 0;
  std::uint8_t leaf = 0;
};

struct WideNodes {
  std::vector<WideHeader> headers;  ///< one per node
  std::vector<WideBox4> blocks;     ///< children's boxes of every interior node
  std::size_t bytes() const {
    return headers.size() * sizeof(WideHeader) + blocks.size() * sizeof(WideBox4);
  }
};

/// (Re)builds `h.wide` from `h.nodes`.
void build_wide(ExplicitHierarchy& h);

/// Per-ray constants of the wide box test.
struct WideRay {
  float o[3];
  float inv[3];
  bool zero[3];  ///< dir[axis] == 0: the axis is a containment test (as in intersect_box)
  static WideRay of(const Ray& r) {
    WideRay w;
    for (int a = 0; a < 3; ++a)
      w.o[a] = r.origin[a], w.inv[a] = r.inv_dir[a], w.zero[a] = r.dir[a] == 0.0f;
    return w;
  }
};

/// Tests the first `n` (1..4) boxes of `b` against the ray over [tmin, tmax], exactly as
/// `intersect_box` would one at a time. Returns the lanes hit as a bit mask; `t_entry[i]` is
/// the entry parameter (Span::t0) of lane i where it is hit.
inline unsigned intersect_wide4(const WideBox4& b, const WideRay& r, float tmin, float tmax, int n,
                                float t_entry[kWideLanes]) {
  constexpr float kGrow = 1.0f + 2.0f * gamma(3);
#if AMALGAM_WIDE_SSE
  __m128 t_near = _mm_set1_ps(-kInfinity), t_far = _mm_set1_ps(kInfinity);
  __m128 ok = _mm_castsi128_ps(_mm_set1_epi32(-1));
  for (int a = 0; a < 3; ++a) {
    const __m128 o = _mm_set1_ps(r.o[a]);
    const __m128 lo = _mm_load_ps(b.lo[a]), hi = _mm_load_ps(b.hi[a]);
    if (r.zero[a]) {  // scalar: if (o < lo || o > hi) miss
      ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpnlt_ps(o, lo), _mm_cmpngt_ps(o, hi)));
      continue;
    }
    const __m128 inv = _mm_set1_ps(r.inv[a]);
    const __m128 t0 = _mm_mul_ps(_mm_sub_ps(lo, o), inv);
    const __m128 t1 = _mm_mul_ps(_mm_sub_ps(hi, o), inv);
    // scalar: if (t0 > t1) swap. minps(x, y) = x < y ? x : y; maxps(x, y) = x > y ? x : y.
    const __m128 tn = _mm_min_ps(t1, t0);
    const __m128 tf = _mm_mul_ps(_mm_max_ps(t0, t1), _mm_set1_ps(kGrow));
    t_near = _mm_max_ps(tn, t_near);  // if (t0 > t_near) t_near = t0
    t_far = _mm_min_ps(tf, t_far);    // if (t1 < t_far) t_far = t1
  }
  ok = _mm_and_ps(ok, _mm_cmple_ps(t_near, t_far));
  const __m128 s0 = _mm_max_ps(_mm_set1_ps(tmin), t_near);  // std::max(t_near, tmin)
  const __m128 s1 = _mm_min_ps(_mm_set1_ps(tmax), t_far);   // std::min(t_far, tmax)
  ok = _mm_and_ps(ok, _mm_cmple_ps(s0, s1));
  _mm_storeu_ps(t_entry, s0);
  return static_cast<unsigned>(_mm_movemask_ps(ok)) & ((1u << n) - 1u);
#else
  unsigned mask = 0;
  for (int i = 0; i < n; ++i) {
    Bbox box{{b.lo[0][i], b.lo[1][i], b.lo[2][i]}, {b.hi[0][i], b.hi[1][i], b.hi[2][i]}};
    Ray ray;
    ray.origin = {r.o[0], r.o[1], r.o[2]};
    ray.inv_dir = {r.inv[0], r.inv[1], r.inv[2]};
    for (int a = 0; a < 3; ++a) ray.dir[a] = r.zero[a] ? 0.0f : 1.0f / r.inv[a];
    ray.tmin = tmin, ray.tmax = tmax;
    float t0, t1;
    if (intersect_box(ray, box, t0, t1)) mask |= 1u << i, t_entry[i] = t0;
  }
  (void)kGrow;
  return mask;
#endif
}

#if AMALGAM_WIDE_SSE && defined(__AVX2__)
/// Two blocks (8 boxes, the first `n` of them used, 5..8) at once with AVX; same contract as
/// `intersect_wide4`.
inline unsigned intersect_wide8(const WideBox4& b0, const WideBox4& b1, const WideRay& r,
                                float tmin, float tmax, int n, float t_entry[2 * kWideLanes]) {
  constexpr float kGrow = 1.0f + 2.0f * gamma(3);
  __m256 t_near = _mm256_set1_ps(-kInfinity), t_far = _mm256_set1_ps(kInfinity);
  __m256 ok = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  for (int a = 0; a < 3; ++a) {
    const __m256 o = _mm256_set1_ps(r.o[a]);
    const __m256 lo = _mm256_set_m128(_mm_load_ps(b1.lo[a]), _mm_load_ps(b0.lo[a]));
    const __m256 hi = _mm256_set_m128(_mm_load_ps(b1.hi[a]), _mm_load_ps(b0.hi[a]));
    if (r.zero[a]) {
      ok = _mm256_and_ps(
          ok, _mm256_and_ps(_mm256_cmp_ps(o, lo, _CMP_NLT_US), _mm256_cmp_ps(o, hi, _CMP_NGT_US)));
      continue;
    }
    const __m256 inv = _mm256_set1_ps(r.inv[a]);
    const __m256 t0 = _mm256_mul_ps(_mm256_sub_ps(lo, o), inv);
    const __m256 t1 = _mm256_mul_ps(_mm256_sub_ps(hi, o), inv);
    const __m256 tn = _mm256_min_ps(t1, t0);
    const __m256 tf = _mm256_mul_ps(_mm256_max_ps(t0, t1), _mm256_set1_ps(kGrow));
    t_near = _mm256_max_ps(tn, t_near);
    t_far = _mm256_min_ps(tf, t_far);
  }
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(t_near, t_far, _CMP_LE_OQ));
  const __m256 s0 = _mm256_max_ps(_mm256_set1_ps(tmin), t_near);
  const __m256 s1 = _mm256_min_ps(_mm256_set1_ps(tmax), t_far);
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(s0, s1, _CMP_LE_OQ));
  _mm256_storeu_ps(t_entry, s0);
  return static_cast<unsigned>(_mm256_movemask_ps(ok)) & ((1u << n) - 1u);
}
#endif

}  // namespace amalgam

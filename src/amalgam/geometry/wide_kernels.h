#pragma once
/// \file SIMD kernels: four (or, in the AVX2 copy, eight) ray/box slab tests at once, and the
/// watertight ray/triangle test on four triangles at once (SSE; a scalar loop without SSE).
///
/// The box kernel is the SIMD form of the scalar robust slab test `intersect_box`
/// (intersect.h), and the pack kernel that of the watertight `triangle_test`, both written to
/// give bit-identical results lane by lane, NaNs, signed zeros and zero direction components
/// included (see the comments at each step); tests/traverse/simd_test.cpp checks them against
/// the scalar kernels and the whole traversal against the scalar reference.
///
/// Compiled once per instruction set (util/isa.h): include it only from the hot paths
/// (traverse/, render/), never from a lower layer, so that the AVX2 translation unit is the
/// first to include it there.

#include <bit>

#include "amalgam/geometry/intersect.h"
#include "amalgam/geometry/wide.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// Per-ray constants of the wide box and triangle tests.
struct WideRay {
  float o[3];
  float inv[3];
  bool zero[3];  ///< dir[axis] == 0: the axis is a containment test (as in intersect_box)
  bool any_zero;
  TrianglePre pre;  ///< the watertight triangle test's setup (TrianglePre::of)
#if AMALGAM_WIDE_SSE
  // Broadcast once per ray, so the kernels read them as memory operands instead of
  // broadcasting them again for every node and leaf.
  __m128 o4[3], inv4[3];
  __m128 shear4[3];  ///< pre.sx, pre.sy, pre.sz
  __m128 ok4[3];     ///< o[pre.kx], o[pre.ky], o[pre.kz]
#if defined(AMALGAM_ISA_AVX2)
  __m256 o8[3], inv8[3];
#endif
#endif
  static WideRay of(const Ray& r) {
    WideRay w;
    for (int a = 0; a < 3; ++a) {
      w.o[a] = r.origin[a], w.inv[a] = r.inv_dir[a], w.zero[a] = r.dir[a] == 0.0f;
#if AMALGAM_WIDE_SSE
      w.o4[a] = _mm_set1_ps(w.o[a]), w.inv4[a] = _mm_set1_ps(w.inv[a]);
#if defined(AMALGAM_ISA_AVX2)
      w.o8[a] = _mm256_set1_ps(w.o[a]), w.inv8[a] = _mm256_set1_ps(w.inv[a]);
#endif
#endif
    }
    w.any_zero = w.zero[0] || w.zero[1] || w.zero[2];
    w.pre = TrianglePre::of(r);
#if AMALGAM_WIDE_SSE
    w.shear4[0] = _mm_set1_ps(w.pre.sx), w.shear4[1] = _mm_set1_ps(w.pre.sy);
    w.shear4[2] = _mm_set1_ps(w.pre.sz);
    w.ok4[0] = w.o4[w.pre.kx], w.ok4[1] = w.o4[w.pre.ky], w.ok4[2] = w.o4[w.pre.kz];
#endif
    return w;
  }
};

/// Tests the first `n` (1..4) boxes of `b` against the ray over [tmin, tmax], exactly as
/// `intersect_box` would one at a time. Returns the lanes hit as a bit mask; `t_entry[i]` is
/// the entry parameter (Span::t0) of lane i where it is hit. `kZeroAxes` false: the caller
/// knows that `r` has no zero direction component (`!r.any_zero`), so the per-axis branch of
/// that case is left out.
///
/// The enlargement of the far distance by 2 gamma(3) (the scalar test's `t1 *= ...` per axis)
/// is applied once to the minimum over the axes instead of to each axis: x -> x * (1 + 2
/// gamma(3)) rounded is non-decreasing and maps only zeros to zero, so the minimum of the
/// products and the product of the minimum are the same float (a NaN is skipped either way).
template <bool kZeroAxes = true>
inline unsigned intersect_wide4(const WideBox4& b, const WideRay& r, float tmin, float tmax, int n,
                                float t_entry[kWideLanes]) {
  constexpr float kGrow = 1.0f + 2.0f * gamma(3);
#if AMALGAM_WIDE_SSE
  __m128 t_near = _mm_set1_ps(-kInfinity), t_far = _mm_set1_ps(kInfinity);
  __m128 ok = _mm_castsi128_ps(_mm_set1_epi32(-1));
  for (int a = 0; a < 3; ++a) {
    const __m128 o = r.o4[a];
    const __m128 lo = _mm_load_ps(b.lo[a]), hi = _mm_load_ps(b.hi[a]);
    if (kZeroAxes && r.zero[a]) {  // scalar: if (o < lo || o > hi) miss
      ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpnlt_ps(o, lo), _mm_cmpngt_ps(o, hi)));
      continue;
    }
    const __m128 inv = r.inv4[a];
    const __m128 t0 = _mm_mul_ps(_mm_sub_ps(lo, o), inv);
    const __m128 t1 = _mm_mul_ps(_mm_sub_ps(hi, o), inv);
    // scalar: if (t0 > t1) swap. minps(x, y) = x < y ? x : y; maxps(x, y) = x > y ? x : y.
    const __m128 tn = _mm_min_ps(t1, t0);
    const __m128 tf = _mm_max_ps(t0, t1);
    t_near = _mm_max_ps(tn, t_near);  // if (t0 > t_near) t_near = t0
    t_far = _mm_min_ps(tf, t_far);    // if (t1 < t_far) t_far = t1
  }
  t_far = _mm_mul_ps(t_far, _mm_set1_ps(kGrow));
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

#if AMALGAM_WIDE_SSE && defined(AMALGAM_ISA_AVX2)
/// Two blocks (8 boxes, the first `n` of them used, 5..8) at once with AVX; same contract as
/// `intersect_wide4`.
template <bool kZeroAxes = true>
inline unsigned intersect_wide8(const WideBox4& b0, const WideBox4& b1, const WideRay& r,
                                float tmin, float tmax, int n, float t_entry[2 * kWideLanes]) {
  constexpr float kGrow = 1.0f + 2.0f * gamma(3);
  __m256 t_near = _mm256_set1_ps(-kInfinity), t_far = _mm256_set1_ps(kInfinity);
  __m256 ok = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  for (int a = 0; a < 3; ++a) {
    const __m256 o = r.o8[a];
    const __m256 lo = _mm256_set_m128(_mm_load_ps(b1.lo[a]), _mm_load_ps(b0.lo[a]));
    const __m256 hi = _mm256_set_m128(_mm_load_ps(b1.hi[a]), _mm_load_ps(b0.hi[a]));
    if (kZeroAxes && r.zero[a]) {
      ok = _mm256_and_ps(
          ok, _mm256_and_ps(_mm256_cmp_ps(o, lo, _CMP_NLT_US), _mm256_cmp_ps(o, hi, _CMP_NGT_US)));
      continue;
    }
    const __m256 inv = r.inv8[a];
    const __m256 t0 = _mm256_mul_ps(_mm256_sub_ps(lo, o), inv);
    const __m256 t1 = _mm256_mul_ps(_mm256_sub_ps(hi, o), inv);
    const __m256 tn = _mm256_min_ps(t1, t0);
    const __m256 tf = _mm256_max_ps(t0, t1);
    t_near = _mm256_max_ps(tn, t_near);
    t_far = _mm256_min_ps(tf, t_far);
  }
  t_far = _mm256_mul_ps(t_far, _mm256_set1_ps(kGrow));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(t_near, t_far, _CMP_LE_OQ));
  const __m256 s0 = _mm256_max_ps(_mm256_set1_ps(tmin), t_near);
  const __m256 s1 = _mm256_min_ps(_mm256_set1_ps(tmax), t_far);
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(s0, s1, _CMP_LE_OQ));
  _mm256_storeu_ps(t_entry, s0);
  return static_cast<unsigned>(_mm256_movemask_ps(ok)) & ((1u << n) - 1u);
}
#endif

/// A pack test's candidates by lane (valid where its hit mask is set).
struct alignas(16) TrianglePackHits {
  float t[kWideLanes], u[kWideLanes], v[kWideLanes], w[kWideLanes], det[kWideLanes];
  TriangleCandidate lane(int i) const { return {t[i], u[i], v[i], w[i], det[i]}; }
};

/// `triangle_test` on the first `n` (1..4) triangles of `p` at once, each against the same
/// [tmin, tmax]: the hit lanes as a bit mask, their t and barycentrics in `out`, lane for lane
/// bit-identical to the scalar test. The SSE form performs the scalar test's float operations
/// in the same order on the same operands (a product is commutative in IEEE arithmetic, a sum
/// of three is not: both sum left to right), with no fused multiply-add (the build does not
/// enable FMA), and takes the same double-precision path for a lane whose u, v or w is zero.
/// The caller picks the closest hit among the lanes (a lane's tmax does not shrink by an
/// earlier lane's hit here, unlike in a one-by-one loop).
inline unsigned triangle_test4(const TrianglePack4& p, const WideRay& r, float tmin, float tmax,
                               int n, TrianglePackHits& out) {
  const TrianglePre& pre = r.pre;
  const unsigned lanes = (1u << n) - 1u;
#if AMALGAM_WIDE_SSE
  const int kx = pre.kx, ky = pre.ky, kz = pre.kz;
  const __m128 sx = r.shear4[0], sy = r.shear4[1], sz = r.shear4[2];
  const __m128 ox = r.ok4[0], oy = r.ok4[1], oz = r.ok4[2];
  // Sheared and translated vertices (scalar: A[kx] - sx * A[kz] with A = a - origin).
  __m128 X[3], Y[3], Z[3];
  for (int k = 0; k < 3; ++k) {
    Z[k] = _mm_sub_ps(_mm_load_ps(p.v[k][kz]), oz);
    X[k] = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(p.v[k][kx]), ox), _mm_mul_ps(sx, Z[k]));
    Y[k] = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(p.v[k][ky]), oy), _mm_mul_ps(sy, Z[k]));
  }
  __m128 u = _mm_sub_ps(_mm_mul_ps(X[2], Y[1]), _mm_mul_ps(Y[2], X[1]));  // cx by - cy bx
  __m128 v = _mm_sub_ps(_mm_mul_ps(X[0], Y[2]), _mm_mul_ps(Y[0], X[2]));  // ax cy - ay cx
  __m128 w = _mm_sub_ps(_mm_mul_ps(X[1], Y[0]), _mm_mul_ps(Y[1], X[0]));  // bx ay - by ax
  const __m128 zero = _mm_setzero_ps();
  const unsigned edge =
      static_cast<unsigned>(_mm_movemask_ps(_mm_or_ps(
          _mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)), _mm_cmpeq_ps(w, zero)))) &
      lanes;
  if (edge) [[unlikely]] {  // the scalar test's edge case, lane by lane in double precision
    alignas(16) float x[3][kWideLanes], y[3][kWideLanes], U[kWideLanes], V[kWideLanes],
        W[kWideLanes];
    for (int k = 0; k < 3; ++k) _mm_store_ps(x[k], X[k]), _mm_store_ps(y[k], Y[k]);
    _mm_store_ps(U, u), _mm_store_ps(V, v), _mm_store_ps(W, w);
    for (unsigned m = edge; m; m &= m - 1) {
      const int i = std::countr_zero(m);
      U[i] = static_cast<float>(double(x[2][i]) * y[1][i] - double(y[2][i]) * x[1][i]);
      V[i] = static_cast<float>(double(x[0][i]) * y[2][i] - double(y[0][i]) * x[2][i]);
      W[i] = static_cast<float>(double(x[1][i]) * y[0][i] - double(y[1][i]) * x[0][i]);
    }
    u = _mm_load_ps(U), v = _mm_load_ps(V), w = _mm_load_ps(W);
  }
  // Reject mixed signs: (u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0).
  const __m128 neg =
      _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)), _mm_cmplt_ps(w, zero));
  const __m128 pos =
      _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)), _mm_cmpgt_ps(w, zero));
  const __m128 mixed = _mm_and_ps(neg, pos);
  // Most packs stop here: every lane's ray passes outside its triangle.
  if ((static_cast<unsigned>(_mm_movemask_ps(mixed)) & lanes) == lanes) return 0;
  const __m128 det = _mm_add_ps(_mm_add_ps(u, v), w);
  const __m128 bad = _mm_or_ps(mixed, _mm_cmpeq_ps(det, zero));
  // t = (u az + v bz + w cz) / det with az = sz A[kz].
  const __m128 zs[3] = {_mm_mul_ps(sz, Z[0]), _mm_mul_ps(sz, Z[1]), _mm_mul_ps(sz, Z[2])};
  const __m128 num =
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(u, zs[0]), _mm_mul_ps(v, zs[1])), _mm_mul_ps(w, zs[2]));
  const __m128 t = _mm_div_ps(num, det);
  // !(t >= tmin && t <= tmax) rejects: ordered compares, so a NaN t is rejected as well.
  const __m128 in =
      _mm_and_ps(_mm_cmpge_ps(t, _mm_set1_ps(tmin)), _mm_cmple_ps(t, _mm_set1_ps(tmax)));
  _mm_store_ps(out.t, t), _mm_store_ps(out.u, u), _mm_store_ps(out.v, v);
  _mm_store_ps(out.w, w), _mm_store_ps(out.det, det);
  unsigned hits = static_cast<unsigned>(_mm_movemask_ps(_mm_andnot_ps(bad, in))) & lanes;
  if (hits) {
    // The scalar test's rejection of t within its rounding error, lane by lane on the same
    // operands (triangle_t_error).
    alignas(16) float x[3][kWideLanes], y[3][kWideLanes], z[3][kWideLanes];
    for (int k = 0; k < 3; ++k)
      _mm_store_ps(x[k], X[k]), _mm_store_ps(y[k], Y[k]), _mm_store_ps(z[k], Z[k]);
    for (unsigned m = hits; m; m &= m - 1) {
      const int i = std::countr_zero(m);
      if (out.t[i] <= triangle_t_error(x[0][i], y[0][i], x[1][i], y[1][i], x[2][i], y[2][i],
                                       z[0][i], z[1][i], z[2][i], pre.sz, out.u[i], out.v[i],
                                       out.w[i], out.det[i]))
        hits &= ~(1u << i);
    }
  }
  return hits;
#else
  Ray ray;
  ray.origin = {r.o[0], r.o[1], r.o[2]};
  ray.tmin = tmin, ray.tmax = tmax;
  unsigned mask = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3 a{p.v[0][0][i], p.v[0][1][i], p.v[0][2][i]};
    const Vec3 b{p.v[1][0][i], p.v[1][1][i], p.v[1][2][i]};
    const Vec3 c{p.v[2][0][i], p.v[2][1][i], p.v[2][2][i]};
    TriangleCandidate h;
    if (!triangle_test(ray, pre, a, b, c, h)) continue;
    mask |= 1u << i;
    out.t[i] = h.t, out.u[i] = h.u, out.v[i] = h.v, out.w[i] = h.w, out.det[i] = h.det;
  }
  (void)lanes;
  return mask;
#endif
}

AMALGAM_ISA_END
}  // namespace amalgam

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

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "amalgam/geometry/intersect.h"
#include "amalgam/geometry/wide.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// Per-ray constants of the wide box and triangle tests.
struct WideRay {
  float o[3];
  float inv[3];
  bool zero[3];     ///< dir[axis] == 0: the axis is a containment test (as in intersect_box)
  TrianglePre pre;  ///< the watertight triangle test's setup (TrianglePre::of)
#if AMALGAM_WIDE_SSE
  // Broadcast once per ray, so the kernels read them as memory operands instead of
  // broadcasting them again for every node and leaf. The AVX2 copy keeps only the 8-wide
  // forms: the 4-wide kernels read their lower halves (the same bits), which saved the
  // broadcasts and stores of the 4-wide set per ray.
#if defined(AMALGAM_ISA_AVX2)
  __m256 o8[3], inv8[3];
  __m256 shear8[3];  ///< pre.sx, pre.sy, pre.sz
  __m256 ok8[3];     ///< o[pre.kx], o[pre.ky], o[pre.kz]
#else
  __m128 o4[3], inv4[3];
  __m128 shear4[3], ok4[3];  ///< as shear8, ok8
#endif
#endif
  [[gnu::always_inline]] static WideRay of(const Ray& r) {
    WideRay w;
    for (int a = 0; a < 3; ++a) {
      w.o[a] = r.origin[a], w.inv[a] = r.inv_dir[a], w.zero[a] = r.dir[a] == 0.0f;
#if AMALGAM_WIDE_SSE
#if defined(AMALGAM_ISA_AVX2)
      w.o8[a] = _mm256_set1_ps(w.o[a]), w.inv8[a] = _mm256_set1_ps(w.inv[a]);
#else
      w.o4[a] = _mm_set1_ps(w.o[a]), w.inv4[a] = _mm_set1_ps(w.inv[a]);
#endif
#endif
    }
    w.pre = TrianglePre::of(r);
#if AMALGAM_WIDE_SSE
#if defined(AMALGAM_ISA_AVX2)
    w.shear8[0] = _mm256_set1_ps(w.pre.sx), w.shear8[1] = _mm256_set1_ps(w.pre.sy);
    w.shear8[2] = _mm256_set1_ps(w.pre.sz);
    w.ok8[0] = w.o8[w.pre.kx], w.ok8[1] = w.o8[w.pre.ky], w.ok8[2] = w.o8[w.pre.kz];
#else
    w.shear4[0] = _mm_set1_ps(w.pre.sx), w.shear4[1] = _mm_set1_ps(w.pre.sy);
    w.shear4[2] = _mm_set1_ps(w.pre.sz);
    w.ok4[0] = w.o4[w.pre.kx], w.ok4[1] = w.o4[w.pre.ky], w.ok4[2] = w.o4[w.pre.kz];
#endif
#endif
    return w;
  }
};

#if AMALGAM_WIDE_SSE
/// The vector operations of the box and triangle kernels: 4 lanes (SSE) from half a box block
/// or one pack...
struct Lanes4 {
  using V = __m128;
  static constexpr int kLanes = 4;
  /// One coordinate of one vertex of the triangles of pack `p`.
  static V load(const TrianglePack4* p, int vertex, int axis) {
    return _mm_load_ps(p[0].v[vertex][axis]);
  }
  static V load_aligned(const float* d) { return _mm_load_ps(d); }
  static V load(const float* d) { return _mm_loadu_ps(d); }
  static V set1(float x) { return _mm_set1_ps(x); }
  static V zero() { return _mm_setzero_ps(); }
  static V all() { return _mm_castsi128_ps(_mm_set1_epi32(-1)); }
  static V add(V a, V b) { return _mm_add_ps(a, b); }
  static V sub(V a, V b) { return _mm_sub_ps(a, b); }
  static V mul(V a, V b) { return _mm_mul_ps(a, b); }
  static V div(V a, V b) { return _mm_div_ps(a, b); }
  static V min(V a, V b) { return _mm_min_ps(a, b); }
  static V max(V a, V b) { return _mm_max_ps(a, b); }
  static V eq(V a, V b) { return _mm_cmpeq_ps(a, b); }
  static V lt(V a, V b) { return _mm_cmplt_ps(a, b); }
  static V gt(V a, V b) { return _mm_cmpgt_ps(a, b); }
  static V ge(V a, V b) { return _mm_cmpge_ps(a, b); }
  static V le(V a, V b) { return _mm_cmple_ps(a, b); }
  static V nlt(V a, V b) { return _mm_cmpnlt_ps(a, b); }
  static V ngt(V a, V b) { return _mm_cmpngt_ps(a, b); }
  static V bor(V a, V b) { return _mm_or_ps(a, b); }
  static V band(V a, V b) { return _mm_and_ps(a, b); }
  static V andnot(V a, V b) { return _mm_andnot_ps(a, b); }
  static unsigned mask(V a) { return static_cast<unsigned>(_mm_movemask_ps(a)); }
  static void store(float* d, V a) { _mm_storeu_ps(d, a); }
  // The box kernel's orderings for rays with tmin >= +0 and no NaN (box_test_vectors): the
  // float forms here, integer ones in Lanes8; both give the kernel's same bits.
  static V near_of(V t0, V t1) { return _mm_min_ps(t1, t0); }
  static V far_of(V t0, V t1) { return _mm_max_ps(t0, t1); }
  static V entry_max(V a, V b) { return _mm_max_ps(a, b); }
#if defined(AMALGAM_ISA_AVX2)
  // The lower halves of the 8-wide forms, loaded as 4 floats: a cast of the 8-wide value
  // makes GCC load it whole, store its lower half to the stack and load that again.
  static V origin(const WideRay& r, int a) {
    return low(r.o8[a]);
  }
  static V inv(const WideRay& r, int a) {
    return low(r.inv8[a]);
  }
  static V shear(const WideRay& r, int a) {
    return low(r.shear8[a]);
  }
  static V sheared_origin(const WideRay& r, int a) {
    return low(r.ok8[a]);
  }
  static V low(const __m256& v) {
    return _mm_load_ps(reinterpret_cast<const float*>(&v));
  }
#else
  static V origin(const WideRay& r, int a) {
    return r.o4[a];
  }
  static V inv(const WideRay& r, int a) {
    return r.inv4[a];
  }
  static V shear(const WideRay& r, int a) {
    return r.shear4[a];
  }
  static V sheared_origin(const WideRay& r, int a) {
    return r.ok4[a];
  }
#endif
};
#if defined(AMALGAM_ISA_AVX2)
/// ... or 8 lanes (AVX) from one box block or two consecutive packs. Without FMA (the build does
/// not enable it), each lane performs exactly the SSE form's operations.
struct Lanes8 {
  using V = __m256;
  static constexpr int kLanes = 8;
  static V load(const TrianglePack4* p, int vertex, int axis) {
    return _mm256_set_m128(_mm_load_ps(p[1].v[vertex][axis]), _mm_load_ps(p[0].v[vertex][axis]));
  }
  static V load_aligned(const float* d) { return _mm256_load_ps(d); }
  static V load(const float* d) { return _mm256_loadu_ps(d); }
  static V set1(float x) { return _mm256_set1_ps(x); }
  static V zero() { return _mm256_setzero_ps(); }
  static V all() { return _mm256_castsi256_ps(_mm256_set1_epi32(-1)); }
  static V add(V a, V b) { return _mm256_add_ps(a, b); }
  static V sub(V a, V b) { return _mm256_sub_ps(a, b); }
  static V mul(V a, V b) { return _mm256_mul_ps(a, b); }
  static V div(V a, V b) { return _mm256_div_ps(a, b); }
  static V min(V a, V b) { return _mm256_min_ps(a, b); }
  static V max(V a, V b) { return _mm256_max_ps(a, b); }
  static V eq(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_EQ_OQ); }
  static V lt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
  static V gt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
  static V ge(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
  static V le(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
  static V nlt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NLT_US); }
  static V ngt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NGT_US); }
  static V bor(V a, V b) { return _mm256_or_ps(a, b); }
  static V band(V a, V b) { return _mm256_and_ps(a, b); }
  static V andnot(V a, V b) { return _mm256_andnot_ps(a, b); }
  static unsigned mask(V a) { return static_cast<unsigned>(_mm256_movemask_ps(a)); }
  static void store(float* d, V a) { _mm256_storeu_ps(d, a); }
  // The signed 32-bit integer minimum and maximum of float bits for the entry: one cycle of
  // latency where the float forms take four, on the chain from a node's boxes to its hit
  // mask. They order non-negative floats as floats do and put every negative float and -0
  // below them, which box_test_vectors shows is enough for the entry. (Not for the far
  // distances: there -0 must stay above the negative floats.)
  static V near_of(V t0, V t1) { return imin(t0, t1); }
  static V far_of(V t0, V t1) { return _mm256_max_ps(t0, t1); }
  static V entry_max(V a, V b) { return imax(a, b); }
  static V imin(V a, V b) {
    return _mm256_castsi256_ps(_mm256_min_epi32(_mm256_castps_si256(a), _mm256_castps_si256(b)));
  }
  static V imax(V a, V b) {
    return _mm256_castsi256_ps(_mm256_max_epi32(_mm256_castps_si256(a), _mm256_castps_si256(b)));
  }
  static V origin(const WideRay& r, int a) { return r.o8[a]; }
  static V inv(const WideRay& r, int a) { return r.inv8[a]; }
  static V shear(const WideRay& r, int a) { return r.shear8[a]; }
  static V sheared_origin(const WideRay& r, int a) { return r.ok8[a]; }
};
#endif
#endif

/// How the box kernel may treat a ray: kZeroAxes, any ray (a zero direction component makes
/// that axis a containment test, as in intersect_box); kNonZero, a ray for which
/// `box_rays_simple` holds, so that no slab distance can be NaN: the per-axis branch and the
/// infinite starting values of the interval are left out (the same floats without them).
enum class BoxRays { kZeroAxes, kNonZero };

/// Whether `r` may take the kNonZero kernels: a finite origin and a finite, nonzero inverse of
/// every direction component (so no zero component either), tmin +0 or positive and tmax not
/// NaN. Then (plane - o) * inv is never NaN for a box's planes, which are never NaN, infinite
/// ones (empty boxes) included, and the kernel may order its distances as integers.
[[gnu::always_inline]] inline bool box_rays_simple(const Ray& r) {
  for (int a = 0; a < 3; ++a) {
    const float inv = std::fabs(r.inv_dir[a]);
    if (!(std::fabs(r.origin[a]) < kInfinity) || !(inv < kInfinity) || !(inv > 0.0f)) return false;
  }
  return r.tmin >= 0.0f && !std::signbit(r.tmin) && !std::isnan(r.tmax);
}

#if AMALGAM_WIDE_SSE

/// Tests the first `n` (1..L::kLanes) boxes of the blocks at `b` against the ray over [tmin,
/// tmax], exactly as `intersect_box` would one at a time. Returns the lanes hit as a bit mask;
/// `t_entry[i]` is the entry parameter (Span::t0) of lane i where it is hit.
///
/// The enlargement of the far distance by 2 gamma(3) (the scalar test's `t1 *= ...` per axis)
/// is applied once to the minimum over the axes instead of to each axis: x -> x * (1 + 2
/// gamma(3)) rounded is non-decreasing and maps only zeros to zero, so the minimum of the
/// products and the product of the minimum are the same float (a NaN is skipped either way).
///
/// `box_test_vectors` is the same test on boxes already in registers (`lo[axis]`, `hi[axis]`:
/// the instanced walk's world boxes, computed per visit).
template <class L, BoxRays kRays>
[[gnu::always_inline]] inline unsigned box_test_vectors(const typename L::V lo[3],
                                                        const typename L::V hi[3], const WideRay& r,
                                                        float tmin, float tmax, int n,
                                                        float* t_entry) {
  using V = typename L::V;
  constexpr float kGrow = 1.0f + 2.0f * gamma(3);
  if constexpr (kRays == BoxRays::kNonZero) {
    // No NaN anywhere and tmin >= +0 (box_rays_simple): the scalar test's result as a short
    // dependency chain. Its entry max(t_near, tmin) (tmin on a tie) is the maximum of tmin
    // and the three near distances, taken in any order and, in Lanes8, as integers: a
    // maximum above tmin is a positive float, whose equal values have equal bits, and one
    // equal to tmin = +0 is +0 either way, while the negative distances and -0, which the
    // integer order puts below +0, never win; so an axis's near distance may be the integer
    // minimum of its pair too (it differs from the float one only where both are below +0).
    // The test entry <= min(t_far, tmax), with t_far the minimum over the axes of far * (1 +
    // 2 gamma(3)) (a rounded product is non-decreasing), is entry <= each of them, compared
    // one by one: no chain of minima.
    V tn[3], tf[3];
    for (int a = 0; a < 3; ++a) {
      const V o = L::origin(r, a), inv = L::inv(r, a);
      const V t0 = L::mul(L::sub(lo[a], o), inv);
      const V t1 = L::mul(L::sub(hi[a], o), inv);
      tn[a] = L::near_of(t0, t1), tf[a] = L::far_of(t0, t1);
    }
    const V s0 = L::entry_max(L::entry_max(tn[0], tn[1]), L::entry_max(tn[2], L::set1(tmin)));
    L::store(t_entry, s0);
    const V grow = L::set1(kGrow);
    const V in = L::band(L::band(L::le(s0, L::mul(tf[0], grow)), L::le(s0, L::mul(tf[1], grow))),
                         L::band(L::le(s0, L::mul(tf[2], grow)), L::le(s0, L::set1(tmax))));
    return L::mask(in) & ((1u << n) - 1u);
  }
  V t_near = L::set1(-kInfinity), t_far = L::set1(kInfinity);
  V ok = L::all();
  for (int a = 0; a < 3; ++a) {
    const V o = L::origin(r, a);
    if (kRays == BoxRays::kZeroAxes && r.zero[a]) {  // scalar: if (o < lo || o > hi) miss
      ok = L::band(ok, L::band(L::nlt(o, lo[a]), L::ngt(o, hi[a])));
      continue;
    }
    const V inv = L::inv(r, a);
    const V t0 = L::mul(L::sub(lo[a], o), inv);
    const V t1 = L::mul(L::sub(hi[a], o), inv);
    // scalar: if (t0 > t1) swap. minps(x, y) = x < y ? x : y; maxps(x, y) = x > y ? x : y.
    const V tn = L::min(t1, t0);
    const V tf = L::max(t0, t1);
    t_near = L::max(tn, t_near);  // if (t0 > t_near) t_near = t0
    t_far = L::min(tf, t_far);    // if (t1 < t_far) t_far = t1
  }
  t_far = L::mul(t_far, L::set1(kGrow));
  const V s0 = L::max(t_near, L::set1(tmin));  // t_near > tmin ? t_near : tmin
  const V s1 = L::min(L::set1(tmax), t_far);   // std::min(t_far, tmax)
  L::store(t_entry, s0);
  ok = L::band(ok, L::le(t_near, t_far));
  ok = L::band(ok, L::le(s0, s1));
  return L::mask(ok) & ((1u << n) - 1u);
}

/// `box_test_vectors` on lanes c0 .. c0 + L::kLanes - 1 of the rows `b` (c0: 0, or 4 for the
/// upper half of 8-lane rows in SSE), the first `n` of them. An 8-lane read of 4-lane rows
/// takes the next row's floats into its upper lanes: n <= 4 masks them off.
template <class L, BoxRays kRays>
[[gnu::always_inline]] inline unsigned box_test_lanes(BoxRows b, int c0, const WideRay& r,
                                                      float tmin, float tmax, int n,
                                                      float* t_entry) {
  using V = typename L::V;
  V lo[3], hi[3];
  for (int a = 0; a < 3; ++a)
    lo[a] = L::load(b.rows + a * b.stride + c0), hi[a] = L::load(b.rows + (3 + a) * b.stride + c0);
  return box_test_vectors<L, kRays>(lo, hi, r, tmin, tmax, n, t_entry);
}
#endif

/// Boxes c0 .. c0 + n - 1 of the rows `b` (n <= 4; c0 a multiple of 4) against the ray: the
/// 4-lane `box_test_lanes` (SSE; a scalar loop without SSE, where every mode is the scalar
/// test). `kZeroAxes` false: the caller knows that `box_rays_simple` holds for `r` (finite
/// origin and inverse direction), so the per-axis branch of a zero component and the
/// NaN-skipping start are left out. Lane i of the mask and of `t_entry` is box c0 + i.
template <bool kZeroAxes = true>
inline unsigned intersect_wide4(BoxRows b, int c0, const WideRay& r, float tmin, float tmax, int n,
                                float t_entry[kWideLanes]) {
#if AMALGAM_WIDE_SSE
  return box_test_lanes < Lanes4,
         kZeroAxes ? BoxRays::kZeroAxes : BoxRays::kNonZero > (b, c0, r, tmin, tmax, n, t_entry);
#else
  unsigned mask = 0;
  for (int i = 0; i < n; ++i) {
    Bbox box;
    for (int a = 0; a < 3; ++a)
      box.lo[a] = b.rows[a * b.stride + c0 + i], box.hi[a] = b.rows[(3 + a) * b.stride + c0 + i];
    Ray ray;
    ray.origin = {r.o[0], r.o[1], r.o[2]};
    ray.inv_dir = {r.inv[0], r.inv[1], r.inv[2]};
    for (int a = 0; a < 3; ++a) ray.dir[a] = r.zero[a] ? 0.0f : 1.0f / r.inv[a];
    ray.tmin = tmin, ray.tmax = tmax;
    float t0, t1;
    if (intersect_box(ray, box, t0, t1)) mask |= 1u << i, t_entry[i] = t0;
  }
  return mask;
#endif
}

/// The first `n` (<= the rows' stride) boxes of the rows `b`: one 8-lane kernel call in the
/// AVX2 copy, one or two 4-lane ones otherwise (a scalar loop without SSE, exact for any ray).
/// `t` holds 8 entries.
template <BoxRays kRays>
[[gnu::always_inline]] inline unsigned box_test_block(BoxRows b, const WideRay& wr, float tmin,
                                                      float tmax, int n, float* t) {
#if AMALGAM_WIDE_SSE && defined(AMALGAM_ISA_AVX2)
  return box_test_lanes<Lanes8, kRays>(b, 0, wr, tmin, tmax, n, t);
#else
  constexpr bool kZero = kRays == BoxRays::kZeroAxes;
  unsigned m = intersect_wide4<kZero>(b, 0, wr, tmin, tmax, std::min(n, kWideLanes), t);
  if (n > kWideLanes)
    m |= intersect_wide4<kZero>(b, kWideLanes, wr, tmin, tmax, n - kWideLanes, t + kWideLanes)
         << kWideLanes;
  return m;
#endif
}

/// A pack test's candidates by lane (valid where its hit mask is set); N = 4, or 8 for two
/// packs tested at once (AVX2).
template <int N>
struct alignas(32) TrianglePackHitsN {
  float t[N], u[N], v[N], w[N], det[N];
  TriangleCandidate lane(int i) const { return {t[i], u[i], v[i], w[i], det[i]}; }
};
using TrianglePackHits = TrianglePackHitsN<kWideLanes>;

#if AMALGAM_WIDE_SSE

/// `triangle_test` on the first `n` (1..L::kLanes) triangles of the packs at `p` at once, each
/// against the same [tmin, tmax]: the hit lanes as a bit mask, their t and barycentrics in
/// `out`, lane for lane bit-identical to the scalar test. It performs the scalar test's float
/// operations in the same order on the same operands (a product is commutative in IEEE
/// arithmetic, a sum of three is not: both sum left to right), with no fused multiply-add, and
/// takes the same double-precision path for a lane whose u, v or w is zero. The caller picks
/// the closest hit among the lanes (a lane's tmax does not shrink by an earlier lane's hit
/// here, unlike in a one-by-one loop).
template <class L>
[[gnu::always_inline]] inline unsigned triangle_test_lanes(const TrianglePack4* p, const WideRay& r,
                                                           float tmin, float tmax, int n,
                                                           TrianglePackHitsN<L::kLanes>& out) {
  using V = typename L::V;
  constexpr int N = L::kLanes;
  const TrianglePre& pre = r.pre;
  const unsigned lanes = (1u << n) - 1u;
  const int kx = pre.kx, ky = pre.ky, kz = pre.kz;
  const V sx = L::shear(r, 0), sy = L::shear(r, 1), sz = L::shear(r, 2);
  const V ox = L::sheared_origin(r, 0), oy = L::sheared_origin(r, 1);
  const V oz = L::sheared_origin(r, 2);
  // Sheared and translated vertices (scalar: A[kx] - sx * A[kz] with A = a - origin).
  V X[3], Y[3], Z[3];
  for (int k = 0; k < 3; ++k) {
    Z[k] = L::sub(L::load(p, k, kz), oz);
    X[k] = L::sub(L::sub(L::load(p, k, kx), ox), L::mul(sx, Z[k]));
    Y[k] = L::sub(L::sub(L::load(p, k, ky), oy), L::mul(sy, Z[k]));
  }
  V u = L::sub(L::mul(X[2], Y[1]), L::mul(Y[2], X[1]));  // cx by - cy bx
  V v = L::sub(L::mul(X[0], Y[2]), L::mul(Y[0], X[2]));  // ax cy - ay cx
  V w = L::sub(L::mul(X[1], Y[0]), L::mul(Y[1], X[0]));  // bx ay - by ax
  const V zero = L::zero();
  const unsigned edge =
      L::mask(L::bor(L::bor(L::eq(u, zero), L::eq(v, zero)), L::eq(w, zero))) & lanes;
  if (edge) [[unlikely]] {  // the scalar test's edge case, lane by lane in double precision
    alignas(32) float x[3][N], y[3][N], U[N], V_[N], W[N];
    for (int k = 0; k < 3; ++k) L::store(x[k], X[k]), L::store(y[k], Y[k]);
    L::store(U, u), L::store(V_, v), L::store(W, w);
    for (unsigned m = edge; m; m &= m - 1) {
      const int i = std::countr_zero(m);
      U[i] = static_cast<float>(double(x[2][i]) * y[1][i] - double(y[2][i]) * x[1][i]);
      V_[i] = static_cast<float>(double(x[0][i]) * y[2][i] - double(y[0][i]) * x[2][i]);
      W[i] = static_cast<float>(double(x[1][i]) * y[0][i] - double(y[1][i]) * x[0][i]);
    }
    u = L::load_aligned(U), v = L::load_aligned(V_), w = L::load_aligned(W);
  }
  // Reject mixed signs: (u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0).
  const V neg = L::bor(L::bor(L::lt(u, zero), L::lt(v, zero)), L::lt(w, zero));
  const V pos = L::bor(L::bor(L::gt(u, zero), L::gt(v, zero)), L::gt(w, zero));
  const V mixed = L::band(neg, pos);
  // Most packs stop here: every lane's ray passes outside its triangle.
  if ((L::mask(mixed) & lanes) == lanes) return 0;
  const V det = L::add(L::add(u, v), w);
  const V bad = L::bor(mixed, L::eq(det, zero));
  // t = (u az + v bz + w cz) / det with az = sz A[kz].
  const V zs[3] = {L::mul(sz, Z[0]), L::mul(sz, Z[1]), L::mul(sz, Z[2])};
  const V num = L::add(L::add(L::mul(u, zs[0]), L::mul(v, zs[1])), L::mul(w, zs[2]));
  const V t = L::div(num, det);
  // !(t >= tmin && t <= tmax) rejects: ordered compares, so a NaN t is rejected as well.
  const V in = L::band(L::ge(t, L::set1(tmin)), L::le(t, L::set1(tmax)));
  L::store(out.t, t), L::store(out.u, u), L::store(out.v, v);
  L::store(out.w, w), L::store(out.det, det);
  unsigned hits = L::mask(L::andnot(bad, in)) & lanes;
  if (!hits) return 0;
  // The scalar test's rejection of t within its rounding error (triangle_t_error). Its first
  // case for all lanes at once: a triangle wholly on the side of the origin that the ray
  // faces (the z of its vertices all of the sign of sz) has no error bound, 0, so only t <= 0
  // is rejected; the compares are those of the scalar code on the same operands.
  const V ahead = pre.sz > 0.0f
                      ? L::band(L::band(L::gt(Z[0], zero), L::gt(Z[1], zero)), L::gt(Z[2], zero))
                      : L::band(L::band(L::lt(Z[0], zero), L::lt(Z[1], zero)), L::lt(Z[2], zero));
  const unsigned near = L::mask(ahead) & hits;
  hits &= ~(L::mask(L::le(t, zero)) & near);
  if (const unsigned rest = hits & ~near) {
    // The other lanes one by one on the same operands.
    alignas(32) float x[3][N], y[3][N], z[3][N];
    for (int k = 0; k < 3; ++k) L::store(x[k], X[k]), L::store(y[k], Y[k]), L::store(z[k], Z[k]);
    for (unsigned m = rest; m; m &= m - 1) {
      const int i = std::countr_zero(m);
      if (out.t[i] <= triangle_t_error(x[0][i], y[0][i], x[1][i], y[1][i], x[2][i], y[2][i],
                                       z[0][i], z[1][i], z[2][i], pre.sz, out.u[i], out.v[i],
                                       out.w[i], out.det[i]))
        hits &= ~(1u << i);
    }
  }
  return hits;
}
#endif

/// `triangle_test` on the first `n` (1..4) triangles of `p` at once (SSE, `triangle_test_lanes`;
/// a scalar loop without SSE).
[[gnu::always_inline]] inline unsigned triangle_test4(const TrianglePack4& p, const WideRay& r,
                                                      float tmin, float tmax, int n,
                                                      TrianglePackHits& out) {
#if AMALGAM_WIDE_SSE
  return triangle_test_lanes<Lanes4>(&p, r, tmin, tmax, n, out);
#else
  const TrianglePre& pre = r.pre;
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
  return mask;
#endif
}

AMALGAM_ISA_END
}  // namespace amalgam

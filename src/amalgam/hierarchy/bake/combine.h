#pragma once
/// \file The two ways a bake makes an appearance: from what exact lines met (`finish_bake`)
/// and from the children's appearances (`bake_from_children`), and the orientation of flat
/// results (`orient`). Colour is the mean surface colour the lines see; the shading normal is
/// the dominant axis of the orientation tensor sum n n^T of the normals they see (sign-free,
/// so a flat patch seen from either side gets its own normal: the integrator turns it toward
/// the viewer); contents that are not predominantly flat (largest eigenvalue below
/// `kPlanarity` of the trace) leave the normal zero and are shaded as a cloud of randomly
/// oriented facets (`Shading::kCloud`); a flat node gets `Shading::kNormal`.

#include <cstdint>
#include <span>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "amalgam/geometry/intersect.h"
#include "amalgam/geometry/ray.h"
#include "amalgam/hierarchy/appearance.h"
#include "amalgam/hierarchy/bake/normals.h"
#include "amalgam/hierarchy/hierarchy.h"

namespace amalgam {

/// A child of a node being baked, as the parent sees it.
struct BakeChild {
  Bbox bounds;
  Appearance app;
  NormalTensor normals;  ///< normalised to trace 1 (or zero when nothing is hit)
};

/// The boxes of a node's children (at most kMaxChildren), four to a group in SoA form, for
/// `intersect_box` of a bake's line against four of them at once (most of
/// `bake_from_children`'s box tests). Lane by lane `entries` is geometry/intersect.h's scalar
/// test: the same float operations on the same operands and the same comparisons, NaN
/// included, written with SSE2 compares and selects, so the same hits and entry distances
/// (tests/hierarchy/build_parallel_test.cpp compares them bit for bit).
class ChildBoxes {
 public:
  explicit ChildBoxes(std::span<const BakeChild> kids);
  /// The children `ray` hits (bit k: child k) and, for those, their entries `t0[k]`
  /// (`intersect_box`'s t0). `t0` has room for the children rounded up to a multiple of 4.
  /// Inline: once per line of a bake (as a call, 6 % more of `bake_from_children`'s
  /// instructions).
  std::uint64_t entries(const Ray& ray, float* t0) const;

 private:
  struct alignas(16) Group {
    float lo[3][4], hi[3][4];
  };
#if defined(__SSE2__)
  static __m128 select(__m128 m, __m128 a, __m128 b) {
    return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b));
  }
#endif
  Group groups_[(kMaxChildren + 3) / 4];
  int count_ = 0;
};

#if defined(__SSE2__)
inline std::uint64_t ChildBoxes::entries(const Ray& ray, float* t0) const {
  std::uint64_t hits = 0;
  const __m128 grow = _mm_set1_ps(1.0f + 2.0f * gamma(3));
  for (int g = 0; g < (count_ + 3) / 4; ++g) {
    const Group& b = groups_[g];
    __m128 t_near = _mm_set1_ps(-kInfinity), t_far = _mm_set1_ps(kInfinity);
    __m128 ok = _mm_castsi128_ps(_mm_set1_epi32(-1));
    for (int a = 0; a < 3; ++a) {
      const __m128 o = _mm_set1_ps(ray.origin[a]);
      const __m128 lo = _mm_load_ps(b.lo[a]), hi = _mm_load_ps(b.hi[a]);
      if (ray.dir[a] == 0.0f) {  // a containment test on this axis
        ok = _mm_andnot_ps(_mm_or_ps(_mm_cmplt_ps(o, lo), _mm_cmpgt_ps(o, hi)), ok);
        continue;
      }
      const __m128 inv = _mm_set1_ps(ray.inv_dir[a]);
      const __m128 s0 = _mm_mul_ps(_mm_sub_ps(lo, o), inv);
      const __m128 s1 = _mm_mul_ps(_mm_sub_ps(hi, o), inv);
      const __m128 swap = _mm_cmpgt_ps(s0, s1);  // if (t0 > t1) swap
      const __m128 n0 = select(swap, s1, s0);
      const __m128 n1 = _mm_mul_ps(select(swap, s0, s1), grow);
      t_near = select(_mm_cmpgt_ps(n0, t_near), n0, t_near);
      t_far = select(_mm_cmplt_ps(n1, t_far), n1, t_far);
    }
    const __m128 tmin = _mm_set1_ps(ray.tmin), tmax = _mm_set1_ps(ray.tmax);
    const __m128 e0 = select(_mm_cmpgt_ps(t_near, tmin), t_near, tmin);
    const __m128 e1 = select(_mm_cmplt_ps(tmax, t_far), tmax, t_far);  // std::min(t_far, tmax)
    const __m128 hit =
        _mm_and_ps(_mm_and_ps(ok, _mm_cmple_ps(t_near, t_far)), _mm_cmple_ps(e0, e1));
    _mm_storeu_ps(t0 + 4 * g, e0);
    hits |= static_cast<std::uint64_t>(_mm_movemask_ps(hit)) << (4 * g);
  }
  return hits;
}
#else
inline std::uint64_t ChildBoxes::entries(const Ray& ray, float* t0) const {
  std::uint64_t hits = 0;
  for (int k = 0; k < count_; ++k) {
    const Group& b = groups_[k / 4];
    const Bbox box{{b.lo[0][k % 4], b.lo[1][k % 4], b.lo[2][k % 4]},
                   {b.hi[0][k % 4], b.hi[1][k % 4], b.hi[2][k % 4]}};
    float t1;
    if (intersect_box(ray, box, t0[k], t1)) hits |= std::uint64_t{1} << k;
  }
  return hits;
}
#endif

/// A baked appearance with its normal tensor (trace 1, or 0 when nothing is hit).
struct BakeResult {
  Appearance app;
  NormalTensor normals;
};

/// Turns a kNormal result into kOriented when the outward normals met while baking agree on a
/// side: `outward` is their (weighted) sum, `weight` the sum of weights; the normal is flipped
/// to point out when the mean outward normal's component along it is at least 1/2 in size.
void orient(BakeResult& r, Vec3 outward, float weight);

/// Bakes a node from its children's appearances: `rays` random lines through `box`, each
/// meeting the children it crosses front to back, child i stopping it with probability
/// a_i independently. Opacity = mean of 1 - prod (1 - a_i); colour and normals weighted by
/// the probability each child is the one seen.
BakeResult bake_from_children(const Bbox& box, std::span<const BakeChild> kids, int rays,
                              std::uint64_t key);

/// Finishes an exact bake: `hits` of `rays` lines hit; `colour`, `spec`, `shine` summed over
/// the hits; `normals` summed n n^T over the hits.
BakeResult finish_bake(int rays, int hits, Vec3 colour, float spec, float shine,
                       NormalTensor normals);

}  // namespace amalgam

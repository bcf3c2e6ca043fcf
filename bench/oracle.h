#pragma once
// The oracle bound of level of detail (issue 13, step 1): "ideal" amalgams. Wherever the
// scale-sensitive traversal (footprint K) would render an amalgam for a primary sample, the
// sample's radiance is instead estimated by brute force at full detail: `rays` rays of the
// traditional renderer (full-detail shading and shadow rays) spread uniformly over a disc of
// diameter K x the ray's pixel footprint at the point where the ray enters that amalgam, and
// averaged. Samples that meet no renderable amalgam before a full-detail surface are rendered
// at full detail. The result is the image an amalgam renderer would give if every amalgam
// returned exactly the mean of what it stands for over its footprint: the error floor of
// level of detail itself at K, separate from what a bake gets right or wrong.
//
// Definitions (the choices an oracle has to make, and why):
// - "Would render": the footprint LOD test says render, whatever the amalgam's opacity (an
//   ideal amalgam's coverage is in the brute-force average: rays that miss its contents see
//   what lies behind, filtered the same way).
// - The disc is centred on the primary ray at the entry distance t, perpendicular to it, and
//   the sub-rays start from the camera but only count from a cone width before that plane
//   (t_plane - width): geometry in front of the amalgam that the primary ray passed by is not
//   blurred into the sample, the amalgam's own box (diagonal below the width) is covered.
// - Sub-ray positions: a per-sample scrambled Sobol set mapped to the disc (uniform by area).
// - Primary visibility and shading are filtered; shadow rays stay at full detail (an ideal
//   amalgam on a shadow ray would average transmittance over the shadow beam, which this bound
//   leaves exact).
// - The disc's diameter: K x the pixel footprint at t (`box_disc` false: the width the LOD
//   test compares amalgams with, the brief's definition), or the diagonal of the amalgam's box
//   (`box_disc` true: never wider, since the test renders only boxes below K footprints; what
//   one value per amalgam, centred on the ray, would average over).
// Its time means nothing (a sample in an amalgam costs `rays` full-detail samples).

#include <atomic>
#include <cmath>
#include <numbers>

#include "amalgam/math/sobol.h"
#include "amalgam/render/integrator.h"

namespace amalgam {

/// Opacity policy for finding where an ideal amalgam is met: every amalgam the LOD policy
/// renders stops the ray.
struct StopAtEveryAmalgam {
  static constexpr bool kBlends = false;
  static constexpr bool kSaturates = false;
  AmalgamEffect effect(float, std::uint64_t, NodeId, bool) const { return AmalgamEffect::kStop; }
};

template <Hierarchy H>
class OracleIntegrator {
 public:
  using Find = Traversal<H, ScaleSensitiveLod, StopAtEveryAmalgam, SortedOrder, Counters>;
  using Full = Integrator<H, TraditionalLod, StochasticOpacity, SortedOrder, Counters>;

  /// `in_amalgam` counts the samples replaced by the brute-force estimate.
  OracleIntegrator(const H& h, const Environment& env, float footprint, int rays, bool box_disc,
                   Counters& counters, std::atomic<std::uint64_t>& in_amalgam)
      : h_(&h),
        box_disc_(box_disc),
        find_(h, ScaleSensitiveLod::by_footprint(footprint), counters),
        full_(h, env, TraditionalLod{}, counters),
        k_(footprint),
        rays_(rays),
        in_amalgam_(&in_amalgam) {}

  SampleResult li(const Ray& primary, std::uint64_t key) {
    const TraceHit hit = find_.intersect(primary, hash_combine(key, 0));
    if (hit.kind != TraceHit::Kind::kAmalgam) return full_.li(primary, key);
    in_amalgam_->fetch_add(1, std::memory_order_relaxed);
    const float t = hit.t;
    const float width = box_disc_ ? h_->bounds(hit.id).diagonal() : k_ * primary.footprint(t);
    const Vec3 d = primary.dir;
    const Vec3 a = std::fabs(d.x) > 0.5f ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
    const Vec3 u = normalize(cross(d, a)), v = cross(d, u);
    const Vec3 centre = primary.at(t);
    const std::uint64_t scramble = hash_combine(key, 0x0a4c1e);
    Vec3 sum{};
    for (int i = 0; i < rays_; ++i) {
      const auto [s1, s2] = scrambled_sobol_2d(static_cast<std::uint32_t>(i), scramble);
      const float r = 0.5f * width * std::sqrt(s1);
      const float phi = 2.0f * std::numbers::pi_v<float> * s2;
      const Vec3 p = centre + u * (r * std::cos(phi)) + v * (r * std::sin(phi));
      const Vec3 dir = normalize(p - primary.origin);
      const float t_plane = t / std::max(dot(dir, d), 1e-6f);
      Ray sub = Ray::make(primary.origin, dir, std::max(0.0f, t_plane - width), primary.tmax);
      sub.cone_width = primary.cone_width;
      sub.cone_spread = primary.cone_spread;
      sum += full_.li(sub, hash_combine(key, 0x5b0000ull + static_cast<std::uint64_t>(i))).colour;
    }
    return {sum / static_cast<float>(rays_), hit};
  }

 private:
  const H* h_;
  bool box_disc_;
  Find find_;
  Full full_;
  float k_;
  int rays_;
  std::atomic<std::uint64_t>* in_amalgam_;
};

}  // namespace amalgam

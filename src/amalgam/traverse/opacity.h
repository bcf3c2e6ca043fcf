#pragma once
/// \file Opacity models: the second question a traversal asks, once its level-of-detail policy
/// (lod.h) has decided to render an amalgam: "what does this translucent amalgam do to the
/// ray?". `a` is the amalgam's opacity for the ray's direction (hierarchy/appearance.h,
/// `directional_opacity`). The traversals (traverse.h and the reference, reference.h) apply
/// the answer in one place, `RayState::render_amalgam` (state.h).
///
/// The paper, section 3: stochastic opacity makes each translucent amalgam fully opaque or
/// fully transparent at random (so a ray never continues past one it stops at), deterministic
/// opacity blends (each rendered translucent amalgam is shaded and attenuates what lies behind
/// it, and casts its own shadow rays: the O(n^2l1) worst case). A third model, not the
/// paper's, combines them: stochastic for camera rays, deterministic for shadow rays.

#include <cstdint>

#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/math/random.h"

namespace amalgam {

/// What rendering an amalgam does to a ray.
enum class AmalgamEffect : std::uint8_t {
  kPass,   ///< transparent to this ray: its contents are ignored
  kStop,   ///< opaque: the ray hits the amalgam's box where it enters it
  kBlend,  ///< translucent: recorded for blending (primary) or attenuating (shadow), passed
};

/// Stochastic opacity: per (ray, amalgam), opaque with probability `a`, else transparent. The
/// decision is a hash of the ray's key and the amalgam's id, so it is the same for any thread
/// count and for the fast and reference traversals.
struct StochasticOpacity {
  /// Whether closest-hit rays collect translucent amalgams for blending.
  static constexpr bool kBlends = false;
  AmalgamEffect effect(float a, std::uint64_t ray_key, NodeId id, bool /*shadow*/) const {
    return to_unit_float(hash_combine(ray_key, id)) < a ? AmalgamEffect::kStop
                                                        : AmalgamEffect::kPass;
  }
};

/// Deterministic opacity: opaque only when `a` >= 1, passed when `a` <= 0, blended otherwise:
/// a closest-hit ray records the amalgam (the integrator blends front to back); a shadow ray is
/// attenuated by (1 - a).
struct DeterministicOpacity {
  static constexpr bool kBlends = true;
  AmalgamEffect effect(float a, std::uint64_t /*ray_key*/, NodeId /*id*/,
                       bool /*shadow*/) const {
    if (a >= 1.0f) return AmalgamEffect::kStop;
    if (a <= 0.0f) return AmalgamEffect::kPass;
    return AmalgamEffect::kBlend;
  }
};

/// Prefiltered shadows: stochastic opacity for closest-hit rays (so a camera ray shades one
/// thing and casts one shadow ray per light, as under StochasticOpacity) and deterministic
/// attenuation for shadow rays: a shadow ray crossing a rendered translucent amalgam is
/// attenuated by (1 - a) rather than stopped with probability a. The expected transmittance
/// is the same as under StochasticOpacity (independent decisions: the product of (1 - a_i)),
/// without the variance of the decisions: a soft shadow cast by sub-pixel geometry comes out
/// of one shadow ray instead of many. A shadow ray then goes on past translucent amalgams
/// rather than stopping at the first one that is opaque for it, so it costs more tests.
struct PrefilteredOpacity {
  static constexpr bool kBlends = false;
  AmalgamEffect effect(float a, std::uint64_t ray_key, NodeId id, bool shadow) const {
    if (shadow) return DeterministicOpacity{}.effect(a, ray_key, id, shadow);
    return StochasticOpacity{}.effect(a, ray_key, id, shadow);
  }
};

}  // namespace amalgam

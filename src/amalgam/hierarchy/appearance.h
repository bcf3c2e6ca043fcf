#pragma once
/// \file The appearance of an amalgam: what a rendered amalgam looks like (surface, opacity,
/// shading normal, shading model) and its opacity for a ray of a given direction.
///
/// Stored apart from the node data a traversal streams through (`ExplicitHierarchy::
/// appearances`, one per node), and read by the traversal only through `directional_opacity`
/// and by the integrator through the fields below: a richer appearance (a normal distribution,
/// directional coverage tables, lit fractions per light) is added here and in the bake
/// (hierarchy/bake/) without touching the traversal.

#include <cstdint>

#include "amalgam/geometry/bbox.h"
#include "amalgam/scene/scene.h"

namespace amalgam {

/// How a rendered amalgam is shaded (src/amalgam/render/integrator.h).
enum class Shading : std::uint8_t {
  /// The normal of the box face the ray enters, or `Appearance::normal` when it is set: the
  /// builtin scenes' exact box amalgams (and the default, so hand-made appearances keep it).
  kFace,
  /// `Appearance::normal`, turned toward the viewer: baked contents that are mostly flat.
  kNormal,
  /// A cloud of isotropically oriented Lambertian facets (the Lambert-sphere phase function):
  /// baked contents that are not predominantly flat, e.g. a whole mesh seen from far away.
  kCloud,
  /// As kNormal, with `Appearance::normal` pointing out of the closed surfaces the contents
  /// are part of: a ray meeting it from behind (dot(normal, dir) > 0) comes from inside, and
  /// a ray that has not stopped yet is outside every object, so it passes (opacity 0 for it;
  /// see directional_opacity below).
  kOriented,
};

/// The visual attributes of an amalgam: a surface, an opacity, optionally a shading normal
/// (zero means "use the normal of the box face the ray enters") and how to shade it.
struct Appearance {
  Surface surface;
  float opacity = 1.0f;  ///< probability that a ray crossing the amalgam hits its contents
  Vec3 normal{};
  Shading shading = Shading::kFace;
};

/// Opacity of a rendered amalgam for rays of direction `dir` (any length), i.e. the
/// probability that a line of that direction crossing `box` hits the contents.
/// `Appearance::opacity` is the mean of that probability over all lines crossing the box (the
/// isotropic line measure); by Cauchy's formula it is E[A_c(d)] / E[A_box(d)], A(d) the area
/// projected along d. The box's projected area is known exactly (E[A_box] = S(box) / 4), and
/// the contents' follows from how the bake classified them: a flat layer (`Shading::kNormal`,
/// normal n) projects A |n . d| (mean A / 2), a cloud of isotropically oriented facets
/// (`Shading::kCloud`) the same area in every direction. Hence
///   a(d) = a * F_c(d) / F_box(d),  F_box(d) = A_box(d) / (S / 4),  F_c = 2 |n . d| or 1,
/// clamped to [0, 1]. Its mean over isotropic lines crossing the box is `a` again.
/// A flat patch of a closed surface is nearly opaque to the rays that see it face on (the
/// rays that matter: the visible surface is seen along its normal) while the isotropic mean is
/// about 1/3; with the isotropic value those rays leak through the front of an object to
/// patches behind it (docs/real-scenes.md, "the far band"). A `Shading::kOriented` patch is
/// also transparent (0) to a ray meeting it from behind: an unstopped ray is outside every
/// closed surface, so a back face is never the first thing it meets. `Shading::kFace`
/// appearances (hand-made, the builtin scenes) keep `a` in every direction. Every traversal
/// (traverse/) calls this, through its opacity policy, with the ray's direction.
float directional_opacity(const Appearance& app, const Bbox& box, Vec3 dir);

}  // namespace amalgam

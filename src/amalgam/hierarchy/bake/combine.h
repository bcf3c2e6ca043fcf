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

#include "amalgam/hierarchy/appearance.h"
#include "amalgam/hierarchy/bake/normals.h"

namespace amalgam {

/// A child of a node being baked, as the parent sees it.
struct BakeChild {
  Bbox bounds;
  Appearance app;
  NormalTensor normals;  ///< normalised to trace 1 (or zero when nothing is hit)
};

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

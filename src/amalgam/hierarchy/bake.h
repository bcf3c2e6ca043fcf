#pragma once
/// \file Baking amalgam appearances by sampling random lines through a node.
///
/// Opacity is the probability that a random line crossing the node's box hits its contents.
/// "Random line crossing a box" is the isotropic (motion-invariant) line measure restricted to
/// the box: pick a face with probability proportional to its area, a uniform point on it and
/// a cosine-weighted direction into the box (Santalo, "Integral Geometry and Geometric
/// Probability", ch. 12). Colour is the mean surface colour those lines see. The shading
/// normal is the dominant axis of the orientation tensor sum n n^T of the normals they see:
/// sign-free, so a flat patch seen from either side gets its own normal (the integrator turns
/// it toward the viewer); when the contents are not predominantly flat (largest eigenvalue
/// below `kPlanarity` of the trace) the normal is left zero and the node is shaded as a cloud
/// of randomly oriented facets (`Shading::kCloud`); a flat node gets `Shading::kNormal`.

#include <cstdint>
#include <span>

#include "amalgam/geometry/intersect.h"
#include "amalgam/scene/scene.h"

namespace amalgam {

/// Settings of the bake.
struct BakeConfig {
  /// Sampled lines per node (stratified over the faces). 16 keeps the bake within about
  /// twice the build time (docs/real-scenes.md); 32-64 for smoother far-field images.
  int rays = 16;
  int exact_prims = 4;   ///< nodes with at most this many primitives below them are traced
                         ///< exactly against their subtree; larger ones combine children
  bool parallel = true;  ///< oneTBB over the nodes of one level
  std::uint64_t seed = 0x6a6b;
  /// Flat amalgams get an outward normal (Shading::kOriented) when the hierarchy's triangles
  /// form closed, consistently wound surfaces (closed_orientation); the check is skipped for
  /// more triangles than this (it sorts two 8-byte keys per edge).
  std::uint64_t orient_max_triangles = std::uint64_t{1} << 24;
};

/// Whether `prims`' triangles form closed, consistently wound surfaces: +1 when no directed
/// edge a->b (vertices compared bit for bit) occurs twice, at least 95 % of them are matched by
/// a b->a (closed up to small holes, as real meshes are) and the enclosed signed volume is
/// positive (wound counter-clockwise seen from outside), -1 for the same wound inward, 0
/// otherwise (open, inconsistent, no triangles). Degenerate triangles (two vertices the same)
/// and other primitive kinds are ignored (spheres and boxes are closed solids of their own).
/// One parallel sort of 8-byte keys, 3 per triangle: about 2 s for 10^7 triangles on 2 cores.
int closed_orientation(std::span<const Primitive> prims);

/// Symmetric 3x3 tensor sum w n n^T, stored xx, yy, zz, xy, yz, zx.
struct NormalTensor {
  float v[6]{};
  void add(Vec3 n, float w) {
    v[0] += w * n.x * n.x, v[1] += w * n.y * n.y, v[2] += w * n.z * n.z;
    v[3] += w * n.x * n.y, v[4] += w * n.y * n.z, v[5] += w * n.z * n.x;
  }
  void add(const NormalTensor& o, float w) {
    for (int i = 0; i < 6; ++i) v[i] += w * o.v[i];
  }
  void scale(float s) {
    for (float& x : v) x *= s;
  }
  float trace() const { return v[0] + v[1] + v[2]; }
  Vec3 apply(Vec3 x) const {
    return {v[0] * x.x + v[3] * x.y + v[5] * x.z, v[3] * x.x + v[1] * x.y + v[4] * x.z,
            v[5] * x.x + v[4] * x.y + v[2] * x.z};
  }
};

/// Largest eigenvalue / trace above which the contents count as flat.
inline constexpr float kPlanarity = 0.6f;

/// The dominant normal axis of `t` (unit length), or zero when `t` is not planar enough.
Vec3 dominant_normal(const NormalTensor& t);

/// M t M^T with the rows of M given as three vectors, then renormalised to the same trace
/// (the tensor of the normals transformed by M, M being a normal matrix).
NormalTensor transform_tensor(const NormalTensor& t, const Vec3 rows[3]);

/// A random line crossing `box` as a ray (unit direction) that starts outside it. `u` are
/// six uniform numbers in [0, 1); u[0] picks the face (stratify it), u[1] the side.
Ray sample_line(const Bbox& box, const float u[6]);

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
/// appearances (hand-made, the builtin scenes) keep `a` in every direction. The traversal's
/// `render` (traverse.h, reference.h) calls this with the ray's direction.
float directional_opacity(const Appearance& app, const Bbox& box, Vec3 dir);

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

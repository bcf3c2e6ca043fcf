#pragma once
/// \file The bake: every amalgam's appearance, computed bottom-up from what it contains, for
/// every stored hierarchy form (the builtin scenes compute theirs in closed form).
///
/// Opacity is the probability that a random line crossing the node's box (bake/lines.h) hits
/// its contents; colour is the mean surface colour those lines see; the shading normal and
/// model follow from the normals they see (bake/combine.h, bake/normals.h). Small nodes are
/// baked exactly, by tracing the lines against their subtree; larger ones combine their
/// children's appearances along the same kind of lines, so the bake costs
/// O(nodes * rays * arity) beyond the bottom. Nodes of one level are baked in parallel; the
/// result does not depend on the thread count.

#include <cstdint>

#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"

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
  /// false: the amalgams get no appearance (every one the default Appearance, no root normals):
  /// for renderers that never render a box amalgam (traditional, volumetric, Embree), which
  /// then pay only for the SIMD form.
  bool appearances = true;
};

/// Bakes every node of `h` bottom-up, one level at a time. A node with at most
/// `config.exact_prims` primitives below it is baked exactly: `config.rays` random lines
/// through its box are traced against its subtree; opacity = fraction that hit, colour = mean
/// colour of the surfaces hit (a textured triangle: its colour times its texture's mean over
/// the triangle's texture coordinates), normal = dominant axis of their normals. A larger node
/// combines its children (`bake_from_children`). Sets `h.appearances`, `h.root_normals` and
/// rebuilds the SIMD child boxes (`build_wide`).
void bake(ExplicitHierarchy& h, const BakeConfig& config = {});

/// Bakes the top level of an instanced hierarchy bottom-up from its instance roots, whose
/// appearances are their meshes' (baked already), seen through the instance transforms.
void bake(InstancedHierarchy& h, const BakeConfig& config = {});

}  // namespace amalgam

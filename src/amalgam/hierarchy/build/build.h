#pragma once
/// \file Builders of the stored hierarchy forms: a binned SAH tree (build/sah.h), collapsed to
/// wide nodes, then baked (bake/bake.h).

#include <vector>

#include "amalgam/hierarchy/bake/bake.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"

namespace amalgam {

/// Build settings for `build_explicit` and `build_instanced`.
struct BuildConfig {
  int arity = 4;      ///< children per interior node (2..kMaxChildren)
  int leaf_size = 4;  ///< at most this many primitives in a leaf (1..kMaxChildren)
  int bins = 16;      ///< SAH bins per axis
  bool parallel = true;
  BakeConfig bake;
};

/// Builds a hierarchy over `prims` with a binned SAH, collapsed to `arity`-wide nodes, in
/// parallel, then bakes every amalgam's appearance bottom-up (bake/bake.h). Empty input gives
/// a single empty leaf.
ExplicitHierarchy build_explicit(std::vector<Primitive> prims, std::vector<Surface> materials,
                                 const BuildConfig& config = {});

/// Builds the top level over `instances` (binned SAH, collapsed to `config.arity`), then
/// bakes its amalgams from the instance roots. `meshes` must be built and baked already (see
/// build_explicit); instances of empty meshes are dropped. Mesh indices must be in range and
/// there must be fewer than 2^32 - 1 instances (checked: InternalError).
InstancedHierarchy build_instanced(std::vector<ExplicitHierarchy> meshes,
                                   std::vector<Instance> instances, const BuildConfig& config = {});

}  // namespace amalgam

#pragma once
/// \file Builders of the stored hierarchy forms: a binned SAH tree (build/sah.h), collapsed to
/// wide nodes, then baked (bake/bake.h).

#include <cstdint>
#include <memory>
#include <vector>

#include "amalgam/hierarchy/bake/bake.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/hierarchy/instanced.h"

namespace amalgam {

/// Memory a built scene takes at its peak (reading, building and baking included), as measured
/// with this build's default settings (max resident set of `amalgam render` at 8x8 pixels,
/// docs/reliability.md "Resource limits"): for an explicit hierarchy about 215-250 bytes per
/// triangle (the triangles as read, the SAH's temporaries, nodes, appearances, SIMD child boxes
/// and triangle packs, the bake's tensors), about 305 for the meshes of an instanced one; per
/// instance (its transform data, the top-level tree and its bake) about 420 bytes. Small scenes
/// (under about 30 MiB) are overestimated, by up to 40 % (the allocator reuses the memory of
/// the process), which errs on the safe side.
struct MemoryModel {
  static constexpr std::uint64_t kProcess = 8u << 20;          ///< the process before any scene
  static constexpr std::uint64_t kSceneFile = 8u << 20;        ///< reading a scene file or mesh
  static constexpr std::uint64_t kPerTriangle = 250;           ///< explicit hierarchy, at its peak
  static constexpr std::uint64_t kPerInstancedTriangle = 305;  ///< a mesh placed by instances
  static constexpr std::uint64_t kPerInstance = 420;           ///< instanced hierarchy
  /// The film at its peak, per pixel: the progressive state (colour sum 12 bytes, tests 8,
  /// auxiliary sums 40: render.h's FilmState and PixelAov), either the pass's copy of it (60)
  /// while rendering or the outputs (image 12, cost 8, tests 8, depth 4, level 4, normal 12,
  /// albedo 12) after, plus a checkpoint being written (60, its bytes).
  static constexpr std::uint64_t kPerPixel = 180;
  /// Bytes a scene file of `triangles` triangles built explicitly (loose or expanded), plus
  /// `instances` placements of instanced meshes of `instanced_triangles` in all, takes.
  static constexpr std::uint64_t scene(std::uint64_t triangles, std::uint64_t instanced_triangles,
                                       std::uint64_t instances) {
    return kSceneFile + triangles * kPerTriangle + instanced_triangles * kPerInstancedTriangle +
           instances * kPerInstance;
  }
};

/// Build settings for `build_explicit` and `build_instanced`.
struct BuildConfig {
  int arity = 8;      ///< children per interior node (2..kMaxChildren)
  int leaf_size = 4;  ///< at most this many primitives in a leaf (1..kMaxChildren)
  int bins = 16;      ///< SAH bins per axis
  bool parallel = true;
  BakeConfig bake;
  double* bake_seconds = nullptr;  ///< when set, the bakes' wall time is added to it
};

/// Builds a hierarchy over `prims` with a binned SAH, collapsed to `arity`-wide nodes, in
/// parallel, then bakes every amalgam's appearance bottom-up (bake/bake.h). Empty input gives
/// a single empty leaf. `uvs`, when not empty, holds the texture coordinates of each of
/// `prims` (reordered with them); `textures` are those the materials index. `normals`, when not
/// empty, holds the vertex normals of each of `prims` (reordered with them).
ExplicitHierarchy build_explicit(std::vector<Primitive> prims, std::vector<Surface> materials,
                                 const BuildConfig& config = {}, std::vector<TexCoords> uvs = {},
                                 std::shared_ptr<const std::vector<Texture>> textures = {},
                                 std::vector<VertexNormals> normals = {});

/// Builds the top level over `instances` (binned SAH, collapsed to `config.arity`), then
/// bakes its amalgams from the instance roots. `meshes` must be built and baked already (see
/// build_explicit); instances of empty meshes are dropped. Mesh indices must be in range and
/// there must be fewer than 2^32 - 1 instances (checked: InternalError).
InstancedHierarchy build_instanced(std::vector<ExplicitHierarchy> meshes,
                                   std::vector<Instance> instances, const BuildConfig& config = {});

}  // namespace amalgam

#pragma once
/// \file The volumetric amalgams of a scene: one cell grid (cells.h) per instanced mesh,
/// shared by every instance of it, each instance's scale (cone widths are converted to
/// object units with it), and the world cells that absorb whole instances (world_cells.h).

#include <cstddef>
#include <vector>

#include "amalgam/hierarchy/instanced.h"
#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/hierarchy/volume/world_cells.h"

namespace amalgam {

struct VolumeSet {
  /// Per mesh of the instanced hierarchy; a grid without cells: the mesh is always traced at
  /// full detail (the scene's loose primitives, a ground box say).
  std::vector<CellGrid> grids;
  /// Per instance: cbrt(|det M|) of its transform, object units -> world units.
  std::vector<float> instance_scale;
  WorldCells world;            ///< empty when config.world is false
  double world_seconds = 0.0;  ///< the world cells' share of the bake
  VolumeConfig config;

  const CellGrid* grid(std::uint32_t mesh) const {
    return mesh < grids.size() && grids[mesh].cells() > 0 ? &grids[mesh] : nullptr;
  }
  std::size_t bytes() const {
    std::size_t b = instance_scale.size() * sizeof(float) + world.bytes();
    for (const CellGrid& g : grids) b += g.bytes();
    return b;
  }
  /// Cells of every object, world cells included.
  std::size_t cells() const {
    std::size_t n = world.cells();
    for (const CellGrid& g : grids) n += g.cells();
    return n;
  }
};

/// Bakes the cells of meshes [0, object_meshes) of `h` (the rest get none), in parallel over
/// their direction bins, then the world cells (config.world); the result does not depend on
/// the thread count.
VolumeSet bake_volumes(const InstancedHierarchy& h, std::size_t object_meshes,
                       const VolumeConfig& config = {});

}  // namespace amalgam

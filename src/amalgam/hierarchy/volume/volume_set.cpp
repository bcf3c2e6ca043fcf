#include "amalgam/hierarchy/volume/volume_set.h"

#include <chrono>
#include <cmath>

namespace amalgam {

VolumeSet bake_volumes(const InstancedHierarchy& h, std::size_t object_meshes,
                       const VolumeConfig& config) {
  VolumeSet v;
  v.config = config;
  v.grids.resize(h.meshes.size());
  for (std::size_t m = 0; m < h.meshes.size() && m < object_meshes; ++m)
    v.grids[m] = bake_cells(h.meshes[m], config);
  v.instance_scale.reserve(h.instances.size());
  for (const InstancedHierarchy::InstanceData& in : h.instances)
    v.instance_scale.push_back(
        static_cast<float>(std::cbrt(std::fabs(static_cast<double>(in.to_world.det())))));
  if (config.world) {
    const auto start = std::chrono::steady_clock::now();
    v.world = bake_world_cells(h, v.grids, v.instance_scale, config);
    v.world_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  v.config.budget = nullptr;  // the bake's account, not part of the result
  return v;
}

}  // namespace amalgam

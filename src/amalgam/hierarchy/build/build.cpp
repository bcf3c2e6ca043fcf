#include "amalgam/hierarchy/build/build.h"

#include <algorithm>
#include <chrono>

#include "amalgam/hierarchy/build/sah.h"
#include "amalgam/util/check.h"
#include "amalgam/util/parallel.h"

namespace amalgam {
namespace {

/// bake(), its wall time added to *seconds when given (the stats JSON's "bake").
template <class H>
void timed_bake(H& h, const BakeConfig& bc, double* seconds) {
  const auto t0 = std::chrono::steady_clock::now();
  bake(h, bc);
  if (seconds)
    *seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

SahConfig sah_config(const BuildConfig& config) {
  AMALGAM_CHECK(config.arity >= 2 && config.arity <= kMaxChildren,
                "BuildConfig::arity must be in [2, kMaxChildren]");
  AMALGAM_CHECK(config.leaf_size >= 1 && config.leaf_size <= kMaxChildren,
                "BuildConfig::leaf_size must be in [1, kMaxChildren]");
  SahConfig sc;
  sc.arity = config.arity;
  sc.leaf_size = config.leaf_size;
  sc.bins = config.bins;
  sc.parallel = config.parallel;
  return sc;
}

/// The nodes of a SAH tree as an explicit hierarchy stores them.
std::vector<ExplicitNode> explicit_nodes(const SahTree& t) {
  std::vector<ExplicitNode> nodes(t.nodes.size());
  for (std::size_t i = 0; i < t.nodes.size(); ++i) {
    AMALGAM_CHECK(t.nodes[i].count <= kMaxChildren,
                  "SAH node with more than kMaxChildren children");
    nodes[i] = {t.nodes[i].bounds, t.nodes[i].first, t.nodes[i].count, t.nodes[i].leaf};
  }
  return nodes;
}

}  // namespace

ExplicitHierarchy build_explicit(std::vector<Primitive> prims, std::vector<Surface> materials,
                                 const BuildConfig& config, std::vector<TexCoords> uvs,
                                 std::shared_ptr<const std::vector<Texture>> textures,
                                 std::vector<VertexNormals> normals) {
  AMALGAM_CHECK(uvs.empty() || uvs.size() == prims.size(),
                "build_explicit: texture coordinates for some primitives only");
  AMALGAM_CHECK(normals.empty() || normals.size() == prims.size(),
                "build_explicit: vertex normals for some primitives only");
  ExplicitHierarchy h;
  h.textures = std::move(textures);
  h.materials = std::move(materials);
  if (h.materials.empty()) h.materials.push_back(Surface{});
  std::vector<Bbox> boxes(prims.size());
  auto each = [&](std::size_t n, auto&& f) { for_each_index(n, f, 65537, 16384, config.parallel); };
  each(prims.size(), [&](std::size_t i) { boxes[i] = bounds(prims[i]); });
  SahTree t = build_sah(std::move(boxes), sah_config(config));
  std::vector<Primitive>& ordered = h.prims.edit();
  ordered.resize(prims.size());
  each(prims.size(), [&](std::size_t i) { ordered[i] = prims[t.order[i]]; });
  prims = {};
  if (!uvs.empty()) {
    h.uvs.resize(uvs.size());
    each(uvs.size(), [&](std::size_t i) { h.uvs[i] = uvs[t.order[i]]; });
  }
  if (!normals.empty()) {
    h.vertex_normals.resize(normals.size());
    each(normals.size(), [&](std::size_t i) { h.vertex_normals[i] = normals[t.order[i]]; });
  }
  h.nodes = explicit_nodes(t);
  h.levels = t.depth + 2;  // primitives one level below the deepest leaf
  BakeConfig bc = config.bake;
  bc.parallel = bc.parallel && config.parallel;
  timed_bake(h, bc, config.bake_seconds);
  return h;
}

InstancedHierarchy build_instanced(std::vector<ExplicitHierarchy> meshes,
                                   std::vector<Instance> instances, const BuildConfig& config) {
  InstancedHierarchy h;
  h.meshes = std::move(meshes);
  AMALGAM_CHECK(instances.size() < 0xffffffffull, "build_instanced: more than 2^32 - 2 instances");
  h.instances.reserve(instances.size());
  for (const Instance& inst : instances) {
    AMALGAM_CHECK_LT(inst.mesh, h.meshes.size(), "build_instanced: mesh index out of range");
    const ExplicitHierarchy& mesh = h.meshes[inst.mesh];
    if (mesh.prims.empty()) continue;
    h.instances.push_back(InstancedHierarchy::make_instance(inst, mesh));
  }

  // Top level: binned SAH over the instances' world boxes.
  std::vector<Bbox> boxes(h.instances.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) boxes[i] = h.instances[i].world_bounds;
  const SahTree t = build_sah(std::move(boxes), sah_config(config));
  h.top_items = t.order;
  h.top_nodes = explicit_nodes(t);
  h.levels = t.depth + 2;
  for (std::size_t i = 0; i < t.nodes.size(); ++i) {
    if (!t.nodes[i].leaf) continue;
    for (std::uint32_t k = 0; k < t.nodes[i].count; ++k) {
      const auto& in = h.instances[h.top_items[t.nodes[i].first + k]];
      h.levels = std::max(h.levels, t.level[i] + 1 + h.meshes[in.mesh].levels);
    }
  }

  BakeConfig bc = config.bake;
  bc.parallel = bc.parallel && config.parallel;
  timed_bake(h, bc, config.bake_seconds);
  build_wide(h);
  return h;
}

}  // namespace amalgam

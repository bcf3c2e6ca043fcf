#pragma once
/// \file The two-level instanced hierarchy: a top-level SAH tree over instances, each an
/// affine transform of a mesh that has its own explicit hierarchy (shared by all its
/// instances), so memory grows with the distinct meshes plus O(1) per instance.
///
/// Ids: the high 32 bits hold 0 for a top-level node, or instance index + 1; the low 32 bits
/// the node (or primitive) index within the top tree or the instance's mesh hierarchy.
/// Levels run on through the instance boundary: an instance's root sits one level below the
/// top-level leaf that holds it, so `Traversal` counts tests on the right levels unchanged.
///
/// Bounds of a node inside an instance are the world box of its transformed box. Primitive
/// tests transform the ray into object space without normalising the direction, so the hit
/// parameter t is the same in both spaces; each test is one intersection test, as for the
/// explicit form. Appearances inside an instance are the mesh's, with the opacity rescaled
/// from the transformed box to its world box (Cauchy: a line crossing the world box crosses
/// the transformed box with probability area ratio) and the normal transformed; top-level
/// amalgams are baked from the instance roots (`bake_from_children`).

#include <algorithm>
#include <cstdint>
#include <vector>

#include "amalgam/hierarchy/explicit.h"

namespace amalgam {

class InstancedHierarchy {
 public:
  /// Precomputed per instance. What the traversal reads at every node inside the instance
  /// (the transform, |M|, the mesh, the identity flag) comes first, in the first two of its
  /// four cache lines.
  struct alignas(64) InstanceData {
    Transform to_world;
    Vec3 abs_rows[3];  ///< rows of |M|, for world boxes
    std::uint32_t mesh = 0;
    bool identity = false;  ///< then rays and boxes are used untransformed (bit-exact)
    Transform to_object;
    Vec3 normal_rows[3];  ///< rows of M^-T: world normal = (rows . n), then normalised
    float face_area[3];   ///< |M e_y x M e_z|, |M e_z x M e_x|, |M e_x x M e_y|
    Bbox world_bounds;    ///< of the mesh root
  };

  std::vector<ExplicitNode> top_nodes;  ///< leaves' children: top_items[first .. +count)
  std::vector<Appearance> top_appearances;
  std::vector<std::uint32_t> top_items;  ///< instance indices
  std::vector<ExplicitHierarchy> meshes;
  std::vector<InstanceData> instances;
  int levels = 0;
  /// The top tree as the SIMD traversal reads it (hierarchy/wide.h), built by `build_wide`
  /// after the bake. Every top node has records: an interior node's hold its children's boxes
  /// and references; a top leaf's (reference marked kWideRefLeaf) hold the world boxes of its
  /// instances (`top_items[first .. +count)`) and their instance indices. Inside an instance
  /// the traversal reads the mesh's own `WideNodes` and transforms the boxes per visit.
  WideNodes top_wide;

  static constexpr std::uint64_t id(std::uint64_t instance_plus_one, std::uint32_t local) {
    return (instance_plus_one << 32) | local;
  }
  static constexpr std::uint32_t local(std::uint64_t id) {
    return static_cast<std::uint32_t>(id & 0xffffffffu);
  }
  static constexpr std::uint64_t slot(std::uint64_t id) { return id >> 32; }  ///< 0: top

  NodeId root() const { return 0; }
  Bbox bounds(NodeId n) const {
    const std::uint64_t s = slot(n);
    if (s == 0) return top_nodes[n].bounds;
    const InstanceData& in = instances[s - 1];
    return world_box(in, meshes[in.mesh].nodes[local(n)].bounds);
  }
  Appearance appearance(NodeId n) const;
  template <class F>
  void for_each_child(NodeId n, F&& f) const {
    const std::uint64_t s = slot(n);
    if (s == 0) {
      const ExplicitNode& t = top_nodes[n];
      for (std::uint32_t i = 0; i < t.count; ++i) {
        const std::uint64_t c = t.leaf ? id(top_items[t.first + i] + 1ull, 0) : t.first + i;
        if (!f(Child{c, false})) return;
      }
      return;
    }
    const ExplicitNode& e = meshes[instances[s - 1].mesh].nodes[local(n)];
    for (std::uint32_t i = 0; i < e.count; ++i)
      if (!f(Child{id(s, e.first + i), e.leaf})) return;
  }
  std::optional<SurfaceHit> intersect(PrimId p, const Ray& ray) const;
  Surface surface(PrimId p) const {
    const InstanceData& in = instances[slot(p) - 1];
    return meshes[in.mesh].surface(local(p));
  }
  Surface surface_at(PrimId p, const SurfaceHit& s) const {
    return meshes[instances[slot(p) - 1].mesh].surface_at(local(p), s);
  }
  /// As ExplicitHierarchy::shading_normal, in world space: the mesh's interpolated normal
  /// mapped by the instance's M^-T (world hit `s` carries the object-space barycentrics).
  Vec3 shading_normal(PrimId p, const SurfaceHit& s) const {
    const InstanceData& in = instances[slot(p) - 1];
    const ExplicitHierarchy& mesh = meshes[in.mesh];
    if (mesh.vertex_normals.empty()) return s.normal;
    const Vec3 n = interpolate(mesh.vertex_normals[local(p)], s.b1, s.b2);
    if (n == Vec3{}) return s.normal;
    if (in.identity) return n;
    const Vec3 w{dot(in.normal_rows[0], n), dot(in.normal_rows[1], n), dot(in.normal_rows[2], n)};
    return normalize(w);
  }
  HierarchyInfo info() const;
  /// The top tree's SIMD form when `build_wide` has built it (and with it every mesh's), else
  /// null: the traversal's generic source.
  const WideNodes* top_wide_nodes() const {
    return !top_nodes.empty() && top_wide.headers.size() == top_nodes.size() ? &top_wide : nullptr;
  }
  /// As ExplicitHierarchy::wide_stale for the top tree: its SIMD form missing (never built, or
  /// the top tree changed since) although `build_wide` did not leave it out by design (a mesh or
  /// the top tree with more records than references address).
  bool wide_stale() const {
    return !top_nodes.empty() && !top_wide_nodes() &&
           top_wide.unaddressable_nodes != top_nodes.size();
  }
  /// The primitive in world space (for flatten() and tests).
  Primitive primitive(PrimId p) const;

  /// The precomputed data of placement `inst` of `mesh` (built and baked).
  static InstanceData make_instance(const Instance& inst, const ExplicitHierarchy& mesh);

  /// The world box of the transformed box `b` of instance `in` (conservative by a few ulps).
  static Bbox world_box(const InstanceData& in, const Bbox& b);

  /// A world ray origin `o` in the object space of instance `in`: M^-1 (o - t) evaluated as
  /// to_object's matrix times (o - t), not as to_object.point(o) = M^-1 o - M^-1 t. For an
  /// origin near the instance (a shadow ray leaving it) o - t is exact or nearly, and the result
  /// is off by the rounding of the distance from the instance, not from the world origin (there
  /// 1e-5 m 100 m out, as much as a subdivided Wuson's triangles are from a ray's silhouette).
  static Vec3 object_origin(const InstanceData& in, Vec3 o);

  /// World ray `r` in the object space of instance `in` (not an identity), the direction left
  /// unnormalised so that t means the same in both spaces; what every primitive test inside
  /// the instance uses.
  static Ray object_ray(const InstanceData& in, const Ray& r) {
    return Ray::make(object_origin(in, r.origin), in.to_object.vector(r.dir), r.tmin, r.tmax);
  }

  /// The world hit of instance `in` (not an identity) from its object-space hit `h` of a ray
  /// with world direction `dir`: normal, point and error bound transformed.
  static SurfaceHit world_hit(const InstanceData& in, const SurfaceHit& h, Vec3 dir);

  /// What `intersect` adds to the error bound `err` of a world hit point `p` of instance `in`:
  /// the error of taking the origin of a ray that leaves p (offset_ray_origin) back into object
  /// space in float, in world units, so that the offset keeps that origin in front of the
  /// surface in object space too (a shadow ray otherwise meets its own triangle again).
  static Vec3 retransform_error(const InstanceData& in, Vec3 p, Vec3 err);
};

}  // namespace amalgam

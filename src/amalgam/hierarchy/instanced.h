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
  /// Precomputed per instance.
  struct InstanceData {
    Transform to_world, to_object;
    Vec3 normal_rows[3];  ///< rows of M^-T: world normal = (rows . n), then normalised
    Vec3 abs_rows[3];     ///< rows of |M|, for world boxes
    float face_area[3];   ///< |M e_y x M e_z|, |M e_z x M e_x|, |M e_x x M e_y|
    Bbox world_bounds;    ///< of the mesh root
    std::uint32_t mesh = 0;
    bool identity = false;  ///< then rays and boxes are used untransformed (bit-exact)
  };

  std::vector<ExplicitNode> top_nodes;  ///< leaves' children: top_items[first .. +count)
  std::vector<Appearance> top_appearances;
  std::vector<std::uint32_t> top_items;  ///< instance indices
  std::vector<ExplicitHierarchy> meshes;
  std::vector<InstanceData> instances;
  int levels = 0;

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
  HierarchyInfo info() const;
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

  /// What `intersect` adds to the error bound `err` of a world hit point `p` of instance `in`:
  /// the error of taking the origin of a ray that leaves p (offset_ray_origin) back into object
  /// space in float, in world units, so that the offset keeps that origin in front of the
  /// surface in object space too (a shadow ray otherwise meets its own triangle again).
  static Vec3 retransform_error(const InstanceData& in, Vec3 p, Vec3 err);

  /// The children of node `n` for the traversal's SIMD test (hierarchy/wide.h): top-level
  /// nodes' and instance roots' world boxes as stored; inside an instance, the world box of
  /// each child's transformed box, computed four at a time with the float operations of
  /// `world_box` in the same order (bit-identical to it); for a leaf inside an instance, its
  /// primitives' ids.
  void gather_children(NodeId n, GatheredChildren& out) const {
    const std::uint64_t s = slot(n);
    if (s == 0) {
      const ExplicitNode& t = top_nodes[n];
      out.count = static_cast<int>(t.count);
      out.primitives = false;
      for (int i = 0; i < out.count; ++i) {
        if (t.leaf) {
          const std::uint32_t inst = top_items[t.first + static_cast<std::uint32_t>(i)];
          out.ids[i] = id(inst + 1ull, 0);
          out.put_box(i, instances[inst].world_bounds);
        } else {
          out.ids[i] = t.first + static_cast<std::uint32_t>(i);
          out.put_box(i, top_nodes[t.first + static_cast<std::uint32_t>(i)].bounds);
        }
      }
      return;
    }
    const InstanceData& in = instances[s - 1];
    const ExplicitHierarchy& mesh = meshes[in.mesh];
    const ExplicitNode& e = mesh.nodes[local(n)];
    out.count = static_cast<int>(e.count);
    out.primitives = e.leaf;
    for (int i = 0; i < out.count; ++i) out.ids[i] = id(s, e.first + static_cast<std::uint32_t>(i));
    if (e.leaf) return;
    for (int i = 0; i < out.count; ++i)
      out.put_box(i, mesh.nodes[e.first + static_cast<std::uint32_t>(i)].bounds);
    if (!in.identity) {
      for (int c0 = 0; c0 < out.count; c0 += kWideLanes)
        world_boxes4(in, out.boxes[c0 / kWideLanes], std::min(out.count - c0, kWideLanes));
    }
  }

 private:
  /// Replaces the first `n` object-space boxes of `w` by world_box of each (empty boxes stay
  /// as they are, as there).
  static void world_boxes4(const InstanceData& in, WideBox4& w, int n) {
#if AMALGAM_WIDE_SSE
    bool any_empty = false;
    for (int l = 0; l < n; ++l)
      any_empty |= w.lo[0][l] > w.hi[0][l] || w.lo[1][l] > w.hi[1][l] || w.lo[2][l] > w.hi[2][l];
    if (!any_empty) {
      const __m128 half = _mm_set1_ps(0.5f);
      const __m128 sign = _mm_set1_ps(-0.0f);
      const __m128 k = _mm_set1_ps(4.0f * gamma(3));
      __m128 c[3], h[3];
      for (int a = 0; a < 3; ++a) {
        const __m128 lo = _mm_load_ps(w.lo[a]), hi = _mm_load_ps(w.hi[a]);
        c[a] = _mm_mul_ps(_mm_add_ps(lo, hi), half);  // Bbox::center
        h[a] = _mm_mul_ps(_mm_sub_ps(hi, lo), half);  // Bbox::extent() * 0.5f
      }
      for (int r = 0; r < 3; ++r) {
        const float* m = in.to_world.m[r];
        // Transform::point: ((m0 x + m1 y) + m2 z) + m3.
        __m128 cw = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(m[0]), c[0]),
                                                     _mm_mul_ps(_mm_set1_ps(m[1]), c[1])),
                                          _mm_mul_ps(_mm_set1_ps(m[2]), c[2])),
                               _mm_set1_ps(m[3]));
        // dot(abs_rows[r], h): (x + y) + z.
        const Vec3 ar = in.abs_rows[r];
        __m128 rw = _mm_add_ps(
            _mm_add_ps(_mm_mul_ps(_mm_set1_ps(ar.x), h[0]), _mm_mul_ps(_mm_set1_ps(ar.y), h[1])),
            _mm_mul_ps(_mm_set1_ps(ar.z), h[2]));
        // r += (|c| + r) * 4 gamma(3)
        rw = _mm_add_ps(rw, _mm_mul_ps(_mm_add_ps(_mm_andnot_ps(sign, cw), rw), k));
        _mm_store_ps(w.lo[r], _mm_sub_ps(cw, rw));
        _mm_store_ps(w.hi[r], _mm_add_ps(cw, rw));
      }
      return;
    }
#endif
    for (int l = 0; l < n; ++l) {
      const Bbox b = world_box(
          in, Bbox{{w.lo[0][l], w.lo[1][l], w.lo[2][l]}, {w.hi[0][l], w.hi[1][l], w.hi[2][l]}});
      w.lo[0][l] = b.lo.x, w.lo[1][l] = b.lo.y, w.lo[2][l] = b.lo.z;
      w.hi[0][l] = b.hi.x, w.hi[1][l] = b.hi.y, w.hi[2][l] = b.hi.z;
    }
  }
};

}  // namespace amalgam

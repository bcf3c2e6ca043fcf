#include "amalgam/hierarchy/instanced.h"

#include <algorithm>
#include <cmath>

namespace amalgam {

namespace {

float box_area_ratio(const InstancedHierarchy::InstanceData& in, const Bbox& object,
                     const Bbox& world) {
  const Vec3 e = object.extent();
  const float transformed = 2.0f * (in.face_area[0] * e.y * e.z + in.face_area[1] * e.z * e.x +
                                    in.face_area[2] * e.x * e.y);
  const float outer = surface_area(world);
  if (!(outer > 0.0f)) return 1.0f;
  return std::clamp(transformed / outer, 0.0f, 1.0f);
}

}  // namespace

Bbox InstancedHierarchy::world_box(const InstanceData& in, const Bbox& b) {
  if (in.identity || b.empty()) return b;
  const Vec3 c = in.to_world.point(b.center());
  const Vec3 h = b.extent() * 0.5f;
  Vec3 r{dot(in.abs_rows[0], h), dot(in.abs_rows[1], h), dot(in.abs_rows[2], h)};
  r += (abs(c) + r) * (4.0f * gamma(3));  // rounding of the transform, conservatively
  return {c - r, c + r};
}

InstancedHierarchy::InstanceData InstancedHierarchy::make_instance(const Instance& inst,
                                                                   const ExplicitHierarchy& mesh) {
  InstanceData d;
  d.to_world = inst.to_world;
  d.to_object = inst.to_world.inverse();
  d.mesh = inst.mesh;
  d.identity = inst.to_world.is_identity();
  const auto& m = inst.to_world.m;
  const auto& q = d.to_object.m;
  for (int i = 0; i < 3; ++i) {
    d.normal_rows[i] = {q[0][i], q[1][i], q[2][i]};  // (M^-1)^T
    d.abs_rows[i] = {std::fabs(m[i][0]), std::fabs(m[i][1]), std::fabs(m[i][2])};
  }
  const Vec3 col[3] = {
      {m[0][0], m[1][0], m[2][0]}, {m[0][1], m[1][1], m[2][1]}, {m[0][2], m[1][2], m[2][2]}};
  d.face_area[0] = length(cross(col[1], col[2]));
  d.face_area[1] = length(cross(col[2], col[0]));
  d.face_area[2] = length(cross(col[0], col[1]));
  d.world_bounds = world_box(d, mesh.nodes[0].bounds);
  return d;
}

Appearance InstancedHierarchy::appearance(NodeId n) const {
  const std::uint64_t s = slot(n);
  if (s == 0) return top_appearances[n];
  const InstanceData& in = instances[s - 1];
  const ExplicitHierarchy& mesh = meshes[in.mesh];
  Appearance a = mesh.appearances[local(n)];
  if (in.identity) return a;
  const Bbox& b = mesh.nodes[local(n)].bounds;
  a.opacity *= box_area_ratio(in, b, world_box(in, b));
  if (a.normal != Vec3{}) {
    const Vec3 w{dot(in.normal_rows[0], a.normal), dot(in.normal_rows[1], a.normal),
                 dot(in.normal_rows[2], a.normal)};
    const float len = length(w);
    a.normal = len > 0.0f ? w / len : Vec3{};
  }
  return a;
}

Vec3 InstancedHierarchy::object_origin(const InstanceData& in, Vec3 o) {
  const Vec3 rel{o.x - in.to_world.m[0][3], o.y - in.to_world.m[1][3], o.z - in.to_world.m[2][3]};
  return in.to_object.vector(rel);
}

std::optional<SurfaceHit> InstancedHierarchy::intersect(PrimId p, const Ray& ray) const {
  const InstanceData& in = instances[slot(p) - 1];
  const ExplicitHierarchy& mesh = meshes[in.mesh];
  if (in.identity) return mesh.intersect(local(p), ray);
  auto hit = mesh.intersect(local(p), object_ray(in, ray));
  if (!hit) return hit;
  return world_hit(in, *hit, ray.dir);
}

SurfaceHit InstancedHierarchy::world_hit(const InstanceData& in, const SurfaceHit& h, Vec3 dir) {
  SurfaceHit w;
  w.t = h.t;
  Vec3 n{dot(in.normal_rows[0], h.normal), dot(in.normal_rows[1], h.normal),
         dot(in.normal_rows[2], h.normal)};
  n = normalize(n);
  if (dot(n, dir) > 0.0f) n = -n;
  w.normal = n;
  w.p = in.to_world.point(h.p);
  // Error of the transformed point (pbrt 3, section 3.9.4): the transformed error bound plus
  // the rounding of the transform itself.
  const Vec3 ap = abs(h.p);
  Vec3 err;
  for (int i = 0; i < 3; ++i) {
    err[i] = (gamma(3) + 1.0f) * dot(in.abs_rows[i], h.p_error) +
             gamma(3) * (dot(in.abs_rows[i], ap) + std::fabs(in.to_world.m[i][3]));
  }
  w.p_error = err + retransform_error(in, w.p, err);
  w.b1 = h.b1, w.b2 = h.b2;  // an affine map keeps barycentrics
  return w;
}

Vec3 InstancedHierarchy::retransform_error(const InstanceData& in, Vec3 p, Vec3 err) {
  // A ray leaving p starts at o = offset_ray_origin(p, err', n) (err' the returned bound) and
  // is taken to object space as Q (o - t) (object_origin; Q = to_object's matrix, t the
  // translation): off from the exact M^-1 (o - t) by up to gamma(5) |Q| |o - t| per component
  // (1 rounding of o - t, 3 of the dot product, 1 of Q's entries, rounded from the exact inverse
  // computed in double, whose own error of about cond(M) 1e-16 is negligible), gamma(8) with
  // the rounding of this bound's own float evaluation; |M| times that in world space. The
  // offset moves o from p by at most D = the sum of err' (offset_ray_origin: |n| d <= sum err'),
  // plus the rounding of p + n d and the nextafter step (< 4 ulp(p) / 2): |o - t| <= |p - t| +
  // gamma(4) |p| + D. With e(x) = gamma(8) |M| |Q| x: err' = err + e(|p - t| + gamma(4) |p|) +
  // k D, k = e(1, 1, 1), and D = sum err', solved for D.
  Vec3 qa, qs;  // |Q| a with a = |p - t| + gamma(4) |p|, and |Q| 1
  Vec3 a;
  for (int j = 0; j < 3; ++j)
    a[j] = std::fabs(p[j] - in.to_world.m[j][3]) + gamma(4) * std::fabs(p[j]);
  for (int j = 0; j < 3; ++j) {
    const Vec3 row = abs(Vec3{in.to_object.m[j][0], in.to_object.m[j][1], in.to_object.m[j][2]});
    qa[j] = dot(row, a);
    qs[j] = row.x + row.y + row.z;
  }
  Vec3 e, k;
  for (int i = 0; i < 3; ++i) {
    e[i] = gamma(8) * dot(in.abs_rows[i], qa);
    k[i] = gamma(8) * dot(in.abs_rows[i], qs);
  }
  // D, rounded up by (1 + gamma(4)) for its own float evaluation. k is about 70 cond(M) 2^-24:
  // below 1/2 unless M is within a few parts in a million of singular, where a float transform
  // keeps no digits anyway (then D is taken as twice its first term: no longer a bound).
  const float ksum = k.x + k.y + k.z;
  const float grow = ksum < 0.5f ? 1.0f / (1.0f - ksum) : 2.0f;
  const float d = (err.x + err.y + err.z + e.x + e.y + e.z) * grow * (1.0f + gamma(4));
  return e + k * d;
}

Primitive InstancedHierarchy::primitive(PrimId p) const {
  const InstanceData& in = instances[slot(p) - 1];
  Primitive q = meshes[in.mesh].prims[local(p)];
  if (in.identity) return q;
  if (q.kind == PrimKind::kTriangle) {
    q.a = in.to_world.point(q.a), q.b = in.to_world.point(q.b), q.c = in.to_world.point(q.c);
  } else {
    // Spheres and boxes are only exact under translation; used for tests and small scenes.
    q.a = in.to_world.point(q.a);
    if (q.kind == PrimKind::kBox) q.b = in.to_world.point(q.b);
  }
  return q;
}

HierarchyInfo InstancedHierarchy::info() const {
  HierarchyInfo i;
  i.nodes = static_cast<double>(top_nodes.size());
  for (const InstanceData& in : instances) {
    i.primitives += static_cast<double>(meshes[in.mesh].prims.size());
    i.nodes += static_cast<double>(meshes[in.mesh].nodes.size());
  }
  i.levels = levels;
  return i;
}

}  // namespace amalgam

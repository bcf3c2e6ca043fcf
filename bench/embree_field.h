#pragma once
// Intel Embree 3 as the ray tracer of amalgam's Integrator, for the benchmarks that compare
// whole renders (field_bench.cpp, quality_bench.cpp). Embree is a comparison peer only: it is
// linked into these benchmarks, never into the amalgam libraries or binary.
//
// `EmbreeField`: one Embree scene per mesh (its triangles; box primitives as 12 triangles),
// one RTC_GEOMETRY_TYPE_INSTANCE per instance with the same 3x4 transform. `EmbreeTracer`:
// rtcIntersect1 for closest hits (the hit's surface is then taken from amalgam's own test of
// that one triangle, so shading sees the same normal and error bounds) and rtcOccluded1 for
// shadow rays. `embree_render` runs render()'s pass loop (render/passes.h) with it: same pixel
// sampling, same random streams, same shading as amalgam's traditional renderer.

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "amalgam/render/integrator.h"
#include "amalgam/render/passes.h"
#include "amalgam/render/render.h"

namespace amalgam {

namespace embree_detail {
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
inline void embree_error(void*, RTCError code, const char* str) {
  std::fprintf(stderr, "embree error %d: %s\n", static_cast<int>(code), str);
  std::exit(1);
}

}  // namespace embree_detail

/// The instanced hierarchy's geometry in Embree: one scene per mesh, one instance geometry
/// per instance (geometry ID = instance index).
class EmbreeField {
 public:
  /// `quality`: the build quality of every Embree scene; `scene_flags` those of the top scene.
  /// Embree's own defaults are RTC_BUILD_QUALITY_MEDIUM and RTC_SCENE_FLAG_NONE.
  explicit EmbreeField(const InstancedHierarchy& h,
                       RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM,
                       RTCSceneFlags scene_flags = RTC_SCENE_FLAG_NONE)
      : quality_(quality) {
    const auto t0 = std::chrono::steady_clock::now();
    device_ = rtcNewDevice(nullptr);
    rtcSetDeviceErrorFunction(device_, embree_detail::embree_error, nullptr);
    for (const ExplicitHierarchy& mesh : h.meshes) add_mesh(mesh);
    top_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(top_, quality_);
    rtcSetSceneFlags(top_, scene_flags);
    for (std::size_t i = 0; i < h.instances.size(); ++i) {
      const InstancedHierarchy::InstanceData& in = h.instances[i];
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(g, meshes_[in.mesh]);
      rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &in.to_world.m[0][0]);
      rtcCommitGeometry(g);
      rtcAttachGeometryByID(top_, g, static_cast<unsigned>(i));
      rtcReleaseGeometry(g);
    }
    rtcCommitScene(top_);
    build_seconds = embree_detail::seconds_since(t0);
  }
  ~EmbreeField() {
    rtcReleaseScene(top_);
    for (RTCScene s : meshes_) rtcReleaseScene(s);
    rtcReleaseDevice(device_);
  }
  EmbreeField(const EmbreeField&) = delete;
  EmbreeField& operator=(const EmbreeField&) = delete;

  RTCScene scene() const { return top_; }
  /// The mesh primitive an Embree triangle of mesh `m` came from.
  std::uint32_t prim(std::uint32_t m, std::uint32_t tri) const { return prim_of_tri_[m][tri]; }

  double build_seconds = 0.0;

 private:
  void add_mesh(const ExplicitHierarchy& mesh) {
    std::vector<float> v;
    std::vector<std::uint32_t> idx, owner;
    auto tri = [&](Vec3 a, Vec3 b, Vec3 c, std::uint32_t p) {
      for (Vec3 q : {a, b, c}) {
        idx.push_back(static_cast<std::uint32_t>(v.size() / 3));
        v.insert(v.end(), {q.x, q.y, q.z});
      }
      owner.push_back(p);
    };
    for (std::uint32_t p = 0; p < mesh.prims.size(); ++p) {
      const Primitive& q = mesh.prims[p];
      if (q.kind == PrimKind::kTriangle) {
        tri(q.a, q.b, q.c, p);
      } else if (q.kind == PrimKind::kBox) {
        const Vec3 lo = q.a, hi = q.b;
        auto corner = [&](int i) {
          return Vec3{i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
        };
        // Two triangles per face: corners differing in one bit from a face's base corner.
        static constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                             {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
        for (const auto& f : kFaces) {
          tri(corner(f[0]), corner(f[1]), corner(f[2]), p);
          tri(corner(f[0]), corner(f[2]), corner(f[3]), p);
        }
      } else {
        std::fprintf(stderr, "embree_field.h: spheres are not supported in the Embree scene\n");
        std::exit(1);
      }
    }
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), v.size() / 3));
    std::copy(v.begin(), v.end(), vb);
    auto* ib = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), idx.size() / 3));
    std::copy(idx.begin(), idx.end(), ib);
    rtcCommitGeometry(g);
    RTCScene s = rtcNewScene(device_);
    rtcSetSceneBuildQuality(s, quality_);
    rtcAttachGeometry(s, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(s);
    meshes_.push_back(s);
    prim_of_tri_.push_back(std::move(owner));
  }

  RTCBuildQuality quality_;
  RTCDevice device_ = nullptr;
  RTCScene top_ = nullptr;
  std::vector<RTCScene> meshes_;
  std::vector<std::vector<std::uint32_t>> prim_of_tri_;
};

/// The Integrator's tracer over Embree (full detail: every primitive opaque, no amalgams).
class EmbreeTracer {
 public:
  EmbreeTracer(const InstancedHierarchy& h, const EmbreeField& f) : h_(&h), f_(&f) {}

  TraceHit intersect(const Ray& ray, std::uint64_t, std::vector<TranslucentHit>*) {
    RTCRayHit rh{};
    fill(rh.ray, ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcIntersect1(f_->scene(), &ctx, &rh);
    TraceHit hit;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
    const std::uint32_t inst = rh.hit.instID[0];
    const std::uint32_t local = f_->prim(h_->instances[inst].mesh, rh.hit.primID);
    hit.kind = TraceHit::Kind::kPrimitive;
    hit.id = InstancedHierarchy::id(inst + 1ull, local);
    hit.t = rh.ray.tfar;
    // amalgam's own test of the one primitive Embree found gives the surface (normal, point
    // and its error bound) exactly as the traditional renderer would see it.
    Ray again = ray;
    again.tmax = std::min(ray.tmax, rh.ray.tfar * (1.0f + 8.0f * gamma(3)));
    if (auto s = h_->intersect(hit.id, again)) {
      hit.surf = *s;
      hit.t = s->t;
      return hit;
    }
    // Embree's and amalgam's watertight tests disagree on an edge: Embree's hit as it is.
    const InstancedHierarchy::InstanceData& in = h_->instances[inst];
    const Vec3 ng{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    Vec3 n = normalize(
        Vec3{dot(in.normal_rows[0], ng), dot(in.normal_rows[1], ng), dot(in.normal_rows[2], ng)});
    if (dot(n, ray.dir) > 0.0f) n = -n;
    hit.surf.t = hit.t;
    hit.surf.normal = n;
    hit.surf.p = ray.at(hit.t);
    hit.surf.p_error = abs(hit.surf.p) * (64.0f * gamma(1));
    return hit;
  }

  float transmittance(const Ray& ray, std::uint64_t) {
    RTCRay r{};
    fill(r, ray);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcOccluded1(f_->scene(), &ctx, &r);
    return r.tfar < 0.0f ? 0.0f : 1.0f;
  }

 private:
  static void fill(RTCRay& r, const Ray& ray) {
    r.org_x = ray.origin.x;
    r.org_y = ray.origin.y;
    r.org_z = ray.origin.z;
    r.dir_x = ray.dir.x;
    r.dir_y = ray.dir.y;
    r.dir_z = ray.dir.z;
    r.tnear = ray.tmin;
    r.tfar = ray.tmax;
    r.mask = 0xffffffffu;
    r.time = 0.0f;
    r.flags = 0;
  }

  const InstancedHierarchy* h_;
  const EmbreeField* f_;
};

using EmbreeIntegrator = Integrator<InstancedHierarchy, TraditionalLod, StochasticOpacity,
                                    SortedOrder, Counters, EmbreeTracer>;

/// Renders `o` (its spp, seed, sampler, threads, size) over `f` with `camera`: render()'s pass
/// loop with the Integrator over Embree. Returns the image; `seconds` gets the wall time.
inline std::vector<Vec3> embree_render(const InstancedHierarchy& h, const Environment& env,
                                       const EmbreeField& f, const RenderOptions& o,
                                       double* seconds = nullptr) {
  FilmState st;
  st.width = o.width;
  st.height = o.height;
  st.sum.assign(static_cast<std::size_t>(o.width) * o.height, Vec3{});
  st.tests.assign(st.sum.size(), 0);
  const auto t0 = std::chrono::steady_clock::now();
  render_passes(env.camera, o, st, RenderControl{},
                [&](Counters&) { return EmbreeIntegrator(h, env, EmbreeTracer(h, f)); });
  if (seconds) *seconds = embree_detail::seconds_since(t0);
  return finish(st).image;
}

}  // namespace amalgam

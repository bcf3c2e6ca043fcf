#pragma once
/// \file Any loaded scene rendered with Intel Embree 3 at full detail, through the same pass
/// loop (passes.h) and Integrator as `render`: same camera, pixel sampling, random streams,
/// lights and shading; only the ray tracer differs. Built only when Embree is found (CMake
/// option AMALGAM_EMBREE; library amalgam_embree, macro AMALGAM_HAVE_EMBREE).
///
/// Embree's copy of the scene: triangles as Embree triangle meshes; spheres and boxes as Embree
/// user geometry whose callbacks call the hierarchy's own intersect() (the same surfaces, bit
/// for bit); an instanced scene as one Embree scene per mesh and one Embree instance per
/// instance with the same 3x4 transform; an implicit builtin's primitives listed once. Closest
/// hits by rtcIntersect1, shadow rays by rtcOccluded1, where a triangle's occlusion filter
/// keeps only hits amalgam's own test of it accepts (Embree's transform into an instance can
/// put a shadow ray behind the triangle it leaves; docs/embree.md). A hit's surface (point, normal,
/// error bound for the shadow-ray origin) is recomputed by the hierarchy's own test of the one
/// primitive Embree found, so shading matches the traditional renderer wherever both hit the
/// same primitive. Embree counts no intersection tests: the counters hold rays only.

#include <memory>

#include "amalgam/render/render.h"

namespace amalgam {

/// The Embree device and scene of one loaded scene (which must outlive it).
class EmbreeScene {
 public:
  /// Builds Embree's BVHs. `threads` > 0 caps Embree's build threads (device config
  /// "threads=N"); 0: Embree's default (all hardware threads). Throws InputError when an
  /// implicit builtin has more primitives than kMaxListedPrimitives, RuntimeError when Embree
  /// fails (e.g. out of memory).
  explicit EmbreeScene(const LoadedScene& scene, int threads = 0);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  /// Wall time of the device creation and every BVH build (rtcCommitScene).
  double build_seconds() const;
  /// The scene this was built from.
  const LoadedScene& scene() const;

  /// The most primitives of an implicit builtin Embree's copy lists (2^26: some GB).
  static constexpr double kMaxListedPrimitives = 67108864.0;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// `render` (render.h) with Embree as the ray tracer: the same progressive passes, resume and
/// control. `options.lod` must be FullDetail (the traditional renderer), `options.tracer` embree
/// (InputError otherwise). The output's counters hold the rays traced; its test counts and
/// per-pixel costs are zero (Embree does not count tests).
RenderOutput render_embree(const EmbreeScene& scene, const RenderOptions& options,
                           FilmState* resume = nullptr, const RenderControl& control = {});

/// `render_tile` (render.h) with Embree: samples s0 .. s1 - 1 of the tile's pixels, as
/// render_embree renders them. Returns false when `cancel` stopped it.
bool render_tile_embree(const EmbreeScene& scene, const RenderOptions& options, FilmTile& tile,
                        int s0, int s1, const std::atomic<bool>* cancel = nullptr);

/// `trace` (render.h) with Embree: one primary ray with its shadow rays (counters: rays only).
TraceOutput trace_embree(const EmbreeScene& scene, const RenderOptions& options, const Ray& ray);

}  // namespace amalgam

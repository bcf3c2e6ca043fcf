#pragma once
/// \file The ray tracers a loaded scene renders with, behind one interface, and the one factory
/// that makes them (`make_tracer`), used by the CLI, MPI ranks and the benchmarks:
///
/// - amalgam's own traversal (`TracerKind::kAmalgam`): every renderer of render.h; nothing is
///   built beyond the scene's hierarchy;
/// - Intel Embree 3 at full detail (`TracerKind::kEmbree`, render/embree_tracer.h): Embree's
///   BVHs are built when the tracer is made, with the quality and flags of `EmbreeBuild`.
///
/// Both run the same pass loop and Integrator (render/passes.h): same camera, pixel sampling,
/// random streams, lights and shading; only what finds the hits differs.

#include <atomic>
#include <memory>

#include "amalgam/render/render.h"

namespace amalgam {

/// How Embree builds its BVHs (Embree's RTC_BUILD_QUALITY_* and RTC_SCENE_FLAG_ROBUST). The
/// default, used by `--tracer embree`, is Embree's best static BVH with robust traversal (our own
/// triangle test is watertight); Embree's own default configuration is {kMedium, false}.
struct EmbreeBuild {
  enum class Quality : unsigned char { kLow, kMedium, kHigh };
  Quality quality = Quality::kHigh;
  bool robust = true;
};

/// One loaded scene's ray tracer. The scene must outlive it. Every call takes the options of
/// that render (resolution, samples, seed, ...); they must name this tracer (InputError if not).
class Tracer {
 public:
  virtual ~Tracer() = default;

  /// `render` (render.h) with this tracer: the same progressive passes, resume and control.
  RenderOutput render(const RenderOptions& options, FilmState* resume = nullptr,
                      const RenderControl& control = {}) const {
    return render_view(scene_->env, options, resume, control);
  }
  /// The same with another view of the scene: `env` (camera, lights, background) replaces
  /// scene.env; the hierarchy (and Embree's BVHs) are shared.
  virtual RenderOutput render_view(const Environment& env, const RenderOptions& options,
                                   FilmState* resume, const RenderControl& control) const = 0;
  /// `render_tile` (render.h) with this tracer. False when `cancel` stopped it.
  virtual bool render_tile(const RenderOptions& options, FilmTile& tile, int s0, int s1,
                           const std::atomic<bool>* cancel = nullptr) const = 0;
  /// `trace` (render.h) with this tracer: one primary ray and its shadow rays.
  virtual TraceOutput trace(const RenderOptions& options, const Ray& ray) const = 0;

  /// Wall time of what making the tracer built (Embree's device and BVHs); 0 for amalgam's
  /// traversal, whose hierarchy is built with the scene (LoadedScene::build_seconds).
  virtual double build_seconds() const = 0;
  /// Whether it counts intersection tests (Embree counts rays only: its test counts and per-pixel
  /// costs are zero).
  virtual bool counts_tests() const = 0;

  /// The scene this tracer was made for.
  const LoadedScene& scene() const { return *scene_; }

 protected:
  explicit Tracer(const LoadedScene& scene) : scene_(&scene) {}

 private:
  const LoadedScene* scene_;
};

/// The tracer `options.tracer` names for `scene`, checked against it first (check_options).
/// For Embree, `options.threads` > 0 caps its build threads, and `embree` sets its BVH quality
/// and flags. Throws InputError for options the scene refuses, or `--tracer embree` in a build
/// without Embree or on an implicit builtin too large to list; RuntimeError when Embree fails.
std::unique_ptr<Tracer> make_tracer(const LoadedScene& scene, const RenderOptions& options,
                                    const EmbreeBuild& embree = {});

/// Whether this build has Embree (`--tracer embree`).
bool have_embree();
/// Throws InputError (naming how to get it) when this build lacks `tracer`.
void require_tracer(TracerKind tracer);

}  // namespace amalgam

// The tracer factory (tracer.h): amalgam's traversal, or Embree where this build has it.

#include "amalgam/render/tracer.h"

#include "amalgam/util/error.h"

#if defined(AMALGAM_HAVE_EMBREE)
#include "amalgam/render/embree_tracer.h"
#endif

namespace amalgam {

namespace {

/// amalgam's own traversal: the functions of render.h, over the scene as loaded.
class AmalgamTracer final : public Tracer {
 public:
  explicit AmalgamTracer(const LoadedScene& scene) : Tracer(scene) {}

  RenderOutput render_view(const Environment& env, const RenderOptions& o, FilmState* resume,
                           const RenderControl& control) const override {
    return amalgam::render(scene(), env, o, resume, control);
  }
  bool render_tile(const RenderOptions& o, FilmTile& tile, int s0, int s1,
                   const std::atomic<bool>* cancel) const override {
    return amalgam::render_tile(scene(), o, tile, s0, s1, cancel);
  }
  TraceOutput trace(const RenderOptions& o, const Ray& ray) const override {
    return amalgam::trace(scene(), o, ray);
  }
  double build_seconds() const override { return 0.0; }
  bool counts_tests() const override { return true; }
};

}  // namespace

bool have_embree() {
#if defined(AMALGAM_HAVE_EMBREE)
  return true;
#else
  return false;
#endif
}

void require_tracer(TracerKind tracer) {
  if (tracer == TracerKind::kEmbree && !have_embree())
    throw InputError(
        "--tracer embree: this amalgam was built without Embree (install libembree-dev, "
        "reconfigure with -DAMALGAM_EMBREE=ON)");
}

std::unique_ptr<Tracer> make_tracer(const LoadedScene& scene, const RenderOptions& options,
                                    [[maybe_unused]] const EmbreeBuild& embree) {
  require_tracer(options.tracer);
  check_options(scene, options);
#if defined(AMALGAM_HAVE_EMBREE)
  if (options.tracer == TracerKind::kEmbree)
    return make_embree_tracer(scene, options.threads, embree);
#endif
  return std::make_unique<AmalgamTracer>(scene);
}

}  // namespace amalgam

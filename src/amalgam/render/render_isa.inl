// The per-instruction-set part of render() and trace(): the one place where run-time options
// become template arguments. Included once per instruction set (render_portable.cpp,
// render_avx2.cpp); see util/isa.h.

#include <type_traits>

#include "amalgam/render/integrator.h"
#include "amalgam/render/passes.h"
#include "amalgam/render/render_isa.h"
#include "amalgam/render/volume_integrator.h"

namespace amalgam {
AMALGAM_ISA_BEGIN
namespace {

/// Calls f(hierarchy, lod, opacity, order) with the policies the options select.
template <class F>
auto dispatch(const LoadedScene& scene, const RenderOptions& o, F&& f) {
  return std::visit(
      [&](const auto& h) {
        auto with_lod = [&](auto lod) {
          auto with_opacity = [&](auto op) {
            // The traditional renderer renders no amalgam: one opacity model serves every
            // --opacity (fewer instantiations; the same images and counts).
            if constexpr (std::is_same_v<decltype(lod), TraditionalLod>) {
              if (o.sorted) return f(h, lod, StochasticOpacity{}, SortedOrder{});
              return f(h, lod, StochasticOpacity{}, StoredOrder{});
            } else {
              if (o.sorted) return f(h, lod, op, SortedOrder{});
              return f(h, lod, op, StoredOrder{});
            }
          };
          if (o.opacity == OpacityKind::kStochastic) return with_opacity(StochasticOpacity{});
          if (o.opacity == OpacityKind::kPrefiltered) return with_opacity(PrefilteredOpacity{});
          if (o.opacity == OpacityKind::kComposite) return with_opacity(CompositeOpacity{});
          return with_opacity(DeterministicOpacity{});
        };
        if (const auto* l = std::get_if<OnLevel>(&o.lod)) return with_lod(ScaleSensitiveLod::on_level(l->level));
        if (const auto* f = std::get_if<ByFootprint>(&o.lod))
          return with_lod(ScaleSensitiveLod::by_footprint(f->pixels));
        return with_lod(TraditionalLod{});  // full detail (volumetric: its other objects too)
      },
      scene.hierarchy);
}

/// Under the volumetric renderer, calls f(make) with make(counters) -> a VolumeIntegrator and
/// returns true; else returns false (check_options has made sure the scene has cells).
template <class F>
bool with_volumes(const LoadedScene& scene, const Environment& env, const RenderOptions& o, F&& f) {
  const auto* cells = std::get_if<VolumetricCells>(&o.lod);
  if (!cells) return false;
  const auto& h = std::get<InstancedHierarchy>(scene.hierarchy);
  const VolumeSet& v = *scene.volumes;
  f([&](Counters& c) { return VolumeIntegrator(h, v, env, cells->cone_widths, c); });
  return true;
}

}  // namespace
AMALGAM_ISA_END

namespace detail {

bool AMALGAM_ISA_SUFFIXED(render_passes)(const LoadedScene& scene, const Environment& env,
                                         const RenderOptions& o, FilmState& st,
                                         const RenderControl& control) {
  bool interrupted = false;
  if (with_volumes(scene, env, o, [&](auto make) {
        interrupted = render_passes(env.camera, o, st, control, make);
      }))
    return interrupted;
  dispatch(scene, o, [&](const auto& h, auto lod, auto op, auto order) {
    using I = Integrator<std::decay_t<decltype(h)>, decltype(lod), decltype(op), decltype(order)>;
    interrupted =
        render_passes(env.camera, o, st, control, [&](Counters& c) { return I(h, env, lod, c); });
  });
  return interrupted;
}

bool AMALGAM_ISA_SUFFIXED(render_tile)(const LoadedScene& scene, const RenderOptions& o,
                                       FilmTile& tile, int s0, int s1,
                                       const std::atomic<bool>* cancel) {
  bool interrupted = false;
  if (with_volumes(scene, scene.env, o, [&](auto make) {
        interrupted = render_tile_passes(scene.env.camera, o, tile, s0, s1, cancel, make);
      }))
    return interrupted;
  dispatch(scene, o, [&](const auto& h, auto lod, auto op, auto order) {
    using I = Integrator<std::decay_t<decltype(h)>, decltype(lod), decltype(op), decltype(order)>;
    interrupted = render_tile_passes(scene.env.camera, o, tile, s0, s1, cancel,
                                     [&](Counters& c) { return I(h, scene.env, lod, c); });
  });
  return interrupted;
}

void AMALGAM_ISA_SUFFIXED(trace)(const LoadedScene& scene, const RenderOptions& o, const Ray& ray,
                                 TraceOutput& out) {
  if (with_volumes(scene, scene.env, o, [&](auto make) {
        auto integrator = make(out.counters);
        const SampleResult r = integrator.li(ray, hash_combine(hash_combine(o.seed, 0), 0));
        out.hit = r.hit;
        out.colour = r.colour;
      }))
    return;
  dispatch(scene, o, [&](const auto& h, auto lod, auto op, auto order) {
    using I = Integrator<std::decay_t<decltype(h)>, decltype(lod), decltype(op), decltype(order)>;
    I integrator(h, scene.env, lod, out.counters);
    const SampleResult r = integrator.li(ray, hash_combine(hash_combine(o.seed, 0), 0));
    out.hit = r.hit;
    out.colour = r.colour;
  });
}

}  // namespace detail
}  // namespace amalgam

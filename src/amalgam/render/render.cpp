#include "amalgam/render/render.h"

#include <oneapi/tbb/blocked_range2d.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <chrono>
#include <type_traits>

#include "amalgam/render/integrator.h"

namespace amalgam {
namespace {

/// Calls f(hierarchy, lod, opacity_constant, sorted_constant) with the policies the options
/// select: the one place where run-time options become template arguments.
template <class F>
auto dispatch(const LoadedScene& scene, const RenderOptions& o, F&& f) {
  return std::visit(
      [&](const auto& h) {
        auto with_lod = [&](auto lod) {
          auto with_opacity = [&](auto op) {
            if (o.sorted) return f(h, lod, op, std::true_type{});
            return f(h, lod, op, std::false_type{});
          };
          if (o.opacity == OpacityKind::kStochastic)
            return with_opacity(
                std::integral_constant<OpacityModel, OpacityModel::kStochastic>{});
          return with_opacity(
              std::integral_constant<OpacityModel, OpacityModel::kDeterministic>{});
        };
        if (o.renderer == RendererKind::kTraditional) return with_lod(TraditionalLod{});
        if (o.level) return with_lod(FixedLevelLod{*o.level});
        return with_lod(FootprintLod{o.footprint});
      },
      scene.hierarchy);
}

template <class H, class Lod, class Op, class Sorted>
using IntegratorFor = Integrator<H, Lod, Op::value, Sorted::value>;

struct ThreadState {
  Counters counters;
  CostDistribution per_primary;
};

}  // namespace

void check_options(const LoadedScene& scene, const RenderOptions& o) {
  const int levels = scene.info().levels;
  if (o.level && (*o.level < 0 || *o.level >= levels))
    throw InputError("--level " + std::to_string(*o.level) + ": expected a level in [0, " +
                     std::to_string(levels - 1) + "] for " + scene.name);
  if (!(o.footprint > 0.0f)) throw InputError("--footprint: expected a number > 0");
  if (o.width < 1 || o.height < 1 || o.spp < 1)
    throw InputError("--width, --height and --spp must be at least 1");
}

RenderOutput render(const LoadedScene& scene, const RenderOptions& o) {
  check_options(scene, o);
  RenderOutput out;
  out.width = o.width;
  out.height = o.height;
  out.spp = o.spp;
  out.image.assign(static_cast<std::size_t>(o.width) * o.height, Vec3{});
  out.cost.assign(out.image.size(), 0.0);
  const auto t0 = std::chrono::steady_clock::now();

  dispatch(scene, o, [&](const auto& h, auto lod, auto op, auto sorted) {
    using H = std::decay_t<decltype(h)>;
    using I = IntegratorFor<H, decltype(lod), decltype(op), decltype(sorted)>;
    tbb::enumerable_thread_specific<ThreadState> states;
    const int threads = o.threads > 0 ? o.threads : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range2d<int>(0, o.height, 8, 0, o.width, 8),
          [&](const tbb::blocked_range2d<int>& r) {
            ThreadState& st = states.local();
            I integrator(h, scene.env, lod, st.counters);
            for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
              for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                const std::size_t pix = static_cast<std::size_t>(y) * o.width + x;
                const std::uint64_t pixel_key = hash_combine(o.seed, pix);
                Vec3 sum{};
                std::uint64_t tests = 0;
                for (int s = 0; s < o.spp; ++s) {
                  const std::uint64_t key = hash_combine(pixel_key, static_cast<std::uint64_t>(s));
                  Sampler jitter(hash_combine(key, 0x6a177e5));
                  const float fx = static_cast<float>(x) + jitter.next();
                  const float fy = static_cast<float>(y) + jitter.next();
                  const Ray ray = scene.env.camera.generate(fx, fy, o.width, o.height);
                  const std::uint64_t before = st.counters.total();
                  sum += integrator.li(ray, key).colour;
                  const std::uint64_t cost = st.counters.total() - before;
                  st.per_primary.add(cost);
                  tests += cost;
                }
                out.image[pix] = sum / static_cast<float>(o.spp);
                out.cost[pix] = static_cast<double>(tests) / o.spp;
              }
            }
          });
    });
    for (const ThreadState& st : states) {
      out.counters.merge(st.counters);
      out.per_primary.merge(st.per_primary);
    }
  });
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

TraceOutput trace(const LoadedScene& scene, const RenderOptions& o, const Ray& ray) {
  check_options(scene, o);
  TraceOutput out;
  dispatch(scene, o, [&](const auto& h, auto lod, auto op, auto sorted) {
    using H = std::decay_t<decltype(h)>;
    IntegratorFor<H, decltype(lod), decltype(op), decltype(sorted)> integrator(h, scene.env, lod,
                                                                               out.counters);
    const SampleResult r = integrator.li(ray, hash_combine(hash_combine(o.seed, 0), 0));
    out.hit = r.hit;
    out.colour = r.colour;
  });
  out.per_primary.add(out.counters.total());
  return out;
}

}  // namespace amalgam

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

RenderOutput finish(const FilmState& st) {
  RenderOutput out;
  out.width = st.width;
  out.height = st.height;
  out.spp = st.spp_done;
  out.image.resize(st.sum.size());
  out.cost.resize(st.sum.size());
  const float inv = st.spp_done > 0 ? 1.0f / static_cast<float>(st.spp_done) : 0.0f;
  for (std::size_t i = 0; i < st.sum.size(); ++i) {
    out.image[i] = st.sum[i] * inv;
    out.cost[i] = st.spp_done > 0 ? static_cast<double>(st.tests[i]) / st.spp_done : 0.0;
  }
  out.counters = st.counters;
  out.per_primary = st.per_primary;
  return out;
}

RenderOutput render(const LoadedScene& scene, const RenderOptions& o, FilmState* resume,
                    const RenderControl& control) {
  check_options(scene, o);
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t pixels = static_cast<std::size_t>(o.width) * o.height;
  FilmState local;
  FilmState& st = resume ? *resume : local;
  if (st.sum.empty()) {
    st = FilmState{};
    st.width = o.width;
    st.height = o.height;
    st.sum.assign(pixels, Vec3{});
    st.tests.assign(pixels, 0);
  }
  if (st.width != o.width || st.height != o.height || st.sum.size() != pixels ||
      st.spp_done > o.spp)
    throw InputError("resume: the saved render does not match these options");

  // Samples per pass: whole samples for every pixel, about 2^16 primary rays per pass so that
  // small images do not pay for many passes and large ones can stop quickly.
  const int per_pass = std::max(1, static_cast<int>(65536 / std::max<std::size_t>(pixels, 1)));
  bool interrupted = false;
  dispatch(scene, o, [&](const auto& h, auto lod, auto op, auto sorted) {
    using H = std::decay_t<decltype(h)>;
    using I = IntegratorFor<H, decltype(lod), decltype(op), decltype(sorted)>;
    const int threads = o.threads > 0 ? o.threads : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    std::vector<Vec3> pass_sum;
    std::vector<std::uint64_t> pass_tests;
    while (st.spp_done < o.spp && !interrupted) {
      const int s0 = st.spp_done, s1 = std::min(o.spp, s0 + per_pass);
      pass_sum = st.sum;  // continue each pixel's running sum in sample order
      pass_tests = st.tests;
      tbb::enumerable_thread_specific<ThreadState> states;
      std::atomic<bool> stopped{false};
      arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range2d<int>(0, o.height, 8, 0, o.width, 8),
            [&](const tbb::blocked_range2d<int>& r) {
              if (control.cancel && control.cancel->load(std::memory_order_relaxed)) {
                stopped.store(true, std::memory_order_relaxed);
                return;
              }
              ThreadState& ts = states.local();
              I integrator(h, scene.env, lod, ts.counters);
              for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
                for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                  const std::size_t pix = static_cast<std::size_t>(y) * o.width + x;
                  const std::uint64_t pixel_key = hash_combine(o.seed, pix);
                  Vec3 sum = pass_sum[pix];
                  std::uint64_t tests = 0;
                  for (int s = s0; s < s1; ++s) {
                    const std::uint64_t key =
                        hash_combine(pixel_key, static_cast<std::uint64_t>(s));
                    Sampler jitter(hash_combine(key, 0x6a177e5));
                    const float fx = static_cast<float>(x) + jitter.next();
                    const float fy = static_cast<float>(y) + jitter.next();
                    const Ray ray = scene.env.camera.generate(fx, fy, o.width, o.height);
                    const std::uint64_t before = ts.counters.total();
                    sum += integrator.li(ray, key).colour;
                    const std::uint64_t cost = ts.counters.total() - before;
                    ts.per_primary.add(cost);
                    tests += cost;
                  }
                  pass_sum[pix] = sum;
                  pass_tests[pix] += tests;
                }
              }
            });
      });
      if (stopped.load()) {  // the pass is incomplete: discard it
        interrupted = true;
        break;
      }
      st.sum.swap(pass_sum);
      st.tests.swap(pass_tests);
      for (const ThreadState& ts : states) {
        st.counters.merge(ts.counters);
        st.per_primary.merge(ts.per_primary);
      }
      st.spp_done = s1;
      if (control.cancel && control.cancel->load() && st.spp_done < o.spp) interrupted = true;
      if (control.on_pass) control.on_pass(st);
    }
  });
  RenderOutput out = finish(st);
  out.interrupted = interrupted;
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

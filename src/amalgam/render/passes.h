#pragma once
/// \file The progressive pass loop of a render, independent of what traces the rays: render()
/// runs it with amalgam's Integrator over a hierarchy; bench/field_bench.cpp runs it with the
/// same Integrator over Intel Embree, so both images come from one loop and one sampling.

#include <oneapi/tbb/blocked_range2d.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <tuple>
#include <vector>

#include "amalgam/math/random.h"
#include "amalgam/math/sobol.h"
#include "amalgam/render/integrator.h"
#include "amalgam/render/render.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// Adds one sample's auxiliary outputs to its pixel's sums (PixelAov, render.h).
inline void add_sample(PixelAov& a, const SampleResult& r) {
  a.normal += r.normal;
  a.albedo += r.albedo;
  if (r.hit.kind == TraceHit::Kind::kNone) return;
  a.depth += r.hit.t;
  if (r.hit.kind == TraceHit::Kind::kPrimitive) {
    ++a.primitives;
  } else {
    ++a.amalgams;
    a.level_sum += static_cast<std::uint32_t>(r.hit.level);
  }
}

/// Adds samples st.spp_done .. o.spp - 1 to `st` (sized for o.width x o.height), in passes of
/// whole samples per pixel over 8x8 tiles on o.threads threads (0: all). Pixel (x, y),
/// sample s uses the random stream hash(o.seed, y * width + x, s), so the result does not
/// depend on the thread count. Its position in the pixel comes from that stream
/// (PixelSampler::kIndependent) or is point s of the pixel's scrambled Sobol sequence
/// (kStratified), a function of (o.seed, pixel, s) too. `make(counters)` returns an integrator for
/// one tile (an object with `li(ray, key)` returning a SampleResult) that counts its tests into
/// `counters`. Returns whether control.cancel stopped the render early.
template <class MakeIntegrator>
bool render_passes(const Camera& camera, const RenderOptions& o, FilmState& st,
                   const RenderControl& control, MakeIntegrator&& make) {
  struct ThreadState {
    Counters counters;
    CostDistribution per_primary;
  };
  const std::size_t pixels = static_cast<std::size_t>(o.width) * o.height;
  // Samples per pass: whole samples for every pixel, about 2^16 primary rays per pass so that
  // small images do not pay for many passes and large ones can stop quickly.
  const int per_pass = std::max(1, static_cast<int>(65536 / std::max<std::size_t>(pixels, 1)));
  tbb::task_arena arena(render_threads(o));
  const bool stratified = o.sampler == PixelSampler::kStratified;
  std::vector<Vec3> pass_sum;
  std::vector<std::uint64_t> pass_tests;
  std::vector<PixelAov> pass_aov;
  if (st.aov.size() != pixels) st.aov.assign(pixels, PixelAov{});  // a FilmState made elsewhere
  while (st.spp_done < o.spp) {
    const int s0 = st.spp_done, s1 = std::min(o.spp, s0 + per_pass);
    pass_sum = st.sum;  // continue each pixel's running sum in sample order
    pass_tests = st.tests;
    pass_aov = st.aov;
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
            auto integrator = make(ts.counters);
            for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
              for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                const std::size_t pix = static_cast<std::size_t>(y) * o.width + x;
                const std::uint64_t pixel_key = hash_combine(o.seed, pix);
                const std::uint64_t scramble = hash_combine(pixel_key, 0x50b01);
                Vec3 sum = pass_sum[pix];
                std::uint64_t tests = 0;
                PixelAov aov = pass_aov[pix];
                for (int s = s0; s < s1; ++s) {
                  const std::uint64_t key = hash_combine(pixel_key, static_cast<std::uint64_t>(s));
                  float jx, jy;
                  if (stratified) {
                    std::tie(jx, jy) = scrambled_sobol_2d(static_cast<std::uint32_t>(s), scramble);
                  } else {
                    Sampler jitter(hash_combine(key, 0x6a177e5));
                    jx = jitter.next();
                    jy = jitter.next();
                  }
                  const float fx = static_cast<float>(x) + jx;
                  const float fy = static_cast<float>(y) + jy;
                  const Ray ray = camera.generate(fx, fy, o.width, o.height);
                  const std::uint64_t before = ts.counters.total();
                  const SampleResult r = integrator.li(ray, key);
                  sum += r.colour;
                  add_sample(aov, r);
                  const std::uint64_t cost = ts.counters.total() - before;
                  ts.per_primary.add(cost);
                  tests += cost;
                }
                pass_sum[pix] = sum;
                pass_tests[pix] += tests;
                pass_aov[pix] = aov;
              }
            }
          });
    });
    if (stopped.load()) return true;  // the pass is incomplete: discard it
    st.sum.swap(pass_sum);
    st.tests.swap(pass_tests);
    st.aov.swap(pass_aov);
    for (const ThreadState& ts : states) {
      st.counters.merge(ts.counters);
      st.per_primary.merge(ts.per_primary);
    }
    st.spp_done = s1;
    if (control.on_pass) control.on_pass(st);
    if (control.cancel && control.cancel->load() && st.spp_done < o.spp) return true;
  }
  return false;
}

AMALGAM_ISA_END
}  // namespace amalgam

#pragma once
/// \file The progressive pass loop of a render, independent of what traces the rays: render()
/// runs it with amalgam's Integrator over a hierarchy; bench/field_bench.cpp runs it with the
/// same Integrator over Intel Embree, so both images come from one loop and one sampling.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <tuple>
#include <vector>

#include "amalgam/math/random.h"
#include "amalgam/math/sobol.h"
#include "amalgam/render/integrator.h"
#include "amalgam/render/pass_blocks.h"
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

/// Adds samples s0 .. s1 - 1 of pixel (x, y) to its running sums `sum`, `tests` and `aov`, in
/// sample order: the one per-pixel loop of render_passes and render_tile_passes, so a pixel's
/// bytes do not depend on which of them rendered it.
template <class Integrator>
inline void render_pixel(const Camera& camera, const RenderOptions& o, int x, int y, int s0, int s1,
                         Integrator& integrator, Counters& counters, CostDistribution& per_primary,
                         Vec3& sum_io, std::uint64_t& tests_io, PixelAov& aov_io) {
  const bool stratified = o.sampler == PixelSampler::kStratified;
  const std::size_t pix = static_cast<std::size_t>(y) * o.width + x;
  const std::uint64_t pixel_key = hash_combine(o.seed, pix);
  const std::uint64_t scramble = hash_combine(pixel_key, 0x50b01);
  Vec3 sum = sum_io;
  std::uint64_t tests = 0;
  PixelAov aov = aov_io;
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
    const std::uint64_t before = counters.total();
    const SampleResult r = integrator.li(ray, key);
    sum += r.colour;
    add_sample(aov, r);
    const std::uint64_t cost = counters.total() - before;
    per_primary.add(cost);
    tests += cost;
  }
  sum_io = sum;
  tests_io += tests;
  aov_io = aov;
}

/// The block body of a pass over `Body`, as run_pass_blocks takes it.
template <class Body>
void call_pass_block(void* body, int y0, int y1, int x0, int x1, Counters& counters,
                     CostDistribution& per_primary) {
  (*static_cast<Body*>(body))(y0, y1, x0, x1, counters, per_primary);
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
  const std::size_t pixels = static_cast<std::size_t>(o.width) * o.height;
  // Samples per pass: whole samples for every pixel, about 2^16 primary rays per pass so that
  // small images do not pay for many passes and large ones can stop quickly.
  const int per_pass = samples_per_pass(pixels);
  std::vector<Vec3> pass_sum;
  std::vector<std::uint64_t> pass_tests;
  std::vector<PixelAov> pass_aov;
  if (st.aov.size() != pixels) st.aov.assign(pixels, PixelAov{});  // a FilmState made elsewhere
  while (st.spp_done < o.spp) {
    const int s0 = st.spp_done, s1 = std::min(o.spp, s0 + per_pass);
    pass_sum = st.sum;  // continue each pixel's running sum in sample order
    pass_tests = st.tests;
    pass_aov = st.aov;
    auto body = [&](int y0, int y1, int x0, int x1, Counters& counters,
                    CostDistribution& per_primary) {
      auto integrator = make(counters);
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          const std::size_t pix = static_cast<std::size_t>(y) * o.width + x;
          render_pixel(camera, o, x, y, s0, s1, integrator, counters, per_primary, pass_sum[pix],
                       pass_tests[pix], pass_aov[pix]);
        }
      }
      if (control.pixel_samples)
        control.pixel_samples->fetch_add(static_cast<std::uint64_t>(y1 - y0) *
                                             static_cast<std::uint64_t>(x1 - x0) *
                                             static_cast<std::uint64_t>(s1 - s0),
                                         std::memory_order_relaxed);
    };
    Counters counters;
    CostDistribution per_primary;
    if (run_pass_blocks(render_threads(o), 0, o.height, 0, o.width, control.cancel,
                        &call_pass_block<decltype(body)>, &body, counters, per_primary))
      return true;  // the pass is incomplete: discard it
    st.sum.swap(pass_sum);
    st.tests.swap(pass_tests);
    st.aov.swap(pass_aov);
    st.counters.merge(counters);
    st.per_primary.merge(per_primary);
    st.spp_done = s1;
    if (control.on_pass) control.on_pass(st);
    if (control.cancel && control.cancel->load() && st.spp_done < o.spp) return true;
  }
  return false;
}

/// Adds samples s0 .. s1 - 1 to the pixels of `tile` (a rectangle of an o.width x o.height
/// image, its sums continuing from what it holds) on o.threads threads, in 8x8 blocks, with the
/// per-pixel loop of render_passes: a tile rendered here holds the same bytes as the same pixels
/// of a render_passes render. Its counters and per_primary receive the tests of these samples.
/// Returns whether `cancel` stopped it (the tile is then incomplete and must be discarded).
template <class MakeIntegrator>
bool render_tile_passes(const Camera& camera, const RenderOptions& o, FilmTile& tile, int s0,
                        int s1, const std::atomic<bool>* cancel, MakeIntegrator&& make) {
  const TileRect& t = tile.rect;
  auto body = [&](int y0, int y1, int x0, int x1, Counters& counters,
                  CostDistribution& per_primary) {
    auto integrator = make(counters);
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const std::size_t i = static_cast<std::size_t>(y - t.y0) * (t.x1 - t.x0) + (x - t.x0);
        render_pixel(camera, o, x, y, s0, s1, integrator, counters, per_primary, tile.sum[i],
                     tile.tests[i], tile.aov[i]);
      }
    }
  };
  return run_pass_blocks(render_threads(o), t.y0, t.y1, t.x0, t.x1, cancel,
                         &call_pass_block<decltype(body)>, &body, tile.counters, tile.per_primary);
}

AMALGAM_ISA_END
}  // namespace amalgam

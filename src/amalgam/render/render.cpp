#include "amalgam/render/render.h"

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <type_traits>

#include "amalgam/render/option_rules.h"
#include "amalgam/render/render_isa.h"
#include "amalgam/util/check.h"
#include "amalgam/util/isa.h"

namespace amalgam {

void check_options(const LoadedScene& scene, const RenderOptions& o, OptionSpelling spelling) {
  const int levels = scene.info().levels;
  const auto* on_level = std::get_if<OnLevel>(&o.lod);
  if (on_level && (on_level->level < 0 || on_level->level >= levels))
    throw InputError(option_text("--level", spelling, std::to_string(on_level->level)) +
                     ": expected a level in [0, " + std::to_string(levels - 1) + "] for " +
                     scene.name);
  const auto* by_footprint = std::get_if<ByFootprint>(&o.lod);
  const auto* cells = std::get_if<VolumetricCells>(&o.lod);
  if ((by_footprint && !(by_footprint->pixels > 0.0f)) || (cells && !(cells->cone_widths > 0.0f)))
    throw InputError(option_text("--footprint", spelling) + ": expected a number > 0");
  if (o.width < 1 || o.height < 1 || o.spp < 1)
    throw InputError(option_text("--width", spelling) + ", " + option_text("--height", spelling) +
                     " and " + option_text("--spp", spelling) + " must be at least 1");
  AMALGAM_CHECK(scene.amalgams || o.renderer() != RendererKind::kScaleSensitive,
                "the scale-sensitive renderer on a scene loaded without its amalgams' appearances");
  if (o.tracer == TracerKind::kEmbree && o.renderer() != RendererKind::kTraditional)
    throw InputError(option_text("--tracer", spelling, "embree") +
                     " renders at full detail: only " +
                     option_text("--renderer", spelling, "traditional"));
  if (cells) {
    if (o.opacity != OpacityKind::kStochastic)
      throw InputError(option_text("--renderer", spelling, "volumetric") +
                       " composites its cells by coverage: " + option_text("--opacity", spelling) +
                       " does not apply");
    if (!std::holds_alternative<InstancedHierarchy>(scene.hierarchy))
      throw InputError(option_text("--renderer", spelling, "volumetric") + ": " + scene.name +
                       " has no meshes, which are what it prefilters into cells (spheres, boxes, "
                       "loose triangles and builtin scenes have none): render it with another "
                       "renderer");
    if (!scene.volumes)
      throw InputError(option_text("--renderer", spelling, "volumetric") + ": " + scene.name +
                       " was loaded without volumetric amalgams (load it for the volumetric "
                       "renderer)");
  }
}

namespace {
void require_amalgam_tracer(const RenderOptions& o) {
  if (o.tracer != TracerKind::kAmalgam)
    throw InputError("--tracer embree: render with make_tracer (render/tracer.h)");
}
}  // namespace

void start_film(FilmState& st, const RenderOptions& o) {
  const std::size_t pixels = static_cast<std::size_t>(o.width) * o.height;
  if (st.sum.empty()) {
    st = FilmState{};
    st.width = o.width;
    st.height = o.height;
    st.sum.assign(pixels, Vec3{});
    st.tests.assign(pixels, 0);
    st.aov.assign(pixels, PixelAov{});
  }
  if (st.width != o.width || st.height != o.height || st.sum.size() != pixels ||
      st.aov.size() != pixels || st.spp_done > o.spp)
    throw InputError("resume: the saved render does not match these options");
}

int render_threads(const RenderOptions& o) {
  // More threads than the machine runs at once buys nothing (and makes oneTBB print a
  // warning). The image does not depend on the thread count.
  const int cores = tbb::this_task_arena::max_concurrency();
  return o.threads > 0 ? std::min(o.threads, cores) : cores;
}

RenderOutput finish(const FilmState& st) {
  RenderOutput out;
  out.width = st.width;
  out.height = st.height;
  out.spp = st.spp_done;
  const std::size_t n = st.sum.size();
  out.image.resize(n);
  out.cost.resize(n);
  out.tests = st.tests;
  out.depth.resize(n);
  out.level.resize(n);
  out.normal.resize(n);
  out.albedo.resize(n);
  const float inv = st.spp_done > 0 ? 1.0f / static_cast<float>(st.spp_done) : 0.0f;
  const std::uint32_t spp = static_cast<std::uint32_t>(std::max(st.spp_done, 0));
  for (std::size_t i = 0; i < n; ++i) {
    out.image[i] = st.sum[i] * inv;
    out.cost[i] = st.spp_done > 0 ? static_cast<double>(st.tests[i]) / st.spp_done : 0.0;
    const PixelAov a = i < st.aov.size() ? st.aov[i] : PixelAov{};
    const std::uint32_t hits = a.amalgams + a.primitives;
    const std::uint32_t misses = spp >= hits ? spp - hits : 0;
    out.depth[i] = hits > 0 ? a.depth / static_cast<float>(hits) : kInfinity;
    out.normal[i] = a.normal * inv;
    out.albedo[i] = a.albedo * inv;
    if (a.amalgams > 0 && a.amalgams >= a.primitives && a.amalgams >= misses)
      out.level[i] = static_cast<float>(static_cast<double>(a.level_sum) / a.amalgams);
    else if (a.primitives > 0 && a.primitives >= misses)
      out.level[i] = kLevelPrimitive;
    else
      out.level[i] = kLevelNothing;
  }
  out.counters = st.counters;
  out.per_primary = st.per_primary;
  return out;
}

RenderOutput render(const LoadedScene& scene, const RenderOptions& o, FilmState* resume,
                    const RenderControl& control) {
  return render(scene, scene.env, o, resume, control);
}

RenderOutput render(const LoadedScene& scene, const Environment& env, const RenderOptions& o,
                    FilmState* resume, const RenderControl& control) {
  check_options(scene, o);
  require_amalgam_tracer(o);
  const auto t0 = std::chrono::steady_clock::now();
  FilmState local;
  FilmState& st = resume ? *resume : local;
  start_film(st, o);

#if defined(AMALGAM_BUILD_AVX2_COPY)
  const bool interrupted = active_simd() == Simd::kAvx2
                               ? detail::render_passes_avx2(scene, env, o, st, control)
                               : detail::render_passes_portable(scene, env, o, st, control);
#else  // no AVX2 copy in this build (not GCC, or not x86-64): active_simd() is kPortable
  const bool interrupted = detail::render_passes_portable(scene, env, o, st, control);
#endif
  RenderOutput out = finish(st);
  out.interrupted = interrupted;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

int samples_per_pass(std::size_t pixels) {
  return std::max(1, static_cast<int>(65536 / std::max<std::size_t>(pixels, 1)));
}

FilmTile cut_tile(const FilmState& st, const TileRect& r) {
  FilmTile t;
  t.rect = r;
  t.sum.reserve(r.pixels());
  t.tests.reserve(r.pixels());
  t.aov.reserve(r.pixels());
  for (int y = r.y0; y < r.y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * st.width;
    t.sum.insert(t.sum.end(), st.sum.begin() + row + r.x0, st.sum.begin() + row + r.x1);
    t.tests.insert(t.tests.end(), st.tests.begin() + row + r.x0, st.tests.begin() + row + r.x1);
    t.aov.insert(t.aov.end(), st.aov.begin() + row + r.x0, st.aov.begin() + row + r.x1);
  }
  return t;
}

void paste_tile(const FilmTile& t, FilmState& st) {
  const TileRect& r = t.rect;
  const std::size_t w = static_cast<std::size_t>(r.x1 - r.x0);
  for (int y = r.y0; y < r.y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * st.width + r.x0;
    const std::size_t at = static_cast<std::size_t>(y - r.y0) * w;
    std::copy_n(t.sum.begin() + at, w, st.sum.begin() + row);
    std::copy_n(t.tests.begin() + at, w, st.tests.begin() + row);
    std::copy_n(t.aov.begin() + at, w, st.aov.begin() + row);
  }
}

bool render_tile(const LoadedScene& scene, const RenderOptions& o, FilmTile& tile, int s0, int s1,
                 const std::atomic<bool>* cancel) {
  require_amalgam_tracer(o);
  const TileRect& r = tile.rect;
  if (r.x0 < 0 || r.y0 < 0 || r.x1 > o.width || r.y1 > o.height || r.x0 >= r.x1 || r.y0 >= r.y1 ||
      tile.sum.size() != r.pixels() || tile.tests.size() != r.pixels() ||
      tile.aov.size() != r.pixels() || s0 < 0 || s1 < s0)
    throw InputError("render_tile: the tile does not fit the image of these options");
#if defined(AMALGAM_BUILD_AVX2_COPY)
  const bool interrupted = active_simd() == Simd::kAvx2
                               ? detail::render_tile_avx2(scene, o, tile, s0, s1, cancel)
                               : detail::render_tile_portable(scene, o, tile, s0, s1, cancel);
#else
  const bool interrupted = detail::render_tile_portable(scene, o, tile, s0, s1, cancel);
#endif
  return !interrupted;
}

TraceOutput trace(const LoadedScene& scene, const RenderOptions& o, const Ray& ray) {
  check_options(scene, o);
  require_amalgam_tracer(o);
  TraceOutput out;
#if defined(AMALGAM_BUILD_AVX2_COPY)
  if (active_simd() == Simd::kAvx2)
    detail::trace_avx2(scene, o, ray, out);
  else
#endif
    detail::trace_portable(scene, o, ray, out);
  out.per_primary.add(out.counters.total());
  return out;
}

}  // namespace amalgam

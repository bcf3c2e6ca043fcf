#pragma once
/// \file The entry points of the per-instruction-set copies of the hot paths (util/isa.h):
/// render.cpp calls the one `active_simd()` selects. Defined by render_isa.inl, compiled in
/// render_portable.cpp and, on GCC for x86-64, render_avx2.cpp.

#include "amalgam/render/render.h"

namespace amalgam::detail {

/// Runs the pass loop of `render` (passes.h) with the integrator and traversal the options
/// select, seen with `env` (the scene's or another view of it); returns whether it was
/// interrupted.
bool render_passes_portable(const LoadedScene& scene, const Environment& env,
                            const RenderOptions& o, FilmState& st, const RenderControl& control);
bool render_passes_avx2(const LoadedScene& scene, const Environment& env, const RenderOptions& o,
                        FilmState& st, const RenderControl& control);

/// render_tile's pass (passes.h, render_tile_passes); returns whether it was interrupted.
bool render_tile_portable(const LoadedScene& scene, const RenderOptions& o, FilmTile& tile, int s0,
                          int s1, const std::atomic<bool>* cancel);
bool render_tile_avx2(const LoadedScene& scene, const RenderOptions& o, FilmTile& tile, int s0,
                      int s1, const std::atomic<bool>* cancel);

/// Traces one primary sample along `ray` into `out` (counters, hit, colour).
void trace_portable(const LoadedScene& scene, const RenderOptions& o, const Ray& ray,
                    TraceOutput& out);
void trace_avx2(const LoadedScene& scene, const RenderOptions& o, const Ray& ray, TraceOutput& out);

}  // namespace amalgam::detail

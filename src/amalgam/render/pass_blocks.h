#pragma once
/// \file The parallel part of a render pass, compiled once for the baseline (pass_blocks.cpp):
/// the 8x8 blocks of a rectangle of pixels shared out over threads, each thread with its own
/// counters, merged when every block is done. The per-pixel work comes in through a function
/// pointer from the hot paths (render/passes.h), so TBB's loop is not instantiated again for
/// every integrator and instruction set.

#include <atomic>

#include "amalgam/stats/counters.h"
#include "amalgam/stats/distribution.h"

namespace amalgam {

/// Renders the pixels of rows [y0, y1) x columns [x0, x1), counting into the given counters.
using PassBlockFn = void (*)(void* context, int y0, int y1, int x0, int x1, Counters& counters,
                             CostDistribution& per_primary);

/// Calls block(context, ...) for the 8x8 blocks of rows [y0, y1) x columns [x0, x1) on
/// `threads` threads, then merges each thread's counters and cost distribution into `counters`
/// and `per_primary`. Returns true, merging nothing, if `cancel` was set before every block ran
/// (the pass is then incomplete).
bool run_pass_blocks(int threads, int y0, int y1, int x0, int x1, const std::atomic<bool>* cancel,
                     PassBlockFn block, void* context, Counters& counters,
                     CostDistribution& per_primary);

}  // namespace amalgam

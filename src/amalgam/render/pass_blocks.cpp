#include "amalgam/render/pass_blocks.h"

#include <oneapi/tbb/blocked_range2d.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

namespace amalgam {
namespace {

struct ThreadState {
  Counters counters;
  CostDistribution per_primary;
};

}  // namespace

bool run_pass_blocks(int threads, int y0, int y1, int x0, int x1, const std::atomic<bool>* cancel,
                     PassBlockFn block, void* context, Counters& counters,
                     CostDistribution& per_primary) {
  tbb::task_arena arena(threads);
  tbb::enumerable_thread_specific<ThreadState> states;
  std::atomic<bool> stopped{false};
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range2d<int>(y0, y1, 8, x0, x1, 8),
                      [&](const tbb::blocked_range2d<int>& r) {
                        if (cancel && cancel->load(std::memory_order_relaxed)) {
                          stopped.store(true, std::memory_order_relaxed);
                          return;
                        }
                        ThreadState& ts = states.local();
                        block(context, r.rows().begin(), r.rows().end(), r.cols().begin(),
                              r.cols().end(), ts.counters, ts.per_primary);
                      });
  });
  if (stopped.load()) return true;
  for (const ThreadState& ts : states) {
    counters.merge(ts.counters);
    per_primary.merge(ts.per_primary);
  }
  return false;
}

}  // namespace amalgam

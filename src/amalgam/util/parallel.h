#pragma once
/// \file for_each_index: a loop over [0, n) that oneTBB runs in parallel when n is large.

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <cstddef>

namespace amalgam {

/// Calls f(i) for every i in [0, n): serially below `serial_below` items or when not
/// `parallel`, else over oneTBB in chunks of `grain`. f must be safe to call concurrently for
/// different i.
template <class F>
void for_each_index(std::size_t n, F&& f, std::size_t serial_below = 16384,
                    std::size_t grain = 4096, bool parallel = true) {
  if (!parallel || n < serial_below) {
    for (std::size_t i = 0; i < n; ++i) f(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i < r.end(); ++i) f(i);
                    });
}

}  // namespace amalgam

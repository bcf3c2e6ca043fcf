#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace amalgam::cli {

double progress_delay() {
  if (const char* e = std::getenv("AMALGAM_PROGRESS_AFTER"); e != nullptr && *e != '\0') {
    char* end = nullptr;
    const double v = std::strtod(e, &end);
    if (end != e && *end == '\0' && v >= 0.0) return v;
  }
  return 1.0;
}

PhaseStatus::PhaseStatus(bool enabled) : enabled_(enabled && isatty(2)), delay_(progress_delay()) {
  if (enabled_) thread_ = std::thread([this] { run(); });
}

PhaseStatus::~PhaseStatus() {
  stop();
}

void PhaseStatus::phase(const std::string& what) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  what_ = what;
  since_ = clock::now();
}

void PhaseStatus::stop() {
  if (!enabled_) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
  if (shown_) std::fprintf(stderr, "\n");
}

void PhaseStatus::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  std::size_t last_width = 0;
  // Four updates a second; more often when asked to show phases at once (the tests).
  const auto tick = std::chrono::duration<double>(std::clamp(delay_ / 4, 0.02, 0.25));
  while (!wake_.wait_for(lock, tick, [this] { return stopping_; })) {
    const double t = std::chrono::duration<double>(clock::now() - since_).count();
    if (what_.empty() || t < delay_) continue;
    char line[512];
    const int n = std::snprintf(line, sizeof line, "%s: %.1f s", what_.c_str(), t);
    const std::size_t width = n > 0 ? static_cast<std::size_t>(n) : 0;
    // Pad over a longer previous phase's text.
    std::fprintf(stderr, "\r%s%*s", line,
                 static_cast<int>(last_width > width ? last_width - width : 0), "");
    last_width = width;
    shown_ = true;
  }
}

Progress::Progress(std::uint64_t pixels, int spp, int spp_done, bool enabled)
    : pixels_(pixels),
      total_(pixels * static_cast<std::uint64_t>(spp)),
      before_(pixels * static_cast<std::uint64_t>(spp_done)),
      spp_(spp),
      enabled_(enabled && isatty(2) && spp_done < spp && pixels > 0),
      delay_(progress_delay()),
      done_(before_) {
  if (enabled_) thread_ = std::thread([this] { run(); });
}

void Progress::passes_done(int spp_done) {
  const std::uint64_t at = pixels_ * static_cast<std::uint64_t>(spp_done);
  std::uint64_t now = done_.load(std::memory_order_relaxed);
  while (now < at && !done_.compare_exchange_weak(now, at, std::memory_order_relaxed)) {
  }
}

void Progress::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto tick = std::chrono::duration<double>(std::clamp(delay_ / 4, 0.02, 0.25));
  while (!wake_.wait_for(lock, tick, [this] { return stopping_; })) {
    const double t = std::chrono::duration<double>(clock::now() - start_).count();
    // Blocks of a discarded pass stay counted: never past the end.
    const std::uint64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
    if (t < delay_ || done <= before_) continue;
    const double fraction = static_cast<double>(done) / static_cast<double>(total_);
    const double eta = t / static_cast<double>(done - before_) * static_cast<double>(total_ - done);
    const int width = 30, fill = static_cast<int>(width * fraction);
    std::fprintf(stderr, "\r[%s%s] %3d%% of %d spp, %.1f s, ETA %.1f s ",
                 std::string(fill, '#').c_str(), std::string(width - fill, ' ').c_str(),
                 static_cast<int>(100 * fraction), spp_, t, eta);
    shown_ = true;
  }
}

void Progress::finish() {
  if (!enabled_) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
  if (shown_) std::fprintf(stderr, "\n");
}

}  // namespace amalgam::cli

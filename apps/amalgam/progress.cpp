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

StatusLine::StatusLine(bool enabled, std::function<std::string()> draw)
    : enabled_(enabled && isatty(2)), draw_(std::move(draw)) {
  if (enabled_) thread_ = std::thread([this] { run(); });
}

void StatusLine::stop() {
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

void StatusLine::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  std::size_t last_width = 0;
  // Four updates a second; more often when asked to show at once (the tests).
  const auto tick = std::chrono::duration<double>(std::clamp(progress_delay() / 4, 0.02, 0.25));
  while (!wake_.wait_for(lock, tick, [this] { return stopping_; })) {
    const std::string line = draw_();
    if (line.empty()) continue;
    // Pad over a longer previous text.
    std::fprintf(stderr, "\r%s%*s", line.c_str(),
                 static_cast<int>(last_width > line.size() ? last_width - line.size() : 0), "");
    last_width = line.size();
    shown_ = true;
  }
}

PhaseStatus::PhaseStatus(bool enabled)
    : delay_(progress_delay()), line_(enabled, [this] { return draw(); }) {}

void PhaseStatus::phase(const std::string& what) {
  if (!line_.enabled()) return;
  std::lock_guard<std::mutex> lock(line_.mutex());
  what_ = what;
  since_ = clock::now();
}

std::string PhaseStatus::draw() {
  const double t = std::chrono::duration<double>(clock::now() - since_).count();
  if (what_.empty() || t < delay_) return {};
  char line[512];
  std::snprintf(line, sizeof line, "%s: %.1f s", what_.c_str(), t);
  return line;
}

Progress::Progress(std::uint64_t pixels, int spp, int spp_done, bool enabled)
    : pixels_(pixels),
      total_(pixels * static_cast<std::uint64_t>(spp)),
      before_(pixels * static_cast<std::uint64_t>(spp_done)),
      spp_(spp),
      delay_(progress_delay()),
      done_(before_),
      line_(enabled && spp_done < spp && pixels > 0, [this] { return draw(); }) {}

void Progress::passes_done(int spp_done) {
  const std::uint64_t at = pixels_ * static_cast<std::uint64_t>(spp_done);
  std::uint64_t now = done_.load(std::memory_order_relaxed);
  while (now < at && !done_.compare_exchange_weak(now, at, std::memory_order_relaxed)) {
  }
}

std::string Progress::draw() {
  const double t = std::chrono::duration<double>(clock::now() - start_).count();
  // Blocks of a discarded pass stay counted: never past the end.
  const std::uint64_t done = std::min(done_.load(std::memory_order_relaxed), total_);
  if (t < delay_ || done <= before_) return {};
  const double fraction = static_cast<double>(done) / static_cast<double>(total_);
  const double eta = t / static_cast<double>(done - before_) * static_cast<double>(total_ - done);
  const int width = 30, fill = static_cast<int>(width * fraction);
  char line[160];
  std::snprintf(line, sizeof line, "[%s%s] %3d%% of %d spp, %.1f s, ETA %.1f s",
                std::string(fill, '#').c_str(), std::string(width - fill, ' ').c_str(),
                static_cast<int>(100 * fraction), spp_, t, eta);
  return line;
}

}  // namespace amalgam::cli

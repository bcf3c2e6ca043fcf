#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

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

Progress::Progress(int total, bool enabled)
    : total_(total), enabled_(enabled && isatty(2)), delay_(progress_delay()) {}

void Progress::update(int done) {
  if (!enabled_) return;
  const double t = std::chrono::duration<double>(clock::now() - start_).count();
  if (t < delay_ || done <= 0) return;
  const double eta = t / done * (total_ - done);
  const int width = 30, fill = static_cast<int>(width * static_cast<double>(done) / total_);
  std::fprintf(stderr, "\r[%s%s] %3d%% %d/%d spp, %.1f s, ETA %.1f s ",
               std::string(fill, '#').c_str(), std::string(width - fill, ' ').c_str(),
               100 * done / total_, done, total_, t, eta);
  shown_ = true;
}

void Progress::finish() {
  if (shown_) std::fprintf(stderr, "\n");
  shown_ = false;
}

}  // namespace amalgam::cli

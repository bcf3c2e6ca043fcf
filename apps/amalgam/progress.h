#pragma once
/// \file What `render` shows on a terminal while it works: the phase it is in (reading,
/// building and baking) once a phase takes over a second, then a progress bar over the pixel
/// samples. Nothing is shown when stderr is not a terminal or with --quiet; every line shown is
/// ended before anything else is printed.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace amalgam::cli {

/// Seconds a phase or render runs before it is shown: 1, or the environment's
/// AMALGAM_PROGRESS_AFTER (a number of seconds; the tests set 0).
double progress_delay();

/// One status line on stderr, redrawn four times a second (more often when progress_delay()
/// is under a second) by a thread of its own while stderr is a terminal: each tick calls
/// `draw` under mutex(), which returns the line's text, or empty to leave it as it is.
class StatusLine {
 public:
  StatusLine(bool enabled, std::function<std::string()> draw);
  ~StatusLine() { stop(); }
  StatusLine(const StatusLine&) = delete;
  StatusLine& operator=(const StatusLine&) = delete;
  bool enabled() const { return enabled_; }
  /// What `draw` reads and others write is guarded by this.
  std::mutex& mutex() { return mutex_; }
  /// Stops the thread and ends the line if one was drawn; idempotent.
  void stop();

 private:
  void run();
  bool enabled_;
  std::function<std::string()> draw_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  bool shown_ = false;
  std::thread thread_;
};

/// "reading scene.json: 2.4 s", for as long as the phase lasts and once it has lasted
/// progress_delay() seconds.
class PhaseStatus {
 public:
  explicit PhaseStatus(bool enabled);
  /// Starts a new phase (its clock restarts).
  void phase(const std::string& what);
  /// Ends the display (and its line, if one was shown); idempotent.
  void stop() { line_.stop(); }

 private:
  using clock = std::chrono::steady_clock;
  std::string draw();
  double delay_;
  std::string what_;
  clock::time_point since_ = clock::now();
  StatusLine line_;  ///< last: its thread starts once the rest is set
};

/// A one-line progress bar with an estimate of the time left, over the pixel samples of a
/// render (pixels x samples per pixel), shown after progress_delay(): the render adds each
/// finished block's pixel samples to counter() (RenderControl::pixel_samples), so the bar
/// moves within a pass of samples.
class Progress {
 public:
  /// `pixels` per sample, `spp` samples in all, `spp_done` of them already there (a resumed
  /// render: not counted in the rate).
  Progress(std::uint64_t pixels, int spp, int spp_done, bool enabled);
  std::atomic<std::uint64_t>* counter() { return &done_; }
  /// A pass of samples is complete: `spp_done` samples of every pixel are there (for renders
  /// that count no blocks, e.g. across MPI ranks).
  void passes_done(int spp_done);
  /// Ends the bar's line if one was shown, so that what follows starts a line of its own;
  /// idempotent.
  void finish() { line_.stop(); }

 private:
  using clock = std::chrono::steady_clock;
  std::string draw();
  std::uint64_t pixels_, total_, before_;
  int spp_;
  double delay_;
  std::atomic<std::uint64_t> done_;
  clock::time_point start_ = clock::now();
  StatusLine line_;  ///< last: its thread starts once the rest is set
};

}  // namespace amalgam::cli

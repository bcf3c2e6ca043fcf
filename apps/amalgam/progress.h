#pragma once
/// \file What `render` shows on a terminal while it works: the phase it is in (reading,
/// building and baking) once a phase takes over a second, then a progress bar over the pixel
/// samples.
/// Nothing is shown when stderr is not a terminal or with --quiet; every line shown is ended
/// before anything else is printed.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace amalgam::cli {

/// Seconds a phase or render runs before it is shown: 1, or the environment's
/// AMALGAM_PROGRESS_AFTER (a number of seconds; the tests set 0).
double progress_delay();

/// "reading scene.json: 2.4 s" on stderr, updated four times a second by a thread of its own,
/// for as long as the phase lasts and once it has lasted progress_delay() seconds.
class PhaseStatus {
 public:
  explicit PhaseStatus(bool enabled);
  ~PhaseStatus();  ///< stop()
  PhaseStatus(const PhaseStatus&) = delete;
  PhaseStatus& operator=(const PhaseStatus&) = delete;
  /// Starts a new phase (its clock restarts).
  void phase(const std::string& what);
  /// Ends the display (and its line, if one was shown); idempotent.
  void stop();

 private:
  using clock = std::chrono::steady_clock;
  void run();
  bool enabled_;
  double delay_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::string what_;
  clock::time_point since_ = clock::now();
  bool stopping_ = false;
  bool shown_ = false;
  std::thread thread_;
};

/// A one-line progress bar with an estimate of the time left, over the pixel samples of a
/// render (pixels x samples per pixel), shown after progress_delay() and updated four times a
/// second by a thread of its own: the render adds each finished block's pixel samples to
/// counter() (RenderControl::pixel_samples), so the bar moves within a pass of samples.
class Progress {
 public:
  /// `pixels` per sample, `spp` samples in all, `spp_done` of them already there (a resumed
  /// render: not counted in the rate).
  Progress(std::uint64_t pixels, int spp, int spp_done, bool enabled);
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  std::atomic<std::uint64_t>* counter() { return &done_; }
  /// A pass of samples is complete: `spp_done` samples of every pixel are there (for renders
  /// that count no blocks, e.g. across MPI ranks).
  void passes_done(int spp_done);
  /// Stops the display and ends the bar's line if one was shown, so that what follows starts
  /// a line of its own; idempotent.
  void finish();

 private:
  using clock = std::chrono::steady_clock;
  void run();
  std::uint64_t pixels_, total_, before_;
  int spp_;
  bool enabled_;
  double delay_;
  std::atomic<std::uint64_t> done_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  bool shown_ = false;
  clock::time_point start_ = clock::now();
  std::thread thread_;
};

}  // namespace amalgam::cli

/// \file mpi::spread: jobs (experiments, sweep points) handed out to the ranks of an MPI job.

#include <mutex>
#include <thread>

#include "mpi_render.h"
#include "mpi_wire.h"

namespace amalgam::cli::mpi {
namespace {

using namespace wire;

/// A rank > 0: sends kReady, then for each job it is given (kWork: the index) runs it and
/// sends kResult (job index, ok flag, output or error), until kStop.
void spread_worker(const std::function<std::string(int)>& job) {
  world().in_render = true;
  send(0, kReady, {});
  for (;;) {
    MPI_Status status;
    wait_message(0, status, Clock::time_point::max());
    const std::vector<char> bytes = receive(status);
    if (status.MPI_TAG == kStop) break;
    Reader in{bytes};
    const std::int32_t index = in.get<std::int32_t>();
    Writer w;
    w.put(index);
    try {
      const std::string out = job(index);
      w.put(std::int32_t{1});
      w.bytes.insert(w.bytes.end(), out.begin(), out.end());
    } catch (const std::exception& e) {
      w.put(std::int32_t{0});
      const std::string what = e.what();
      w.bytes.insert(w.bytes.end(), what.begin(), what.end());
    }
    send(0, kResult, w.bytes);
  }
  world().in_render = false;
}

/// Rank 0: hands out the jobs to the ranks that ask and runs jobs on a thread of its own, and
/// calls `done` in the order of the jobs as they finish.
void spread_root(int n, const std::function<std::string(int)>& job,
                 const std::function<void(int, const std::string&)>& done) {
  world().in_render = true;
  std::mutex mutex;
  int next = 0;  // the next job to hand out
  std::vector<std::string> outputs(static_cast<std::size_t>(n));
  std::vector<bool> finished(static_cast<std::size_t>(n), false);
  std::string failure;
  auto take = [&]() -> int {
    std::lock_guard<std::mutex> lock(mutex);
    return failure.empty() && next < n ? next++ : -1;
  };
  auto store = [&](int i, bool ok, std::string text, int r) {
    std::lock_guard<std::mutex> lock(mutex);
    if (ok) {
      outputs[static_cast<std::size_t>(i)] = std::move(text);
      finished[static_cast<std::size_t>(i)] = true;
    } else if (failure.empty()) {
      failure = "rank " + std::to_string(r) + ": " + text;
    }
  };
  std::thread own([&] {
    for (int i; (i = take()) >= 0;) {
      try {
        store(i, true, job(i), 0);
      } catch (const std::exception& e) {
        store(i, false, e.what(), 0);
      }
    }
  });
  int reported = 0, stopped = 0;
  std::exception_ptr error;
  try {
    while (stopped < world().size - 1) {
      MPI_Status status;
      if (wait_message(MPI_ANY_SOURCE, status, Clock::now() + std::chrono::milliseconds(5))) {
        const int from = status.MPI_SOURCE;
        const std::vector<char> bytes = receive(status);
        if (status.MPI_TAG == kResult) {
          Reader in{bytes};
          const int i = in.get<std::int32_t>();
          const bool ok = in.get<std::int32_t>() != 0;
          store(i, ok, std::string(bytes.begin() + static_cast<long>(in.at), bytes.end()), from);
        }
        const int i = take();
        Writer w;
        w.put(static_cast<std::int32_t>(i));
        send(from, i >= 0 ? kWork : kStop, i >= 0 ? w.bytes : std::vector<char>{});
        if (i < 0) ++stopped;
      }
      for (;;) {  // the jobs finished in order so far, outside the lock (done writes files)
        std::string out;
        {
          std::lock_guard<std::mutex> lock(mutex);
          if (reported >= n || !finished[static_cast<std::size_t>(reported)]) break;
          out = std::move(outputs[static_cast<std::size_t>(reported)]);
        }
        done(reported++, out);
      }
    }
  } catch (...) {
    error = std::current_exception();
  }
  own.join();
  if (error) std::rethrow_exception(error);
  world().in_render = false;
  if (!failure.empty()) throw RuntimeError(failure);
  while (reported < n) {
    done(reported, outputs[static_cast<std::size_t>(reported)]);
    ++reported;
  }
}

}  // namespace

void spread(int n, const std::function<std::string(int)>& job,
            const std::function<void(int, const std::string&)>& done) {
  if (world().rank != 0)
    spread_worker(job);
  else
    spread_root(n, job, done);
}

}  // namespace amalgam::cli::mpi

#include "mpi_render.h"

#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>
#include <type_traits>
#include <vector>

#include "amalgam/util/error.h"

namespace amalgam::cli::mpi {

namespace {

using Clock = std::chrono::steady_clock;

bool g_started = false;
int g_rank = 0;
int g_size = 1;
bool g_in_render = false;  ///< between render_root/serve and release: an exception aborts

/// The messages. A worker sends one message (kReady, kResult or kCancelled) and waits for the
/// one answer (kWork or kStop): at most one message is ever in flight each way per worker.
enum Tag : int { kReady = 1, kResult = 2, kCancelled = 3, kWork = 4, kStop = 5 };

static_assert(std::is_trivially_copyable_v<Counters>);
static_assert(std::is_trivially_copyable_v<Vec3>);
static_assert(std::is_trivially_copyable_v<PixelAov>);

void check(int rc, const char* what) {
  if (rc == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(rc, text, &len);
  throw RuntimeError(std::string("MPI: ") + what + " failed: " + std::string(text, len));
}

/// Whether an MPI launcher started this process (Open MPI's mpirun, or a PMI/PMIx launcher
/// such as Slurm's srun). Read before MPI_Init, which is never called otherwise.
bool launched() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"})
    if (const char* e = std::getenv(v); e != nullptr && *e != '\0') return true;
  return false;
}

std::string host() {
  char name[MPI_MAX_PROCESSOR_NAME];
  int len = 0;
  if (MPI_Get_processor_name(name, &len) != MPI_SUCCESS) return "?";
  return std::string(name, len);
}

/// Raw bytes in and out of a message.
struct Writer {
  std::vector<char> bytes;
  template <class T>
  void put(const T& v) {
    const char* p = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  template <class T>
  void put_all(const std::vector<T>& v) {
    const char* p = reinterpret_cast<const char*>(v.data());
    bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
  }
};

struct Reader {
  const std::vector<char>& bytes;
  std::size_t at = 0;
  void need(std::size_t n) const {
    if (at + n > bytes.size()) throw RuntimeError("MPI: a message shorter than its contents");
  }
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  template <class T>
  void get_all(std::vector<T>& v, std::size_t n) {
    need(n * sizeof(T));
    v.resize(n);
    std::memcpy(v.data(), bytes.data() + at, n * sizeof(T));
    at += n * sizeof(T);
  }
};

/// Receives the message `status` announced (from MPI_Iprobe).
std::vector<char> receive(const MPI_Status& status) {
  int n = 0;
  check(MPI_Get_count(&status, MPI_BYTE, &n), "MPI_Get_count");
  std::vector<char> bytes(static_cast<std::size_t>(n));
  check(MPI_Recv(bytes.data(), n, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE),
        "MPI_Recv");
  return bytes;
}

/// Waits for a message from `source` (any rank: MPI_ANY_SOURCE) without spinning a core (a
/// blocking MPI_Probe busy-waits in Open MPI): probes, sleeping 100 us between tries. Returns
/// false when `deadline` passes first.
bool wait_message(int source, MPI_Status& status, Clock::time_point deadline) {
  for (;;) {
    int flag = 0;
    check(MPI_Iprobe(source, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), "MPI_Iprobe");
    if (flag) return true;
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
}

void send(int to, Tag tag, const std::vector<char>& bytes) {
  check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD),
        "MPI_Send");
}

std::vector<char> signal_message(int sig) {
  Writer w;
  w.put(static_cast<std::int32_t>(sig));
  return w.bytes;
}

/// The tiles of a w x h image for `ranks` ranks: squares of 64, 32, 16 or 8 pixels, the largest
/// that gives each rank at least 4 tiles per round (a slow rank then holds the others up by at
/// most a small tile). The split does not change a byte of the image.
std::vector<TileRect> plan_tiles(int w, int h, int ranks) {
  int side = 64;
  auto count = [&](int s) {
    return static_cast<long long>((w + s - 1) / s) * static_cast<long long>((h + s - 1) / s);
  };
  while (side > 8 && count(side) < 4LL * ranks) side /= 2;
  std::vector<TileRect> tiles;
  for (int y = 0; y < h; y += side)
    for (int x = 0; x < w; x += side)
      tiles.push_back({x, y, std::min(w, x + side), std::min(h, y + side)});
  return tiles;
}

std::string describe(const TileRect& r) {
  std::ostringstream s;
  s << "x " << r.x0 << ".." << r.x1 - 1 << ", y " << r.y0 << ".." << r.y1 - 1;
  return s.str();
}

/// A work message: round, tile, its rectangle, the samples to add and (after the first samples)
/// the pixels' running sums.
std::vector<char> work_message(int round, int index, const FilmTile& t, int s0, int s1) {
  Writer w;
  for (int v : {round, index, t.rect.x0, t.rect.y0, t.rect.x1, t.rect.y1, s0, s1})
    w.put(static_cast<std::int32_t>(v));
  w.put(static_cast<std::int32_t>(s0 > 0));
  if (s0 > 0) {
    w.put_all(t.sum);
    w.put_all(t.tests);
    w.put_all(t.aov);
  }
  return w.bytes;
}

/// A result message: round, tile, counters, the cost distribution as (value, times) pairs, and
/// the pixels.
std::vector<char> result_message(int round, int index, const FilmTile& t) {
  Writer w;
  w.put(static_cast<std::int32_t>(round));
  w.put(static_cast<std::int32_t>(index));
  w.put(t.counters);
  std::vector<std::uint64_t> pairs;
  t.per_primary.for_each([&](std::uint64_t v, std::uint64_t n) {
    pairs.push_back(v);
    pairs.push_back(n);
  });
  w.put(static_cast<std::uint64_t>(pairs.size()));
  w.put_all(pairs);
  w.put_all(t.sum);
  w.put_all(t.tests);
  w.put_all(t.aov);
  return w.bytes;
}

/// What rank 0 knows of each rank.
struct Worker {
  bool waiting = false;  ///< sent a message rank 0 has not answered yet
  int tile = -1;         ///< the tile it renders, -1: none
  Clock::time_point since{};
  bool lost = false;  ///< silent with a tile for longer than the timeout
  /// The message being sent to it, sent without blocking: a blocking send of a tile larger than
  /// the eager limit would wait for the rank to receive it, forever if it died.
  std::vector<char> out;
  MPI_Request request = MPI_REQUEST_NULL;
};

/// Sends `bytes` to rank `r` without waiting for it to be received. The previous message to it
/// was received already (it answered), so completing its request does not wait.
void post(int r, Worker& w, Tag tag, std::vector<char> bytes) {
  check(MPI_Wait(&w.request, MPI_STATUS_IGNORE), "MPI_Wait");
  w.out = std::move(bytes);
  check(MPI_Isend(w.out.data(), static_cast<int>(w.out.size()), MPI_BYTE, r, tag, MPI_COMM_WORLD,
                  &w.request),
        "MPI_Isend");
}

struct Dispatcher {
  std::vector<Worker> workers;
  double timeout = 600.0;
  bool active = false;
};
Dispatcher g_dispatch;

}  // namespace

Session::Session(int* argc, char*** argv) {
  if (!launched()) return;
  int provided = 0;
  // Only the main thread makes MPI calls (rank 0 renders its own tiles on another thread).
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    std::cerr << "amalgam: MPI_Init failed\n";
    std::exit(1);
  }
  g_started = true;
  // Failures come back as error codes (RuntimeError, a message) rather than ending the job
  // with MPI's own.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
}

Session::~Session() {
  if (!g_started) return;
  // An exception left a render with other ranks waiting on this one: end them all rather than
  // hang in MPI_Finalize.
  if (g_in_render && g_size > 1) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Finalize();
}

bool parallel() {
  return g_started && g_size > 1;
}
int rank() {
  return g_rank;
}
int size() {
  return g_size;
}

void abort(int status) {
  std::cerr.flush();
  MPI_Abort(MPI_COMM_WORLD, status);
  std::_Exit(status);
}

int agree(std::exception_ptr failure) {
  int mine = 0;
  if (failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const std::exception& e) {
      mine = exit_status(e);
    } catch (...) {
      mine = 1;
    }
  }
  int worst = 0;
  check(MPI_Allreduce(&mine, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
  if (failure) {
    if (g_rank == 0) std::rethrow_exception(failure);
    const std::string where = "rank " + std::to_string(g_rank) + " on " + host() + ": ";
    try {
      std::rethrow_exception(failure);
    } catch (const InputError& e) {
      throw InputError(where + e.what());
    } catch (const std::exception& e) {
      throw RuntimeError(where + e.what());
    }
  }
  if (worst != 0 && g_rank == 0)
    std::cerr << "amalgam: another rank failed before rendering (see its message): nothing "
                 "written\n";
  return worst;
}

std::string broadcast(const std::string& text) {
  std::uint64_t n = text.size();
  check(MPI_Bcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "MPI_Bcast");
  std::string out = g_rank == 0 ? text : std::string(n, '\0');
  check(MPI_Bcast(out.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
  return out;
}

RenderOutput render_root(const TileRenderer& render_tile, const RenderOptions& o, FilmState* resume,
                         const RenderControl& control, const std::atomic<int>& signal,
                         double timeout, double round_seconds, Stop& stop) {
  const auto t0 = Clock::now();
  FilmState local;
  FilmState& st = resume ? *resume : local;
  start_film(st, o);
  g_in_render = true;
  g_dispatch.active = true;
  g_dispatch.timeout = timeout;
  g_dispatch.workers.assign(static_cast<std::size_t>(g_size), Worker{});
  std::vector<Worker>& workers = g_dispatch.workers;
  const std::vector<TileRect> tiles = plan_tiles(o.width, o.height, g_size);
  const std::size_t pixels = static_cast<std::size_t>(o.width) * o.height;
  // The first round: about 2^16 primary rays per rank (a single process's pass for each).
  // Every round moves each pixel's running sums to a rank and back through rank 0 (about 120
  // bytes a pixel), so rounds then double while one takes less than half of round_seconds:
  // the gather becomes a small part of a long render. The image does not depend on the
  // rounds; only how much an interruption drops does.
  int per_round = samples_per_pass(std::max<std::size_t>(1, pixels / g_size));
  bool interrupted = false;
  for (int round = 0; st.spp_done < o.spp && !interrupted; ++round) {
    const int s0 = st.spp_done, s1 = std::min(o.spp, s0 + per_round);
    const auto round_start = Clock::now();
    FilmState next;  // the film after this round: its pixels, tile by tile
    next.width = st.width;
    next.height = st.height;
    next.sum = st.sum;
    next.tests = st.tests;
    next.aov = st.aov;
    Counters counters;
    CostDistribution per_primary;
    std::vector<int> holder(tiles.size(), -1);  // rank rendering each tile, -1: none yet
    std::vector<bool> done(tiles.size(), false);
    std::size_t remaining = tiles.size();
    std::deque<int> todo;
    for (std::size_t i = 0; i < tiles.size(); ++i) todo.push_back(static_cast<int>(i));
    auto merge = [&](int index, const FilmTile& t) {
      paste_tile(t, next);
      counters.merge(t.counters);
      per_primary.merge(t.per_primary);
      done[static_cast<std::size_t>(index)] = true;
      --remaining;
    };

    // Rank 0's own share: a thread that takes tiles from the same queue until it is empty
    // (started again when a lost rank's tile goes back into it).
    std::mutex mutex;
    std::vector<std::pair<int, FilmTile>> local_done;
    std::atomic<bool> local_cancel{false};
    std::atomic<bool> own_running{true};
    std::exception_ptr own_failure;  // under `mutex`
    auto own_share = [&] {
      try {
        for (;;) {
          int index = -1;
          {
            std::lock_guard<std::mutex> lock(mutex);
            if (todo.empty() || local_cancel.load()) break;
            index = todo.front();
            todo.pop_front();
            holder[static_cast<std::size_t>(index)] = 0;
          }
          FilmTile t = cut_tile(st, tiles[static_cast<std::size_t>(index)]);
          if (!render_tile(t, s0, s1, &local_cancel)) break;
          std::lock_guard<std::mutex> lock(mutex);
          local_done.emplace_back(index, std::move(t));
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        own_failure = std::current_exception();
      }
      own_running.store(false);
    };
    std::thread own(own_share);

    std::exception_ptr failure;
    try {
      while (remaining > 0) {
        bool busy = false;
        {
          std::lock_guard<std::mutex> lock(mutex);
          if (own_failure) std::rethrow_exception(own_failure);
          for (auto& [index, t] : local_done) merge(index, t);
          busy = !local_done.empty();
          local_done.clear();
          if (!own_running.load() && !todo.empty()) {  // a tile came back: render it here too
            own.join();
            own_running.store(true);
            own = std::thread(own_share);
          }
        }
        MPI_Status status;
        int flag = 0;
        check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status),
              "MPI_Iprobe");
        if (flag) {
          busy = true;
          const int from = status.MPI_SOURCE;
          const std::vector<char> bytes = receive(status);
          Worker& w = workers[static_cast<std::size_t>(from)];
          w.waiting = true;
          Reader in{bytes};
          if (status.MPI_TAG == kCancelled) {
            stop.signal = in.get<std::int32_t>();
            stop.signal_rank = from;
            interrupted = true;
          } else if (status.MPI_TAG == kResult) {
            const int r = in.get<std::int32_t>(), index = in.get<std::int32_t>();
            // A result of an earlier round, or of a tile taken back (timeout), is dropped.
            if (r == round && index == w.tile && !done[static_cast<std::size_t>(index)]) {
              FilmTile t;
              t.rect = tiles[static_cast<std::size_t>(index)];
              t.counters = in.get<Counters>();
              std::vector<std::uint64_t> pairs;
              in.get_all(pairs, in.get<std::uint64_t>());
              for (std::size_t k = 0; k + 1 < pairs.size(); k += 2)
                t.per_primary.add(pairs[k], pairs[k + 1]);
              in.get_all(t.sum, t.rect.pixels());
              in.get_all(t.tests, t.rect.pixels());
              in.get_all(t.aov, t.rect.pixels());
              merge(index, t);
            }
          }
          w.tile = -1;
          if (w.lost) {
            std::cerr << "amalgam: rank " << from << " answered again after it was taken as "
                      << "lost\n";
            w.lost = false;
          }
        }
        if (control.cancel && control.cancel->load()) {
          stop.signal = signal.load();
          stop.signal_rank = 0;
          interrupted = true;
        }
        if (interrupted) break;
        // Hand out tiles to the ranks waiting for one.
        for (int r = 1; r < g_size; ++r) {
          Worker& w = workers[static_cast<std::size_t>(r)];
          if (!w.waiting) continue;
          int index = -1;
          {
            std::lock_guard<std::mutex> lock(mutex);
            if (todo.empty()) break;
            index = todo.front();
            todo.pop_front();
            holder[static_cast<std::size_t>(index)] = r;
          }
          const FilmTile prior = cut_tile(st, tiles[static_cast<std::size_t>(index)]);
          post(r, w, kWork, work_message(round, index, prior, s0, s1));
          w.waiting = false;
          w.tile = index;
          w.since = Clock::now();
          busy = true;
        }
        // A rank silent with a tile for too long: its tile goes back to the queue.
        for (int r = 1; r < g_size; ++r) {
          Worker& w = workers[static_cast<std::size_t>(r)];
          if (w.tile < 0 || w.lost) continue;
          const double silent = std::chrono::duration<double>(Clock::now() - w.since).count();
          if (silent < timeout) continue;
          w.lost = true;
          std::cerr << "amalgam: rank " << r << " has not returned tile "
                    << describe(tiles[static_cast<std::size_t>(w.tile)]) << " (samples " << s0
                    << ".." << s1 - 1 << ") in " << timeout
                    << " s: taken as lost; the other ranks render its tile\n";
          std::lock_guard<std::mutex> lock(mutex);
          todo.push_front(w.tile);
          holder[static_cast<std::size_t>(w.tile)] = -1;
          w.tile = -1;
        }
        if (!busy) std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    } catch (...) {
      failure = std::current_exception();
    }
    local_cancel.store(interrupted || failure != nullptr);
    own.join();
    if (failure) std::rethrow_exception(failure);
    if (interrupted) {
      // The round is incomplete: dropped, as a single process drops its unfinished pass.
      std::ostringstream missing;
      int count = 0;
      for (std::size_t i = 0; i < tiles.size(); ++i) {
        if (done[i]) continue;
        const int h = holder[i];
        if (h < 0) continue;  // never handed out
        missing << (count++ ? "; " : "") << describe(tiles[i]) << " (rank " << h << ")";
      }
      stop.missing = std::to_string(tiles.size() - static_cast<std::size_t>(std::count(
                                                       done.begin(), done.end(), true))) +
                     " of " + std::to_string(tiles.size()) + " tiles of samples " +
                     std::to_string(s0) + ".." + std::to_string(s1 - 1) + " not finished" +
                     (count ? "; under way: " + missing.str() : std::string());
      break;
    }
    st.sum.swap(next.sum);
    st.tests.swap(next.tests);
    st.aov.swap(next.aov);
    st.counters.merge(counters);
    st.per_primary.merge(per_primary);
    st.spp_done = s1;
    if (control.on_pass) control.on_pass(st);
    const double took = std::chrono::duration<double>(Clock::now() - round_start).count();
    if (took < 0.5 * round_seconds && per_round < (1 << 20)) per_round *= 2;
    if (control.cancel && control.cancel->load() && st.spp_done < o.spp) {
      stop.signal = signal.load();
      interrupted = true;
    }
  }
  RenderOutput out = finish(st);
  out.interrupted = interrupted;
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

bool release() {
  if (!g_dispatch.active) return true;
  g_dispatch.active = false;
  bool all = true;
  for (int r = 1; r < g_size; ++r) {
    Worker& w = g_dispatch.workers[static_cast<std::size_t>(r)];
    if (w.lost) {
      all = false;
      std::cerr << "amalgam: rank " << r << " was lost during the render\n";
      continue;
    }
    if (!w.waiting) {  // still rendering a tile (or starting): wait for its message
      const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                               std::chrono::duration<double>(g_dispatch.timeout));
      MPI_Status status;
      if (!wait_message(r, status, deadline)) {
        all = false;
        w.lost = true;  // its last message may never be received: do not wait for it below
        std::cerr << "amalgam: rank " << r << " did not answer within " << g_dispatch.timeout
                  << " s\n";
        continue;
      }
      receive(status);  // a late tile or a cancellation: the outputs are written already
    }
    post(r, w, kStop, {});
    w.waiting = false;
  }
  for (int r = 1; r < g_size; ++r) {  // the stops are small: sent at once
    Worker& w = g_dispatch.workers[static_cast<std::size_t>(r)];
    if (!w.lost && w.request != MPI_REQUEST_NULL) MPI_Wait(&w.request, MPI_STATUS_IGNORE);
  }
  g_in_render = !all;
  return all;
}

void spread(int n, const std::function<std::string(int)>& job,
            const std::function<void(int, const std::string&)>& done) {
  // Messages: a rank > 0 sends kReady, then kResult (job index, ok flag, output or error) for
  // each job it is given (kWork: the index), until kStop.
  if (g_rank != 0) {
    g_in_render = true;
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
    g_in_render = false;
    return;
  }
  g_in_render = true;
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
    while (stopped < g_size - 1) {
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
  g_in_render = false;
  if (!failure.empty()) throw RuntimeError(failure);
  while (reported < n) {
    done(reported, outputs[static_cast<std::size_t>(reported)]);
    ++reported;
  }
}

void serve(const TileRenderer& render_tile, const RenderOptions& o, const std::atomic<bool>& cancel,
           const std::atomic<int>& signal) {
  g_in_render = true;
  send(0, kReady, {});
  const auto forever = Clock::time_point::max();
  for (;;) {
    MPI_Status status;
    wait_message(0, status, forever);
    const std::vector<char> bytes = receive(status);
    if (status.MPI_TAG == kStop) break;
    Reader in{bytes};
    std::int32_t h[9];
    for (std::int32_t& v : h) v = in.get<std::int32_t>();
    const int round = h[0], index = h[1], s0 = h[6], s1 = h[7];
    const TileRect rect{h[2], h[3], h[4], h[5]};
    if (rect.x0 < 0 || rect.y0 < 0 || rect.x1 > o.width || rect.y1 > o.height ||
        rect.x0 >= rect.x1 || rect.y0 >= rect.y1)
      throw RuntimeError("MPI: a tile outside the image from rank 0");
    FilmTile t;
    t.rect = rect;
    if (h[8]) {
      in.get_all(t.sum, rect.pixels());
      in.get_all(t.tests, rect.pixels());
      in.get_all(t.aov, rect.pixels());
    } else {
      t.sum.assign(rect.pixels(), Vec3{});
      t.tests.assign(rect.pixels(), 0);
      t.aov.assign(rect.pixels(), PixelAov{});
    }
    if (!cancel.load() && render_tile(t, s0, s1, &cancel))
      send(0, kResult, result_message(round, index, t));
    else
      send(0, kCancelled, signal_message(signal.load()));
  }
  g_in_render = false;
}

}  // namespace amalgam::cli::mpi

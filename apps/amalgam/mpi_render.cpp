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
#include "mpi_wire.h"

namespace amalgam::cli::mpi {

namespace {

using namespace wire;

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

struct Dispatcher {
  std::vector<Worker> workers;
  double timeout = 600.0;
  bool active = false;
};
Dispatcher g_dispatch;

/// One round of rank 0: every tile gets samples s0..s1-1, from the other ranks as they ask for
/// work and from a thread of rank 0's own that takes tiles from the same queue. A rank silent
/// with a tile for longer than the timeout is taken as lost and its tile goes back to the queue.
class RootRound {
 public:
  RootRound(const TileRenderer& render_tile, const std::vector<TileRect>& tiles,
            const FilmState& st, int round, int s0, int s1)
      : render_tile_(render_tile),
        tiles_(tiles),
        st_(st),
        round_(round),
        s0_(s0),
        s1_(s1),
        holder_(tiles.size(), -1),
        done_(tiles.size(), false),
        remaining_(tiles.size()) {
    next_.width = st.width;
    next_.height = st.height;
    next_.sum = st.sum;
    next_.tests = st.tests;
    next_.aov = st.aov;
    for (std::size_t i = 0; i < tiles.size(); ++i) todo_.push_back(static_cast<int>(i));
  }

  /// Runs the round until every tile is back (true) or a signal stops it here or on another
  /// rank (false, `stop` says where). Rethrows a failure of rank 0's own share.
  bool run(const RenderControl& control, const std::atomic<int>& signal, Stop& stop) {
    own_ = std::thread([this] { own_share(); });
    bool interrupted = false;
    std::exception_ptr failure;
    try {
      while (remaining_ > 0) {
        bool busy = collect_own();
        busy |= receive_one(stop, interrupted);
        if (control.cancel && control.cancel->load()) {
          stop.signal = signal.load();
          stop.signal_rank = 0;
          interrupted = true;
        }
        if (interrupted) break;
        busy |= hand_out();
        reclaim_silent();
        if (!busy) std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    } catch (...) {
      failure = std::current_exception();
    }
    local_cancel_.store(interrupted || failure != nullptr);
    own_.join();
    if (failure) std::rethrow_exception(failure);
    return !interrupted;
  }

  /// The film after a complete round: its pixels, counters and samples into `st`.
  void commit(FilmState& st) {
    st.sum.swap(next_.sum);
    st.tests.swap(next_.tests);
    st.aov.swap(next_.aov);
    st.counters.merge(counters_);
    st.per_primary.merge(per_primary_);
    st.spp_done = s1_;
  }

  /// The tiles of an interrupted round not returned, and the ranks rendering them.
  std::string missing() const {
    std::ostringstream under_way;
    int count = 0;
    for (std::size_t i = 0; i < tiles_.size(); ++i) {
      if (done_[i] || holder_[i] < 0) continue;  // returned, or never handed out
      under_way << (count++ ? "; " : "") << describe(tiles_[i]) << " (rank " << holder_[i] << ")";
    }
    const auto finished = static_cast<std::size_t>(std::count(done_.begin(), done_.end(), true));
    return std::to_string(tiles_.size() - finished) + " of " + std::to_string(tiles_.size()) +
           " tiles of samples " + std::to_string(s0_) + ".." + std::to_string(s1_ - 1) +
           " not finished" + (count ? "; under way: " + under_way.str() : std::string());
  }

 private:
  void merge(int index, const FilmTile& t) {
    paste_tile(t, next_);
    counters_.merge(t.counters);
    per_primary_.merge(t.per_primary);
    done_[static_cast<std::size_t>(index)] = true;
    --remaining_;
  }

  /// Rank 0's own share (a thread): tiles from the queue until it is empty.
  void own_share() {
    try {
      for (;;) {
        int index = -1;
        {
          std::lock_guard<std::mutex> lock(mutex_);
          if (todo_.empty() || local_cancel_.load()) break;
          index = todo_.front();
          todo_.pop_front();
          holder_[static_cast<std::size_t>(index)] = 0;
        }
        FilmTile t = cut_tile(st_, tiles_[static_cast<std::size_t>(index)]);
        if (!render_tile_(t, s0_, s1_, &local_cancel_)) break;
        std::lock_guard<std::mutex> lock(mutex_);
        local_done_.emplace_back(index, std::move(t));
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      own_failure_ = std::current_exception();
    }
    own_running_.store(false);
  }

  /// Merges the tiles rank 0's thread finished; starts it again when a lost rank's tile went
  /// back into an emptied queue. Returns whether there was anything to do.
  bool collect_own() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (own_failure_) std::rethrow_exception(own_failure_);
    for (auto& [index, t] : local_done_) merge(index, t);
    const bool busy = !local_done_.empty();
    local_done_.clear();
    if (!own_running_.load() && !todo_.empty()) {
      own_.join();
      own_running_.store(true);
      own_ = std::thread([this] { own_share(); });
    }
    return busy;
  }

  /// Takes one message from another rank, if one is there: a result (merged unless it is of
  /// an earlier round or of a tile taken back), or a cancellation. Returns whether there was one.
  bool receive_one(Stop& stop, bool& interrupted) {
    MPI_Status status;
    int flag = 0;
    check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status), "MPI_Iprobe");
    if (!flag) return false;
    const int from = status.MPI_SOURCE;
    const std::vector<char> bytes = receive(status);
    Worker& w = g_dispatch.workers[static_cast<std::size_t>(from)];
    w.waiting = true;
    Reader in{bytes};
    if (status.MPI_TAG == kCancelled) {
      stop.signal = in.get<std::int32_t>();
      stop.signal_rank = from;
      interrupted = true;
    } else if (status.MPI_TAG == kResult) {
      const int r = in.get<std::int32_t>(), index = in.get<std::int32_t>();
      if (r == round_ && index == w.tile && !done_[static_cast<std::size_t>(index)]) {
        FilmTile t;
        t.rect = tiles_[static_cast<std::size_t>(index)];
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
      std::cerr << "amalgam: rank " << from << " answered again after it was taken as lost\n";
      w.lost = false;
    }
    return true;
  }

  /// Hands a tile to each rank waiting for one. Returns whether it handed out any.
  bool hand_out() {
    bool busy = false;
    for (int r = 1; r < world().size; ++r) {
      Worker& w = g_dispatch.workers[static_cast<std::size_t>(r)];
      if (!w.waiting) continue;
      int index = -1;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (todo_.empty()) break;
        index = todo_.front();
        todo_.pop_front();
        holder_[static_cast<std::size_t>(index)] = r;
      }
      const FilmTile prior = cut_tile(st_, tiles_[static_cast<std::size_t>(index)]);
      post(r, w, kWork, work_message(round_, index, prior, s0_, s1_));
      w.waiting = false;
      w.tile = index;
      w.since = Clock::now();
      busy = true;
    }
    return busy;
  }

  /// A rank silent with a tile for longer than the timeout: its tile goes back to the queue.
  void reclaim_silent() {
    for (int r = 1; r < world().size; ++r) {
      Worker& w = g_dispatch.workers[static_cast<std::size_t>(r)];
      if (w.tile < 0 || w.lost) continue;
      const double silent = std::chrono::duration<double>(Clock::now() - w.since).count();
      if (silent < g_dispatch.timeout) continue;
      w.lost = true;
      std::cerr << "amalgam: rank " << r << " has not returned tile "
                << describe(tiles_[static_cast<std::size_t>(w.tile)]) << " (samples " << s0_ << ".."
                << s1_ - 1 << ") in " << g_dispatch.timeout
                << " s: taken as lost; the other ranks render its tile\n";
      std::lock_guard<std::mutex> lock(mutex_);
      todo_.push_front(w.tile);
      holder_[static_cast<std::size_t>(w.tile)] = -1;
      w.tile = -1;
    }
  }

  const TileRenderer& render_tile_;
  const std::vector<TileRect>& tiles_;
  const FilmState& st_;  ///< the film before the round (each tile's prior sums)
  const int round_, s0_, s1_;
  FilmState next_;  ///< the film after this round: its pixels, tile by tile
  Counters counters_;
  CostDistribution per_primary_;
  std::vector<int> holder_;  ///< rank rendering each tile, -1: none yet (under mutex_)
  std::vector<bool> done_;
  std::size_t remaining_;
  std::deque<int> todo_;  ///< tiles not handed out (under mutex_)
  std::mutex mutex_;
  std::vector<std::pair<int, FilmTile>> local_done_;  ///< rank 0's finished tiles (under mutex_)
  std::atomic<bool> local_cancel_{false};
  std::atomic<bool> own_running_{true};
  std::exception_ptr own_failure_;  ///< under mutex_
  std::thread own_;
};

}  // namespace

Session::Session(int* argc, char*** argv) {
  if (!launched()) return;
  int provided = 0;
  // Only the main thread makes MPI calls (rank 0 renders its own tiles on another thread).
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    std::cerr << "amalgam: MPI_Init failed\n";
    std::exit(1);
  }
  world().started = true;
  // Failures come back as error codes (RuntimeError, a message) rather than ending the job
  // with MPI's own.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &world().rank);
  MPI_Comm_size(MPI_COMM_WORLD, &world().size);
}

Session::~Session() {
  if (!world().started) return;
  // An exception left a render with other ranks waiting on this one: end them all rather than
  // hang in MPI_Finalize.
  if (world().in_render && world().size > 1) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Finalize();
}

bool parallel() {
  return world().started && world().size > 1;
}
int rank() {
  return world().rank;
}
int size() {
  return world().size;
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
    if (world().rank == 0) std::rethrow_exception(failure);
    const std::string where = "rank " + std::to_string(world().rank) + " on " + host() + ": ";
    try {
      std::rethrow_exception(failure);
    } catch (const InputError& e) {
      throw InputError(where + e.what());
    } catch (const std::exception& e) {
      throw RuntimeError(where + e.what());
    }
  }
  if (worst != 0 && world().rank == 0)
    std::cerr << "amalgam: another rank failed before rendering (see its message): nothing "
                 "written\n";
  return worst;
}

std::string broadcast(const std::string& text) {
  std::uint64_t n = text.size();
  check(MPI_Bcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "MPI_Bcast");
  std::string out = world().rank == 0 ? text : std::string(n, '\0');
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
  world().in_render = true;
  g_dispatch.active = true;
  g_dispatch.timeout = timeout;
  g_dispatch.workers.assign(static_cast<std::size_t>(world().size), Worker{});
  const std::vector<TileRect> tiles = plan_tiles(o.width, o.height, world().size);
  const std::size_t pixels = static_cast<std::size_t>(o.width) * o.height;
  // The first round: about 2^16 primary rays per rank (a single process's pass for each).
  // Every round moves each pixel's running sums to a rank and back through rank 0 (about 120
  // bytes a pixel), so rounds then double while one takes less than half of round_seconds:
  // the gather becomes a small part of a long render. The image does not depend on the
  // rounds; only how much an interruption drops does.
  int per_round = samples_per_pass(std::max<std::size_t>(1, pixels / world().size));
  bool interrupted = false;
  for (int round = 0; st.spp_done < o.spp && !interrupted; ++round) {
    const int s0 = st.spp_done, s1 = std::min(o.spp, s0 + per_round);
    const auto round_start = Clock::now();
    RootRound r(render_tile, tiles, st, round, s0, s1);
    interrupted = !r.run(control, signal, stop);
    if (interrupted) {
      // The round is incomplete: dropped, as a single process drops its unfinished pass.
      stop.missing = r.missing();
      break;
    }
    r.commit(st);
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
  for (int r = 1; r < world().size; ++r) {
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
  for (int r = 1; r < world().size; ++r) {  // the stops are small: sent at once
    Worker& w = g_dispatch.workers[static_cast<std::size_t>(r)];
    if (!w.lost && w.request != MPI_REQUEST_NULL) MPI_Wait(&w.request, MPI_STATUS_IGNORE);
  }
  world().in_render = !all;
  return all;
}

void serve(const TileRenderer& render_tile, const RenderOptions& o, const std::atomic<bool>& cancel,
           const std::atomic<int>& signal) {
  world().in_render = true;
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
  world().in_render = false;
}

}  // namespace amalgam::cli::mpi

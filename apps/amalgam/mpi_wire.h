#pragma once
/// \file The wire of the MPI render (mpi_render.h): message tags and their byte layout, the
/// tiles of an image, what rank 0 knows of each rank, and the process's place in the job.
/// Internal to apps/amalgam's MPI files.

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "amalgam/render/render.h"
#include "amalgam/util/error.h"

namespace amalgam::cli::mpi::wire {

using Clock = std::chrono::steady_clock;

/// The messages. A worker sends one message (kReady, kResult or kCancelled) and waits for the
/// one answer (kWork or kStop): at most one message is ever in flight each way per worker.
enum Tag : int { kReady = 1, kResult = 2, kCancelled = 3, kWork = 4, kStop = 5 };

static_assert(std::is_trivially_copyable_v<Counters>);
static_assert(std::is_trivially_copyable_v<Vec3>);
static_assert(std::is_trivially_copyable_v<PixelAov>);

/// This process's place in the job (set once by mpi::Session).
struct World {
  bool started = false;  ///< MPI_Init was called
  int rank = 0;
  int size = 1;
  bool in_render = false;  ///< between render_root/serve/spread and release: an exception aborts
};
World& world();

/// Throws RuntimeError with MPI's message when `rc` is not MPI_SUCCESS.
void check(int rc, const char* what);

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
std::vector<char> receive(const MPI_Status& status);

/// Waits for a message from `source` (any rank: MPI_ANY_SOURCE) without spinning a core (a
/// blocking MPI_Probe busy-waits in Open MPI): probes, sleeping 100 us between tries. Returns
/// false when `deadline` passes first.
bool wait_message(int source, MPI_Status& status, Clock::time_point deadline);

void send(int to, Tag tag, const std::vector<char>& bytes);

std::vector<char> signal_message(int sig);

/// The tiles of a w x h image for `ranks` ranks: squares of 64, 32, 16 or 8 pixels, the largest
/// that gives each rank at least 4 tiles per round (a slow rank then holds the others up by at
/// most a small tile). The split does not change a byte of the image.
std::vector<TileRect> plan_tiles(int w, int h, int ranks);

std::string describe(const TileRect& r);

/// A work message: round, tile, its rectangle, the samples to add and (after the first samples)
/// the pixels' running sums.
std::vector<char> work_message(int round, int index, const FilmTile& t, int s0, int s1);

/// A result message: round, tile, counters, the cost distribution as (value, times) pairs, and
/// the pixels.
std::vector<char> result_message(int round, int index, const FilmTile& t);

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
void post(int r, Worker& w, Tag tag, std::vector<char> bytes);

}  // namespace amalgam::cli::mpi::wire

#include "mpi_wire.h"

#include <algorithm>
#include <sstream>
#include <thread>

namespace amalgam::cli::mpi::wire {

World& world() {
  static World w;
  return w;
}

void check(int rc, const char* what) {
  if (rc == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(rc, text, &len);
  throw RuntimeError(std::string("MPI: ") + what + " failed: " + std::string(text, len));
}

std::vector<char> receive(const MPI_Status& status) {
  int n = 0;
  check(MPI_Get_count(&status, MPI_BYTE, &n), "MPI_Get_count");
  std::vector<char> bytes(static_cast<std::size_t>(n));
  check(MPI_Recv(bytes.data(), n, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE),
        "MPI_Recv");
  return bytes;
}

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

void post(int r, Worker& w, Tag tag, std::vector<char> bytes) {
  check(MPI_Wait(&w.request, MPI_STATUS_IGNORE), "MPI_Wait");
  w.out = std::move(bytes);
  check(MPI_Isend(w.out.data(), static_cast<int>(w.out.size()), MPI_BYTE, r, tag, MPI_COMM_WORLD,
                  &w.request),
        "MPI_Isend");
}

}  // namespace amalgam::cli::mpi::wire

#include "amalgam/io/checkpoint.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string_view>
#include <vector>

#include "amalgam/math/random.h"
#include "amalgam/util/atomic_file.h"
#include "amalgam/util/error.h"
#include "amalgam/util/file_kind.h"

namespace amalgam {
namespace {

/// The format version is the last part of the magic; version 3 added the auxiliary outputs
/// (PixelAov) after the tests per pixel; version 4 the `reached` counters of Counters; version 5
/// the cell tests of volumetric amalgams (ObjectKind::kCell).
constexpr char kMagicPrefix[] = "AMALGAM-CHECKPOINT-";
constexpr char kMagic[] = "AMALGAM-CHECKPOINT-5";

}  // namespace

/// 64-bit words through hash_combine, so any flipped bit changes it (with probability
/// 1 - 2^-64).
std::uint64_t checkpoint_checksum(std::string_view bytes) {
  std::uint64_t h = 0xc4ec4ec4ull;
  std::size_t i = 0;
  for (; i + 8 <= bytes.size(); i += 8) {
    std::uint64_t w;
    std::memcpy(&w, bytes.data() + i, 8);
    h = hash_combine(h, w);
  }
  std::uint64_t tail = bytes.size();
  for (; i < bytes.size(); ++i) tail = tail * 257 + static_cast<unsigned char>(bytes[i]);
  return hash_combine(h, tail);
}

namespace {

/// Appends raw bytes to a string reserved to the checkpoint's exact size, so the film is held
/// once more while writing, not twice or three times as a growing stream would (MemoryModel).
template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
void put_array(std::string& out, const std::vector<T>& v) {
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}
template <class T>
void get(std::istream& in, T& v) {
  in.read(reinterpret_cast<char*>(&v), sizeof v);
}

}  // namespace

void write_checkpoint(const std::string& path, const std::string& fingerprint,
                      const FilmState& st) {
  std::uint64_t distinct = 0;
  st.per_primary.for_each([&](std::uint64_t, std::uint64_t) { ++distinct; });
  std::vector<PixelAov> zero;  // a FilmState made outside render() may have no AOVs yet
  if (st.aov.size() != st.sum.size()) zero.assign(st.sum.size(), PixelAov{});
  const std::vector<PixelAov>& aov = zero.empty() ? st.aov : zero;
  std::string bytes;
  bytes.reserve(sizeof kMagic + 8 + fingerprint.size() + 3 * sizeof(int) +
                st.sum.size() * (sizeof(Vec3) + sizeof(std::uint64_t) + sizeof(PixelAov)) +
                sizeof(Counters) + 8 + distinct * 16 + 8);
  bytes.append(kMagic, sizeof kMagic);
  put(bytes, static_cast<std::uint64_t>(fingerprint.size()));
  bytes.append(fingerprint);
  put(bytes, st.width);
  put(bytes, st.height);
  put(bytes, st.spp_done);
  put_array(bytes, st.sum);
  put_array(bytes, st.tests);
  put_array(bytes, aov);
  put(bytes, st.counters);
  put(bytes, distinct);
  st.per_primary.for_each([&](std::uint64_t v, std::uint64_t c) { put(bytes, v), put(bytes, c); });
  const std::uint64_t sum = checkpoint_checksum(bytes);
  put(bytes, sum);
  write_file_atomic(path, bytes);
}

bool is_checkpoint_of(const std::string& path, const std::string& fingerprint) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) return false;
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) return false;
  std::string expect(kMagic, sizeof kMagic);
  put(expect, static_cast<std::uint64_t>(fingerprint.size()));
  expect += fingerprint;
  std::string head(expect.size(), '\0');
  std::size_t got = 0;
  while (got < head.size()) {
    const ssize_t r = ::pread(fd, head.data() + got, head.size() - got, static_cast<off_t>(got));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    got += static_cast<std::size_t>(r);
  }
  return head == expect;
}

namespace {

/// Throws the InputError for a file whose first bytes, `head`, are not this format's magic.
[[noreturn]] void refuse_magic(const std::string& path, const std::string& head) {
  if (head.compare(0, sizeof kMagicPrefix - 1, kMagicPrefix) != 0)
    throw InputError(path + ": not an amalgam checkpoint");
  // "AMALGAM-CHECKPOINT-<digits>\0" is a checkpoint of another format; anything else there
  // (a flipped byte) is damage, whatever digits it starts with.
  std::size_t i = sizeof kMagicPrefix - 1;
  std::string format;
  while (i < head.size() && format.size() < 4 && std::isdigit(static_cast<unsigned char>(head[i])))
    format += head[i++];
  if (format.empty() || format == kMagic + sizeof kMagicPrefix - 1 || i >= head.size() ||
      head[i] != '\0')
    throw InputError(path +
                     ": checkpoint is damaged (its header is not that of any format): "
                     "delete it to start over");
  throw InputError(path + ": checkpoint of another amalgam version (format " + format +
                   ", this one reads format 5): delete it and render again");
}

}  // namespace

FilmState read_checkpoint(const std::string& path, const std::string& fingerprint,
                          FilmSize film_size) {
  // Opened without waiting (a FIFO would wait for a writer) and refused unless a regular file:
  // a device or a FIFO may never end, and only a file has a size to check the header against.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) throw InputError(path + ": cannot open checkpoint: " + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat info {};
  if (::fstat(fd, &info) != 0)
    throw InputError(path + ": cannot open checkpoint: " + std::strerror(errno));
  if (!S_ISREG(info.st_mode))
    throw InputError(path + ": is " + special_file_kind(info.st_mode) +
                     ", not a checkpoint file (resume reads only a regular file amalgam wrote)");
  const auto size = static_cast<std::uint64_t>(info.st_size);
  // Reads `n` bytes at `offset`: false when the file ends before them.
  const auto read_at = [&](std::uint64_t offset, void* data, std::size_t n) {
    char* p = static_cast<char*>(data);
    while (n > 0) {
      const ssize_t r = ::pread(fd, p, n, static_cast<off_t>(offset));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0) throw InputError(path + ": cannot read checkpoint: " + std::strerror(errno));
      if (r == 0) return false;
      p += r, offset += static_cast<std::uint64_t>(r), n -= static_cast<std::size_t>(r);
    }
    return true;
  };

  // The header: the magic with the format version, then the fingerprint's length.
  char magic[sizeof kMagic] = {};
  const bool whole_magic = read_at(0, magic, sizeof magic);
  if (!whole_magic || std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    refuse_magic(
        path, std::string(
                  magic, whole_magic ? sizeof magic : std::min<std::uint64_t>(size, sizeof magic)));
  // Every size the header declares is checked against the file's before it is read, so no more
  // than the checkpoint's own bytes (the film of this render, checked by the fingerprint) are
  // ever held.
  const std::string short_file =
      path + ": checkpoint is truncated or damaged (its header declares more than its " +
      std::to_string(size) + " bytes): delete it to start over";
  std::uint64_t fp_size = 0;
  if (!read_at(sizeof kMagic, &fp_size, sizeof fp_size)) throw InputError(short_file);
  if (fp_size > (1u << 20)) throw InputError(path + ": corrupt checkpoint header");
  // The settings and the film the header declares are this render's, before the body is read.
  std::string fp(static_cast<std::size_t>(fp_size), '\0');
  if (!read_at(sizeof kMagic + sizeof fp_size, fp.data(), fp.size())) throw InputError(short_file);
  if (fp != fingerprint)
    throw InputError(path + ": checkpoint was written for different settings (" +
                     one_line(fp, 300) + ")");
  const std::uint64_t dims_at = sizeof kMagic + sizeof fp_size + fp_size;
  int dims[3] = {};
  if (!read_at(dims_at, dims, sizeof dims)) throw InputError(short_file);
  if (dims[0] < 1 || dims[1] < 1 || static_cast<std::uint64_t>(dims[0]) * dims[1] > (1ull << 32))
    throw InputError(path + ": corrupt checkpoint header");
  if (film_size.width > 0 && (dims[0] != film_size.width || dims[1] != film_size.height))
    throw InputError(path + ": checkpoint declares a " + std::to_string(dims[0]) + "x" +
                     std::to_string(dims[1]) + " film, this render's is " +
                     std::to_string(film_size.width) + "x" + std::to_string(film_size.height) +
                     ": it is damaged; delete it to start over");
  const std::uint64_t film = static_cast<std::uint64_t>(dims[0]) * dims[1];
  const std::uint64_t distinct_at =
      dims_at + sizeof dims + film * (sizeof(Vec3) + sizeof(std::uint64_t) + sizeof(PixelAov)) +
      sizeof(Counters);
  std::uint64_t pairs = 0;
  if (!read_at(distinct_at, &pairs, sizeof pairs)) throw InputError(short_file);
  const std::uint64_t pairs_at = distinct_at + sizeof pairs;
  if (pairs > (size - std::min(size, pairs_at)) / 16) throw InputError(short_file);
  const std::uint64_t declared = pairs_at + pairs * 16 + sizeof(std::uint64_t);
  if (declared != size)
    throw InputError(path + ": checkpoint is truncated or damaged (its header declares " +
                     std::to_string(declared) + " bytes, the file has " + std::to_string(size) +
                     "): delete it to start over");
  std::string bytes(static_cast<std::size_t>(declared), '\0');
  if (!read_at(0, bytes.data(), bytes.size())) throw InputError(short_file);

  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + bytes.size() - sizeof stored, sizeof stored);
  bytes.resize(bytes.size() - sizeof stored);
  if (checkpoint_checksum(bytes) != stored)
    throw InputError(path + ": checkpoint is damaged (checksum mismatch): delete it to start over");
  std::istringstream in(bytes, std::ios::binary);
  in.seekg(sizeof kMagic);
  std::uint64_t len = 0;
  get(in, len);
  if (!in || len > (1u << 20)) throw InputError(path + ": corrupt checkpoint header");
  in.seekg(static_cast<std::streamoff>(len), std::ios::cur);  // checked above
  FilmState st;
  get(in, st.width);
  get(in, st.height);
  get(in, st.spp_done);
  if (!in || st.width < 1 || st.height < 1 || st.spp_done < 0 ||
      static_cast<std::uint64_t>(st.width) * st.height > (1ull << 32))
    throw InputError(path + ": corrupt checkpoint header");
  const std::size_t pixels = static_cast<std::size_t>(st.width) * st.height;
  st.sum.resize(pixels);
  st.tests.resize(pixels);
  st.aov.resize(pixels);
  in.read(reinterpret_cast<char*>(st.sum.data()),
          static_cast<std::streamsize>(pixels * sizeof(Vec3)));
  in.read(reinterpret_cast<char*>(st.tests.data()),
          static_cast<std::streamsize>(pixels * sizeof(std::uint64_t)));
  in.read(reinterpret_cast<char*>(st.aov.data()),
          static_cast<std::streamsize>(pixels * sizeof(PixelAov)));
  get(in, st.counters);
  std::uint64_t distinct = 0;
  get(in, distinct);
  for (std::uint64_t i = 0; in && i < distinct; ++i) {
    std::uint64_t v = 0, c = 0;
    get(in, v), get(in, c);
    st.per_primary.add(v, c);
  }
  if (!in || in.peek() != std::char_traits<char>::eof())
    throw InputError(path + ": checkpoint is truncated or has trailing data");
  for (const Vec3& v : st.sum)
    if (!is_finite(v)) throw InputError(path + ": checkpoint holds a non-finite pixel sum");
  const auto spp = static_cast<std::uint64_t>(st.spp_done);
  for (const PixelAov& a : st.aov)
    if (!is_finite(a.normal) || !is_finite(a.albedo) || !std::isfinite(a.depth) ||
        std::uint64_t{a.amalgams} + a.primitives > spp)
      throw InputError(path + ": checkpoint holds an invalid auxiliary pixel sum");
  return st;
}

}  // namespace amalgam

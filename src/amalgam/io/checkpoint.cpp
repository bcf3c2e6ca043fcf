#include "amalgam/io/checkpoint.h"

#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string_view>
#include <vector>

#include "amalgam/math/random.h"
#include "amalgam/util/atomic_file.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

/// The format version is the last part of the magic; version 3 added the auxiliary outputs
/// (PixelAov) after the tests per pixel; version 4 the `reached` counters of Counters; version 5
/// the cell tests of volumetric amalgams (ObjectKind::kCell).
constexpr char kMagicPrefix[] = "AMALGAM-CHECKPOINT-";
constexpr char kMagic[] = "AMALGAM-CHECKPOINT-5";

/// Checksum of a checkpoint's bytes (everything before the checksum itself): 64-bit words
/// through hash_combine, so any flipped bit changes it (with probability 1 - 2^-64).
std::uint64_t checksum(std::string_view bytes) {
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
  const std::uint64_t sum = checksum(bytes);
  put(bytes, sum);
  write_file_atomic(path, bytes);
}

FilmState read_checkpoint(const std::string& path, const std::string& fingerprint) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open checkpoint: " + std::strerror(errno));
  std::string bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    if (bytes.compare(0, sizeof kMagicPrefix - 1, kMagicPrefix) == 0) {
      std::string format;
      for (std::size_t i = sizeof kMagicPrefix - 1;
           i < bytes.size() && format.size() < 4 &&
           std::isdigit(static_cast<unsigned char>(bytes[i]));
           ++i)
        format += bytes[i];
      throw InputError(path + ": checkpoint of another amalgam version (format " + format +
                       ", this one reads format 5): delete it and render again");
    }
    throw InputError(path + ": not an amalgam checkpoint");
  }
  std::uint64_t stored = 0;
  if (bytes.size() < sizeof kMagic + sizeof stored)
    throw InputError(path + ": checkpoint is truncated");
  std::memcpy(&stored, bytes.data() + bytes.size() - sizeof stored, sizeof stored);
  bytes.resize(bytes.size() - sizeof stored);
  if (checksum(bytes) != stored)
    throw InputError(path + ": checkpoint is damaged (checksum mismatch): delete it to start over");
  std::istringstream in(bytes, std::ios::binary);
  in.seekg(sizeof kMagic);
  std::uint64_t len = 0;
  get(in, len);
  if (!in || len > (1u << 20)) throw InputError(path + ": corrupt checkpoint header");
  std::string fp(len, '\0');
  in.read(fp.data(), static_cast<std::streamsize>(len));
  if (fp != fingerprint)
    throw InputError(path + ": checkpoint was written for different settings (" + fp + ")");
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

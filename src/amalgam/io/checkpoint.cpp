#include "amalgam/io/checkpoint.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string_view>

#include "amalgam/math/random.h"
#include "amalgam/util/atomic_file.h"
#include "amalgam/util/error.h"

namespace amalgam {
namespace {

constexpr char kMagic[] = "AMALGAM-CHECKPOINT-2";

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

template <class T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
void get(std::istream& in, T& v) {
  in.read(reinterpret_cast<char*>(&v), sizeof v);
}

}  // namespace

void write_checkpoint(const std::string& path, const std::string& fingerprint,
                      const FilmState& st) {
  std::ostringstream out(std::ios::binary);
  out.write(kMagic, sizeof kMagic);
  put(out, static_cast<std::uint64_t>(fingerprint.size()));
  out.write(fingerprint.data(), static_cast<std::streamsize>(fingerprint.size()));
  put(out, st.width);
  put(out, st.height);
  put(out, st.spp_done);
  out.write(reinterpret_cast<const char*>(st.sum.data()),
            static_cast<std::streamsize>(st.sum.size() * sizeof(Vec3)));
  out.write(reinterpret_cast<const char*>(st.tests.data()),
            static_cast<std::streamsize>(st.tests.size() * sizeof(std::uint64_t)));
  put(out, st.counters);
  std::uint64_t distinct = 0;
  st.per_primary.for_each([&](std::uint64_t, std::uint64_t) { ++distinct; });
  put(out, distinct);
  st.per_primary.for_each([&](std::uint64_t v, std::uint64_t c) { put(out, v), put(out, c); });
  std::string bytes = out.str();
  const std::uint64_t sum = checksum(bytes);
  bytes.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  write_file_atomic(path, bytes);
}

FilmState read_checkpoint(const std::string& path, const std::string& fingerprint) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open checkpoint: " + std::strerror(errno));
  std::string bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw InputError(path + ": not an amalgam checkpoint (or one of an older version)");
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
  in.read(reinterpret_cast<char*>(st.sum.data()),
          static_cast<std::streamsize>(pixels * sizeof(Vec3)));
  in.read(reinterpret_cast<char*>(st.tests.data()),
          static_cast<std::streamsize>(pixels * sizeof(std::uint64_t)));
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
  return st;
}

}  // namespace amalgam

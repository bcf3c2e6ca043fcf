#include "amalgam/io/import_protocol.h"

#include <type_traits>

#include "amalgam/util/fd_io.h"

namespace amalgam::import_protocol {
namespace {

static_assert(std::is_trivially_copyable_v<Primitive> && std::is_trivially_copyable_v<Surface> &&
              std::is_trivially_copyable_v<Bbox>);

/// Names the version and the raw record sizes: a helper built from other sources says so.
std::string hello() {
  return "amalgam-import protocol 1: Primitive " + std::to_string(sizeof(Primitive)) +
         ", Surface " + std::to_string(sizeof(Surface)) + ", Bbox " + std::to_string(sizeof(Bbox));
}

constexpr std::uint64_t kMaxString = std::uint64_t{1} << 24;

bool send_string(int fd, const std::string& s) {
  const std::uint64_t n = s.size();
  return write_all(fd, &n, sizeof n) && write_all(fd, s.data(), s.size());
}

bool read_string(int fd, std::string& s) {
  std::uint64_t n = 0;
  if (!read_all(fd, &n, sizeof n) || n > kMaxString) return false;
  s.resize(n);
  return read_all(fd, s.data(), n);
}

}  // namespace

bool send_mesh(int fd, const ImportedMesh& m) {
  const std::uint8_t status = 0;
  const std::uint64_t counts[4] = {m.triangles.size(), m.materials.size(), m.dropped_degenerate,
                                   m.warnings.size()};
  if (!send_string(fd, hello()) || !write_all(fd, &status, 1) ||
      !write_all(fd, counts, sizeof counts) ||
      !write_all(fd, m.triangles.data(), m.triangles.size() * sizeof(Primitive)) ||
      !write_all(fd, m.materials.data(), m.materials.size() * sizeof(Surface)) ||
      !write_all(fd, &m.bounds, sizeof m.bounds))
    return false;
  for (const std::string& w : m.warnings)
    if (!send_string(fd, w)) return false;
  return true;
}

bool send_error(int fd, const std::string& message) {
  const std::uint8_t status = 1;
  return send_string(fd, hello()) && write_all(fd, &status, 1) && send_string(fd, message);
}

Reply receive(int fd, std::uint64_t max_triangles) {
  Reply r;
  std::string their_hello;
  if (!read_string(fd, their_hello)) return r;
  if (their_hello != hello()) {
    r.kind = Reply::Kind::kIncompatible;
    r.error = std::move(their_hello);
    return r;
  }
  std::uint8_t status = 2;
  if (!read_all(fd, &status, 1)) return r;
  if (status == 1) {
    if (read_string(fd, r.error)) r.kind = Reply::Kind::kError;
    return r;
  }
  std::uint64_t counts[4] = {};
  if (status != 0 || !read_all(fd, counts, sizeof counts) || counts[0] > max_triangles ||
      counts[1] > (std::uint64_t{1} << 32) || counts[3] > kMaxString)
    return r;
  ImportedMesh& m = r.mesh;
  m.triangles.resize(counts[0]);
  m.materials.resize(counts[1]);
  m.dropped_degenerate = counts[2];
  if (!read_all(fd, m.triangles.data(), counts[0] * sizeof(Primitive)) ||
      !read_all(fd, m.materials.data(), counts[1] * sizeof(Surface)) ||
      !read_all(fd, &m.bounds, sizeof m.bounds))
    return r;
  for (std::uint64_t i = 0; i < counts[3]; ++i) {
    std::string w;
    if (!read_string(fd, w)) return r;
    m.warnings.push_back(std::move(w));
  }
  r.kind = Reply::Kind::kMesh;
  return r;
}

}  // namespace amalgam::import_protocol

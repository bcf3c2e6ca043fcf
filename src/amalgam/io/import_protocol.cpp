#include "amalgam/io/import_protocol.h"

#include <type_traits>

#include "amalgam/util/fd_io.h"

namespace amalgam::import_protocol {
namespace {

static_assert(std::is_trivially_copyable_v<Primitive> && std::is_trivially_copyable_v<Surface> &&
              std::is_trivially_copyable_v<Bbox> && std::is_trivially_copyable_v<TexCoords> &&
              std::is_trivially_copyable_v<Camera> && std::is_trivially_copyable_v<Light>);

/// Names the version and the raw record sizes: a helper built from other sources says so.
std::string hello() {
  return "amalgam-import protocol 4: Primitive " + std::to_string(sizeof(Primitive)) +
         ", Surface " + std::to_string(sizeof(Surface)) + ", Bbox " + std::to_string(sizeof(Bbox)) +
         ", TexCoords " + std::to_string(sizeof(TexCoords)) + ", Camera " +
         std::to_string(sizeof(Camera)) + ", Light " + std::to_string(sizeof(Light)) +
         ", VertexNormals " + std::to_string(sizeof(VertexNormals));
}

constexpr std::uint64_t kMaxString = std::uint64_t{1} << 24;
constexpr int kCounts = 11;

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
  const std::uint64_t counts[kCounts] = {
      m.triangles.size(), m.materials.size(),     m.dropped_degenerate, m.warnings.size(),
      m.uvs.size(),       m.textures.size(),      m.cameras.size(),     m.lights.size(),
      m.dropped.size(),   m.files_read.size(), m.normals.size()};
  if (!send_string(fd, hello()) || !write_all(fd, &status, 1) ||
      !write_all(fd, counts, sizeof counts) ||
      !write_all(fd, m.triangles.data(), m.triangles.size() * sizeof(Primitive)) ||
      !write_all(fd, m.materials.data(), m.materials.size() * sizeof(Surface)) ||
      !write_all(fd, m.uvs.data(), m.uvs.size() * sizeof(TexCoords)) ||
      !write_all(fd, m.normals.data(), m.normals.size() * sizeof(VertexNormals)) ||
      !write_all(fd, m.lights.data(), m.lights.size() * sizeof(Light)) ||
      !write_all(fd, &m.bounds, sizeof m.bounds))
    return false;
  for (const Texture& t : m.textures) {
    const std::uint32_t size[2] = {t.width, t.height};
    const std::uint8_t wrap[2] = {static_cast<std::uint8_t>(t.wrap_u),
                                  static_cast<std::uint8_t>(t.wrap_v)};
    if (!write_all(fd, size, sizeof size) || !write_all(fd, wrap, sizeof wrap) ||
        !write_all(fd, t.texels.data(), t.texels.size()))
      return false;
  }
  for (const NamedCamera& c : m.cameras)
    if (!send_string(fd, c.name) || !write_all(fd, &c.camera, sizeof c.camera)) return false;
  for (const auto* lines : {&m.warnings, &m.dropped, &m.files_read})
    for (const std::string& w : *lines)
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
  std::uint64_t counts[kCounts] = {};
  if (status != 0 || !read_all(fd, counts, sizeof counts) || counts[0] > max_triangles ||
      counts[1] > (std::uint64_t{1} << 32) || counts[3] > kMaxString ||
      (counts[4] != 0 && counts[4] != counts[0]) || counts[5] > kMaxTextures ||
      counts[6] > kMaxString || counts[7] > kMaxString || counts[8] > kMaxString ||
      counts[9] > kMaxTextures || (counts[10] != 0 && counts[10] != counts[0]))
    return r;
  ImportedMesh& m = r.mesh;
  m.triangles.resize(counts[0]);
  m.materials.resize(counts[1]);
  m.dropped_degenerate = counts[2];
  m.uvs.resize(counts[4]);
  m.normals.resize(counts[10]);
  m.lights.resize(counts[7]);
  if (!read_all(fd, m.triangles.data(), counts[0] * sizeof(Primitive)) ||
      !read_all(fd, m.materials.data(), counts[1] * sizeof(Surface)) ||
      !read_all(fd, m.uvs.data(), counts[4] * sizeof(TexCoords)) ||
      !read_all(fd, m.normals.data(), counts[10] * sizeof(VertexNormals)) ||
      !read_all(fd, m.lights.data(), counts[7] * sizeof(Light)) ||
      !read_all(fd, &m.bounds, sizeof m.bounds))
    return r;
  std::uint64_t texel_bytes = 0;
  for (std::uint64_t i = 0; i < counts[5]; ++i) {
    std::uint32_t size[2];
    std::uint8_t wrap[2];
    if (!read_all(fd, size, sizeof size) || size[0] == 0 || size[1] == 0 ||
        size[0] > kMaxTextureSide || size[1] > kMaxTextureSide ||
        !read_all(fd, wrap, sizeof wrap) || wrap[0] > 2 || wrap[1] > 2)
      return r;
    Texture t;
    t.width = size[0], t.height = size[1];
    t.wrap_u = static_cast<Wrap>(wrap[0]), t.wrap_v = static_cast<Wrap>(wrap[1]);
    const std::uint64_t bytes = std::uint64_t{3} * size[0] * size[1];
    texel_bytes += bytes;
    if (texel_bytes > kMaxTextureBytes) return r;
    t.texels.resize(bytes);
    if (!read_all(fd, t.texels.data(), bytes)) return r;
    finish_texture(t);
    m.textures.push_back(std::move(t));
  }
  for (std::uint64_t i = 0; i < counts[6]; ++i) {
    NamedCamera c;
    if (!read_string(fd, c.name) || !read_all(fd, &c.camera, sizeof c.camera)) return r;
    m.cameras.push_back(std::move(c));
  }
  for (std::uint64_t i = 0; i < counts[3] + counts[8] + counts[9]; ++i) {
    std::string w;
    if (!read_string(fd, w)) return r;
    (i < counts[3]               ? m.warnings
     : i < counts[3] + counts[8] ? m.dropped
                                 : m.files_read)
        .push_back(std::move(w));
  }
  // Texture indices the receiver trusts (ExplicitHierarchy::surface_at checks them again).
  for (Surface& s : m.materials)
    if (s.texture >= static_cast<std::int64_t>(m.textures.size()) || s.texture < -1) return r;
  r.kind = Reply::Kind::kMesh;
  return r;
}

}  // namespace amalgam::import_protocol

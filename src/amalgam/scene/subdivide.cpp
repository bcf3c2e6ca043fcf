#include "amalgam/scene/subdivide.h"

#include <array>
#include <utility>

namespace amalgam {
namespace {

/// The one midpoint split of the three subdivisions: corner values 0, 1, 2 of each triangle
/// (`get(t, k)`, a Vec3) and their edge midpoints 3, 4, 5 (ab, bc, ca) make four triangles,
/// in the same order for triangles and every per-corner attribute (`make(t, x, y, z)`).
template <class T, class Get, class Make>
std::vector<T> split_levels(const std::vector<T>& in, int levels, Get get, Make make) {
  std::vector<T> out = in;
  for (int l = 0; l < levels; ++l) {
    std::vector<T> next;
    next.reserve(out.size() * 4);
    for (const T& t : out) {
      Vec3 v[6] = {get(t, 0), get(t, 1), get(t, 2)};
      for (int k = 0; k < 3; ++k) v[3 + k] = (v[k] + v[(k + 1) % 3]) * 0.5f;
      for (const auto& tri :
           {std::array{0, 3, 5}, std::array{3, 1, 4}, std::array{5, 4, 2}, std::array{3, 4, 5}})
        next.push_back(make(t, v[tri[0]], v[tri[1]], v[tri[2]]));
    }
    out = std::move(next);
  }
  return out;
}

}  // namespace

std::vector<Primitive> subdivide(const std::vector<Primitive>& triangles, int levels) {
  return split_levels(
      triangles, levels,
      [](const Primitive& t, int k) { return k == 0   ? t.a
                                             : k == 1 ? t.b
                                                      : t.c; },
      [](const Primitive& t, Vec3 a, Vec3 b, Vec3 c) {
        return Primitive::triangle(a, b, c, t.material);
      });
}

std::vector<TexCoords> subdivide(const std::vector<TexCoords>& uvs, int levels) {
  return split_levels(
      uvs, levels,
      [](const TexCoords& t, int k) {
        return Vec3{t.u[k], t.v[k], 0.0f};
      },
      [](const TexCoords&, Vec3 a, Vec3 b, Vec3 c) {
        TexCoords out;
        const Vec3 corner[3] = {a, b, c};
        for (int k = 0; k < 3; ++k) out.u[k] = corner[k].x, out.v[k] = corner[k].y;
        return out;
      });
}

std::vector<VertexNormals> subdivide(const std::vector<VertexNormals>& normals, int levels) {
  return split_levels(
      normals, levels, [](const VertexNormals& t, int k) { return t.n[k]; },
      [](const VertexNormals&, Vec3 a, Vec3 b, Vec3 c) {
        return VertexNormals{{a, b, c}};
      });
}

}  // namespace amalgam

#include "amalgam/scene/subdivide.h"

#include <array>
#include <utility>

namespace amalgam {

std::vector<Primitive> subdivide(const std::vector<Primitive>& triangles, int levels) {
  std::vector<Primitive> out = triangles;
  for (int l = 0; l < levels; ++l) {
    std::vector<Primitive> next;
    next.reserve(out.size() * 4);
    for (const Primitive& t : out) {
      const Vec3 ab = (t.a + t.b) * 0.5f, bc = (t.b + t.c) * 0.5f, ca = (t.c + t.a) * 0.5f;
      next.push_back(Primitive::triangle(t.a, ab, ca, t.material));
      next.push_back(Primitive::triangle(ab, t.b, bc, t.material));
      next.push_back(Primitive::triangle(ca, bc, t.c, t.material));
      next.push_back(Primitive::triangle(ab, bc, ca, t.material));
    }
    out = std::move(next);
  }
  return out;
}

std::vector<TexCoords> subdivide(const std::vector<TexCoords>& uvs, int levels) {
  std::vector<TexCoords> out = uvs;
  for (int l = 0; l < levels; ++l) {
    std::vector<TexCoords> next;
    next.reserve(out.size() * 4);
    for (const TexCoords& t : out) {
      // Vertices 0, 1, 2 = a, b, c; 3, 4, 5 = the midpoints ab, bc, ca.
      float u[6] = {t.u[0], t.u[1], t.u[2]}, v[6] = {t.v[0], t.v[1], t.v[2]};
      for (int k = 0; k < 3; ++k) {
        u[3 + k] = (t.u[k] + t.u[(k + 1) % 3]) * 0.5f;
        v[3 + k] = (t.v[k] + t.v[(k + 1) % 3]) * 0.5f;
      }
      for (const auto& tri :
           {std::array{0, 3, 5}, std::array{3, 1, 4}, std::array{5, 4, 2}, std::array{3, 4, 5}}) {
        TexCoords c;
        for (int k = 0; k < 3; ++k) c.u[k] = u[tri[k]], c.v[k] = v[tri[k]];
        next.push_back(c);
      }
    }
    out = std::move(next);
  }
  return out;
}

std::vector<VertexNormals> subdivide(const std::vector<VertexNormals>& normals, int levels) {
  std::vector<VertexNormals> out = normals;
  for (int l = 0; l < levels; ++l) {
    std::vector<VertexNormals> next;
    next.reserve(out.size() * 4);
    for (const VertexNormals& t : out) {
      Vec3 n[6] = {t.n[0], t.n[1], t.n[2]};  // as for the coordinates above
      for (int k = 0; k < 3; ++k) n[3 + k] = (t.n[k] + t.n[(k + 1) % 3]) * 0.5f;
      for (const auto& tri :
           {std::array{0, 3, 5}, std::array{3, 1, 4}, std::array{5, 4, 2}, std::array{3, 4, 5}}) {
        VertexNormals c;
        for (int k = 0; k < 3; ++k) c.n[k] = n[tri[k]];
        next.push_back(c);
      }
    }
    out = std::move(next);
  }
  return out;
}

}  // namespace amalgam

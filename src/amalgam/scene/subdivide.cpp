#include "amalgam/scene/subdivide.h"

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

}  // namespace amalgam

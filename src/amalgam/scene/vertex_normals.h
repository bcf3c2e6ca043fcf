#pragma once
/// \file Vertex normals of a triangle (smooth shading): the normals a mesh file gives at a
/// triangle's three vertices, interpolated across it at a hit with the hit's barycentrics.

#include <cmath>

#include "amalgam/math/vec.h"

namespace amalgam {

/// The normals at one triangle's vertices a, b, c (any length: they are interpolated, then
/// normalised), or all zero when the file gives none for this triangle (it is then shaded with
/// its geometric normal, as every triangle of a mesh without normals is).
struct VertexNormals {
  Vec3 n[3] = {};
  bool present() const { return !(n[0] == Vec3{} && n[1] == Vec3{} && n[2] == Vec3{}); }
};

/// The unit normal at the point with barycentric weights (1 - b1 - b2, b1, b2), or the zero
/// vector when `v` has no normals or they cancel there (the caller then shades with the
/// geometric normal).
inline Vec3 interpolate(const VertexNormals& v, float b1, float b2) {
  const Vec3 s = v.n[0] * (1.0f - b1 - b2) + v.n[1] * b1 + v.n[2] * b2;
  const float l2 = dot(s, s);
  if (!(l2 > 1e-30f) || !std::isfinite(l2)) return {};
  return s / std::sqrt(l2);
}

/// The normals of `v` mapped by the rows of M^-T (`rows[i]` . n is component i), as normals
/// transform under the affine map M.
inline VertexNormals transform(const VertexNormals& v, const Vec3 rows[3]) {
  VertexNormals out;
  for (int k = 0; k < 3; ++k)
    out.n[k] = {dot(rows[0], v.n[k]), dot(rows[1], v.n[k]), dot(rows[2], v.n[k])};
  return out;
}

}  // namespace amalgam

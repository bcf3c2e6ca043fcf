#pragma once
/// \file Directions binned on an octahedral map (Engelhardt & Dachsbacher 2008; Cigolle et al.
/// 2014, "A Survey of Efficient Representations for Independent Unit Vectors"): the sphere
/// folded onto the square [0, 1]^2, cut into res x res bins of nearly equal solid angle. The
/// cells of a volumetric amalgam (cells.h) keep their coverage per direction bin and their
/// normal distribution as a histogram over such bins.

#include <algorithm>
#include <cmath>

#include "amalgam/math/vec.h"

namespace amalgam {

/// The point of [0, 1]^2 that unit direction `d` maps to.
inline void octahedral_uv(Vec3 d, float& u, float& v) {
  const float s = std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z);
  float x = d.x / s, y = d.y / s;
  if (d.z < 0.0f) {
    const float fx = (1.0f - std::fabs(y)) * (x >= 0.0f ? 1.0f : -1.0f);
    const float fy = (1.0f - std::fabs(x)) * (y >= 0.0f ? 1.0f : -1.0f);
    x = fx, y = fy;
  }
  u = 0.5f * (x + 1.0f);
  v = 0.5f * (y + 1.0f);
}

/// The unit direction at point (u, v) of [0, 1]^2 (the inverse of octahedral_uv).
inline Vec3 octahedral_dir(float u, float v) {
  const float x = 2.0f * u - 1.0f, y = 2.0f * v - 1.0f;
  const float z = 1.0f - std::fabs(x) - std::fabs(y);
  Vec3 d{x, y, z};
  if (z < 0.0f) {
    d.x = (1.0f - std::fabs(y)) * (x >= 0.0f ? 1.0f : -1.0f);
    d.y = (1.0f - std::fabs(x)) * (y >= 0.0f ? 1.0f : -1.0f);
  }
  return normalize(d);
}

/// The direction at the centre of bin `b` (row-major, b = j * res + i) of a res x res map.
inline Vec3 octahedral_bin_dir(int b, int res) {
  const int i = b % res, j = b / res;
  return octahedral_dir((static_cast<float>(i) + 0.5f) / static_cast<float>(res),
                        (static_cast<float>(j) + 0.5f) / static_cast<float>(res));
}

/// The bin of a res x res map that unit direction `d` falls in.
inline int octahedral_bin(Vec3 d, int res) {
  float u, v;
  octahedral_uv(d, u, v);
  const int i = std::clamp(static_cast<int>(u * static_cast<float>(res)), 0, res - 1);
  const int j = std::clamp(static_cast<int>(v * static_cast<float>(res)), 0, res - 1);
  return j * res + i;
}

/// Bilinear interpolation weights of direction `d` over the four bin centres around it. Beyond
/// the outermost centres the map continues across its border as the sphere does: the square's
/// edges fold onto themselves (u and 1 - u on the edges v = 0 and v = 1 are one direction, and
/// likewise v and 1 - v on u = 0 and u = 1), so the bin one step beyond edge v = 0 at column i
/// is bin (res - 1 - i, 0), and a corner's diagonal neighbour is the opposite corner. Clamping
/// there instead would give every direction near a fold the bins of one side, half a bin away.
struct OctahedralLerp {
  int bin[4];
  float w[4];
  /// The projected area along d of the cells of the grid it is for, over its largest
  /// (CellGrid::lerp sets it; 1 from `of`).
  float norm = 1.0f;

  static OctahedralLerp of(Vec3 d, int res) {
    float u, v;
    octahedral_uv(d, u, v);
    const float fr = static_cast<float>(res);
    const float x = u * fr - 0.5f, y = v * fr - 0.5f;  // in bin centres, in (-0.5, res - 0.5)
    const int i0 = static_cast<int>(std::floor(x)), j0 = static_cast<int>(std::floor(y));
    const float fx = x - static_cast<float>(i0), fy = y - static_cast<float>(j0);
    OctahedralLerp l;
    const int is[2] = {i0, i0 + 1}, js[2] = {j0, j0 + 1};
    for (int b = 0; b < 4; ++b) {
      int i = is[b & 1], j = js[b >> 1];
      // Across an edge: mirror the other coordinate (a corner's neighbour: both).
      if (i < 0 || i >= res) i = i < 0 ? 0 : res - 1, j = res - 1 - j;
      if (j < 0 || j >= res) j = j < 0 ? 0 : res - 1, i = res - 1 - i;
      l.bin[b] = std::clamp(j, 0, res - 1) * res + std::clamp(i, 0, res - 1);
      l.w[b] = ((b & 1) ? fx : 1.0f - fx) * ((b >> 1) ? fy : 1.0f - fy);
    }
    return l;
  }
};

}  // namespace amalgam

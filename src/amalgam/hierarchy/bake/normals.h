#pragma once
/// \file Orientation tensors of the normals a bake sees: their sum, their dominant axis (the
/// shading normal of a flat amalgam) and their transformation into an instance's world.

#include "amalgam/math/vec.h"

namespace amalgam {

/// Symmetric 3x3 tensor sum w n n^T, stored xx, yy, zz, xy, yz, zx.
struct NormalTensor {
  float v[6]{};
  void add(Vec3 n, float w) {
    v[0] += w * n.x * n.x, v[1] += w * n.y * n.y, v[2] += w * n.z * n.z;
    v[3] += w * n.x * n.y, v[4] += w * n.y * n.z, v[5] += w * n.z * n.x;
  }
  void add(const NormalTensor& o, float w) {
    for (int i = 0; i < 6; ++i) v[i] += w * o.v[i];
  }
  void scale(float s) {
    for (float& x : v) x *= s;
  }
  float trace() const { return v[0] + v[1] + v[2]; }
  Vec3 apply(Vec3 x) const {
    return {v[0] * x.x + v[3] * x.y + v[5] * x.z, v[3] * x.x + v[1] * x.y + v[4] * x.z,
            v[5] * x.x + v[4] * x.y + v[2] * x.z};
  }
};

/// Largest eigenvalue / trace above which the contents count as flat.
inline constexpr float kPlanarity = 0.6f;

/// The dominant normal axis of `t` (unit length), or zero when `t` is not planar enough.
Vec3 dominant_normal(const NormalTensor& t);

/// M t M^T with the rows of M given as three vectors, then renormalised to the same trace
/// (the tensor of the normals transformed by M, M being a normal matrix).
NormalTensor transform_tensor(const NormalTensor& t, const Vec3 rows[3]);

}  // namespace amalgam

#include "amalgam/hierarchy/bake/normals.h"

namespace amalgam {

Vec3 dominant_normal(const NormalTensor& t) {
  const float tr = t.trace();
  if (!(tr > 0.0f)) return {};
  // Power iteration from the axis with the largest diagonal entry.
  int a = 0;
  for (int i = 1; i < 3; ++i)
    if (t.v[i] > t.v[a]) a = i;
  Vec3 x{};
  x[a] = 1.0f;
  float lambda = 0.0f;
  for (int it = 0; it < 24; ++it) {
    const Vec3 y = t.apply(x);
    const float len = length(y);
    if (!(len > 0.0f)) return {};
    const Vec3 next = y / len;
    lambda = len;
    // A fixed point of the float iteration stays one: stopping there returns what the
    // remaining iterations would (most nodes' tensors are nearly rank one and get there in a
    // few steps).
    if (next == x) break;
    x = next;
  }
  if (lambda < kPlanarity * tr) return {};
  return x;
}

NormalTensor transform_tensor(const NormalTensor& t, const Vec3 rows[3]) {
  // (M T M^T)_ij = row_i . (T row_j)
  const Vec3 tr[3] = {t.apply(rows[0]), t.apply(rows[1]), t.apply(rows[2])};
  NormalTensor out;
  out.v[0] = dot(rows[0], tr[0]);
  out.v[1] = dot(rows[1], tr[1]);
  out.v[2] = dot(rows[2], tr[2]);
  out.v[3] = dot(rows[0], tr[1]);
  out.v[4] = dot(rows[1], tr[2]);
  out.v[5] = dot(rows[2], tr[0]);
  const float before = t.trace(), after = out.trace();
  if (after > 0.0f) out.scale(before / after);
  return out;
}

}  // namespace amalgam

#pragma once
/// \file The one affine transform type: p -> M p + t, 3x4 row-major (column 3 is t), in the
/// precision `T`. Scene files compose transforms in double (`AffineD`); hierarchies store and
/// apply them in float (`Transform`).

#include <cmath>
#include <numbers>

#include "amalgam/math/vec.h"

namespace amalgam {

template <class T>
struct BasicTransform {
  T m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  /// M p + t, computed in T, rounded to float.
  Vec3 point(Vec3 p) const {
    Vec3 r;
    for (int i = 0; i < 3; ++i)
      r[i] = static_cast<float>(m[i][0] * p.x + m[i][1] * p.y + m[i][2] * p.z + m[i][3]);
    return r;
  }
  /// M v.
  Vec3 vector(Vec3 v) const {
    Vec3 r;
    for (int i = 0; i < 3; ++i)
      r[i] = static_cast<float>(m[i][0] * v.x + m[i][1] * v.y + m[i][2] * v.z);
    return r;
  }
  T det() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
  bool is_identity() const {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j)
        if (m[i][j] != (i == j ? T{1} : T{0})) return false;
    return true;
  }
  /// The inverse map, computed in double precision. M must be non-singular.
  BasicTransform inverse() const;

  static BasicTransform translate(Vec3 t) {
    BasicTransform a;
    a.m[0][3] = t.x, a.m[1][3] = t.y, a.m[2][3] = t.z;
    return a;
  }
  static BasicTransform scale(Vec3 s) {
    BasicTransform a;
    a.m[0][0] = s.x, a.m[1][1] = s.y, a.m[2][2] = s.z;
    return a;
  }
  /// Rotation by `deg` degrees about axis 0 (x), 1 (y) or 2 (z), right-handed.
  static BasicTransform rotate(int axis, double deg) {
    const double r = deg * std::numbers::pi / 180.0, c = std::cos(r), s = std::sin(r);
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    BasicTransform a;
    a.m[i][i] = static_cast<T>(c), a.m[i][j] = static_cast<T>(-s);
    a.m[j][i] = static_cast<T>(s), a.m[j][j] = static_cast<T>(c);
    return a;
  }
  /// The same map in precision U (each entry converted).
  template <class U>
  BasicTransform<U> as() const {
    BasicTransform<U> r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) r.m[i][j] = static_cast<U>(m[i][j]);
    return r;
  }
};

/// a * b: first b, then a.
template <class T>
BasicTransform<T> operator*(const BasicTransform<T>& a, const BasicTransform<T>& b) {
  BasicTransform<T> r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) {
      T v = j == 3 ? a.m[i][3] : T{0};
      for (int k = 0; k < 3; ++k) v += a.m[i][k] * b.m[k][j];
      r.m[i][j] = v;
    }
  return r;
}

template <class T>
BasicTransform<T> BasicTransform<T>::inverse() const {
  double a[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] = m[i][j];
  const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                     a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                     a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  double inv[3][3];
  inv[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) / det;
  inv[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / det;
  inv[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / det;
  inv[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) / det;
  inv[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / det;
  inv[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / det;
  inv[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) / det;
  inv[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / det;
  inv[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / det;
  BasicTransform r;
  for (int i = 0; i < 3; ++i) {
    double t = 0.0;
    for (int j = 0; j < 3; ++j) {
      r.m[i][j] = static_cast<T>(inv[i][j]);
      t -= inv[i][j] * m[j][3];
    }
    r.m[i][3] = static_cast<T>(t);
  }
  return r;
}

/// Stored and applied by hierarchies (instances).
using Transform = BasicTransform<float>;
/// Composed by scene files (double, rounded to Transform once).
using AffineD = BasicTransform<double>;

}  // namespace amalgam

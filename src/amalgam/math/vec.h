#pragma once
/// \file Small fixed-size vector type used everywhere (points, directions, colours).

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace amalgam {

/// A 3-vector of floats. Plain aggregate: `Vec3{1, 2, 3}`.
struct Vec3 {
  float x = 0, y = 0, z = 0;

  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

  constexpr Vec3& operator+=(const Vec3& o) {
    x += o.x, y += o.y, z += o.z;
    return *this;
  }
  constexpr Vec3& operator*=(float s) {
    x *= s, y *= s, z *= s;
    return *this;
  }
  friend constexpr bool operator==(const Vec3&, const Vec3&) = default;
};

constexpr Vec3 operator+(Vec3 a, Vec3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
constexpr Vec3 operator-(Vec3 a, Vec3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
constexpr Vec3 operator-(Vec3 a) {
  return {-a.x, -a.y, -a.z};
}
constexpr Vec3 operator*(Vec3 a, Vec3 b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
constexpr Vec3 operator*(Vec3 a, float s) {
  return {a.x * s, a.y * s, a.z * s};
}
constexpr Vec3 operator*(float s, Vec3 a) {
  return a * s;
}
constexpr Vec3 operator/(Vec3 a, float s) {
  return a * (1.0f / s);
}

constexpr float dot(Vec3 a, Vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3 a) {
  return std::sqrt(dot(a, a));
}
inline Vec3 normalize(Vec3 a) {
  return a / length(a);
}
constexpr Vec3 min(Vec3 a, Vec3 b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Vec3 max(Vec3 a, Vec3 b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
constexpr float max_component(Vec3 a) {
  return std::max(a.x, std::max(a.y, a.z));
}
inline Vec3 abs(Vec3 a) {
  return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)};
}
inline bool is_finite(Vec3 a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
/// Linear interpolation a + (b - a) t.
constexpr Vec3 lerp(Vec3 a, Vec3 b, float t) {
  return a + (b - a) * t;
}
/// Two unit vectors `s`, `t` perpendicular to unit `w` and to each other (Duff et al. 2017,
/// "Building an orthonormal basis, revisited").
inline void perpendiculars(Vec3 w, Vec3& s, Vec3& t) {
  const float sign = std::copysign(1.0f, w.z);
  const float a = -1.0f / (sign + w.z), b = w.x * w.y * a;
  s = {1.0f + sign * w.x * w.x * a, sign * b, -sign * w.x};
  t = {b, sign + w.y * w.y * a, -w.y};
}
/// Luminance of a linear-RGB colour (Rec. 709 weights).
constexpr float luminance(Vec3 c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

}  // namespace amalgam

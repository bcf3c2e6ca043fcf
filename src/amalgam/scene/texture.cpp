#include "amalgam/scene/texture.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace amalgam {
namespace {

const std::array<float, 256>& srgb_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[static_cast<std::size_t>(i)] =
          static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

/// A texture coordinate reduced to one period of its wrap mode (so that texel indices stay
/// small): [0, 1) for repeat, [0, 2) for mirror, [-1, 2] for clamp; 0 for NaN and infinities.
double reduce(float x, Wrap w) {
  if (!std::isfinite(x)) return 0.0;
  const double d = x;
  switch (w) {
    case Wrap::kRepeat:
      return d - std::floor(d);
    case Wrap::kMirror:
      return d - 2.0 * std::floor(0.5 * d);
    case Wrap::kClamp:
      break;
  }
  return std::clamp(d, -1.0, 2.0);
}

/// Texel index i (any integer) of an axis of n texels under wrap mode `w`.
std::int64_t wrap_index(std::int64_t i, std::int64_t n, Wrap w) {
  switch (w) {
    case Wrap::kRepeat:
      return (i % n + n) % n;
    case Wrap::kMirror: {
      const std::int64_t m = (i % (2 * n) + 2 * n) % (2 * n);
      return m < n ? m : 2 * n - 1 - m;
    }
    case Wrap::kClamp:
      break;
  }
  return std::clamp<std::int64_t>(i, 0, n - 1);
}

}  // namespace

float srgb_to_linear(std::uint8_t c) {
  return srgb_table()[c];
}

void finish_texture(Texture& t) {
  const auto& lut = srgb_table();
  double sum[3] = {0, 0, 0};
  const std::size_t n = static_cast<std::size_t>(t.width) * t.height;
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) sum[k] += lut[t.texels[3 * i + static_cast<std::size_t>(k)]];
  const double inv = n ? 1.0 / static_cast<double>(n) : 0.0;
  t.mean = {static_cast<float>(sum[0] * inv), static_cast<float>(sum[1] * inv),
            static_cast<float>(sum[2] * inv)};
}

Vec3 sample(const Texture& t, float u, float v) {
  const auto& lut = srgb_table();
  const auto w = static_cast<std::int64_t>(t.width), h = static_cast<std::int64_t>(t.height);
  // Texel centres at (i + 0.5) / w; image row 0 is the top, v = 0 the bottom.
  const double x = reduce(u, t.wrap_u) * static_cast<double>(w) - 0.5;
  const double y = (1.0 - reduce(v, t.wrap_v)) * static_cast<double>(h) - 0.5;
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const auto fx = static_cast<float>(x - fx0), fy = static_cast<float>(y - fy0);
  const auto ix = static_cast<std::int64_t>(fx0), iy = static_cast<std::int64_t>(fy0);
  const std::int64_t x0 = wrap_index(ix, w, t.wrap_u), x1 = wrap_index(ix + 1, w, t.wrap_u);
  const std::int64_t y0 = wrap_index(iy, h, t.wrap_v), y1 = wrap_index(iy + 1, h, t.wrap_v);
  auto texel = [&](std::int64_t i, std::int64_t j) {
    const std::uint8_t* p = &t.texels[static_cast<std::size_t>(3 * (j * w + i))];
    return Vec3{lut[p[0]], lut[p[1]], lut[p[2]]};
  };
  const Vec3 top = texel(x0, y0) * (1.0f - fx) + texel(x1, y0) * fx;
  const Vec3 bottom = texel(x0, y1) * (1.0f - fx) + texel(x1, y1) * fx;
  return top * (1.0f - fy) + bottom * fy;
}

Vec3 mean_over_triangle(const Texture& t, const TexCoords& c) {
  // Area in texels (finite coordinates only: `sample` maps the others to 0).
  const double du1 = double(c.u[1]) - c.u[0], dv1 = double(c.v[1]) - c.v[0];
  const double du2 = double(c.u[2]) - c.u[0], dv2 = double(c.v[2]) - c.v[0];
  double texels = 0.5 * std::fabs(du1 * dv2 - du2 * dv1) * t.width * t.height;
  if (!std::isfinite(texels)) texels = 0.0;
  const int n = static_cast<int>(std::clamp(std::ceil(std::sqrt(texels)), 4.0, 64.0));
  Vec3 sum{};
  const float inv = 1.0f / static_cast<float>(n);
  // Sub-triangle centroids in barycentric (b1, b2): n (n + 1) / 2 upright, n (n - 1) / 2
  // inverted, all of area 1 / n^2 of the triangle.
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      for (int up = 0; up < 2; ++up) {
        if (up == 1 && i + j > n - 2) continue;
        const float off = up ? 2.0f / 3.0f : 1.0f / 3.0f;
        float u, v;
        interpolate(c, (static_cast<float>(i) + off) * inv, (static_cast<float>(j) + off) * inv, u,
                    v);
        sum += sample(t, u, v);
      }
    }
  return sum / static_cast<float>(n * n);
}

}  // namespace amalgam

#include "amalgam/scene/sky.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "amalgam/util/error.h"

namespace amalgam {
namespace {

constexpr double kPi = std::numbers::pi;

double luminance_of(const Vec3& c) {
  return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

/// The index i with cdf[i] <= u < cdf[i + 1] among n intervals (skipping empty ones).
int find_interval(const std::vector<double>& cdf, std::size_t first, int n, double u) {
  const auto b = cdf.begin() + static_cast<std::ptrdiff_t>(first);
  const auto it = std::upper_bound(b, b + n + 1, u);
  int i = static_cast<int>(it - b) - 1;
  i = std::clamp(i, 0, n - 1);
  while (i > 0 && !(cdf[first + i + 1] > cdf[first + i])) --i;  // u at the top of an empty run
  while (i < n - 1 && !(cdf[first + i + 1] > cdf[first + i])) ++i;
  return i;
}

}  // namespace

SkyMap::SkyMap(int width, int height, std::vector<Vec3> pixels, Vec3 scale, float rotate_y_deg)
    : width_(width), height_(height), pixels_(std::move(pixels)), rotate_deg_(rotate_y_deg) {
  if (width <= 0 || height <= 0 ||
      pixels_.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    throw InputError("the sky map's size does not match its pixels");
  const double r = rotate_y_deg * kPi / 180.0;
  cos_r_ = static_cast<float>(std::cos(r)), sin_r_ = static_cast<float>(std::sin(r));
  for (Vec3& p : pixels_) {
    p = {p.x * scale.x, p.y * scale.y, p.z * scale.z};
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(p[k]) || p[k] < 0.0f)
        throw InputError("the sky map has a negative or non-finite value");
  }
  weight_.assign(pixels_.size(), 0.0);
  pixel_cdf_.assign(static_cast<std::size_t>(height) * (width + 1), 0.0);
  row_cdf_.assign(static_cast<std::size_t>(height) + 1, 0.0);
  double total = 0;
  std::vector<double> row_sum(static_cast<std::size_t>(height), 0.0);
  for (int y = 0; y < height; ++y) {
    const double s = std::sin(kPi * (y + 0.5) / height);
    double acc = 0;
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      weight_[i] = luminance_of(pixels_[i]) * s;
      acc += weight_[i];
      pixel_cdf_[static_cast<std::size_t>(y) * (width + 1) + x + 1] = acc;
    }
    row_sum[static_cast<std::size_t>(y)] = acc;
    total += acc;
  }
  if (!(total > 0)) throw InputError("the sky map has no light (all pixels black)");
  for (int y = 0; y < height; ++y) {
    const double rs = row_sum[static_cast<std::size_t>(y)];
    row_cdf_[static_cast<std::size_t>(y) + 1] = row_cdf_[static_cast<std::size_t>(y)] + rs / total;
    for (int x = 0; x <= width; ++x) {
      double& c = pixel_cdf_[static_cast<std::size_t>(y) * (width + 1) + x];
      c = rs > 0 ? c / rs : 0.0;
    }
  }
  row_cdf_.back() = 1.0;
  for (double& w : weight_) w /= total;
}

int SkyMap::pixel_of(Vec3 d) const {
  // Into the map's frame: undo the rotation about +y.
  const float x = cos_r_ * d.x - sin_r_ * d.z, z = sin_r_ * d.x + cos_r_ * d.z;
  const double theta = std::acos(std::clamp(static_cast<double>(d.y), -1.0, 1.0));
  double phi = std::atan2(static_cast<double>(x), static_cast<double>(-z));  // from -z to +x
  if (phi < 0) phi += 2 * kPi;
  const int px = std::clamp(static_cast<int>(phi / (2 * kPi) * width_), 0, width_ - 1);
  const int py = std::clamp(static_cast<int>(theta / kPi * height_), 0, height_ - 1);
  return py * width_ + px;
}

Vec3 SkyMap::radiance(Vec3 dir) const {
  return pixels_[static_cast<std::size_t>(pixel_of(dir))];
}

float SkyMap::pdf(Vec3 dir) const {
  const int i = pixel_of(dir);
  const double st = std::sqrt(std::max(0.0, 1.0 - static_cast<double>(dir.y) * dir.y));
  if (!(st > 0)) return 0.0f;
  return static_cast<float>(weight_[static_cast<std::size_t>(i)] * width_ * height_ /
                            (2 * kPi * kPi * st));
}

SkyMap::Sample SkyMap::sample(float u1, float u2) const {
  const int y = find_interval(row_cdf_, 0, height_, u1);
  const double r0 = row_cdf_[static_cast<std::size_t>(y)],
               r1 = row_cdf_[static_cast<std::size_t>(y) + 1];
  const double fy = std::clamp((u1 - r0) / (r1 - r0), 0.0, 1.0);
  const std::size_t row = static_cast<std::size_t>(y) * (width_ + 1);
  const int x = find_interval(pixel_cdf_, row, width_, u2);
  const double c0 = pixel_cdf_[row + x], c1 = pixel_cdf_[row + x + 1];
  const double fx = std::clamp((u2 - c0) / (c1 - c0), 0.0, 1.0);
  const double theta = kPi * (y + fy) / height_, phi = 2 * kPi * (x + fx) / width_;
  const double st = std::sin(theta);
  // In the map's frame, phi from -z toward +x; then the rotation about +y.
  const double mx = st * std::sin(phi), mz = -st * std::cos(phi);
  Sample s;
  s.dir = normalize(Vec3{static_cast<float>(cos_r_ * mx + sin_r_ * mz),
                         static_cast<float>(std::cos(theta)),
                         static_cast<float>(-sin_r_ * mx + cos_r_ * mz)});
  const std::size_t i = static_cast<std::size_t>(y) * width_ + x;
  s.radiance = pixels_[i];
  s.pdf = st > 0 ? static_cast<float>(weight_[i] * width_ * height_ / (2 * kPi * kPi * st)) : 0.0f;
  return s;
}

}  // namespace amalgam

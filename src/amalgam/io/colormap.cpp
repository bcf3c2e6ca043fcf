#include "amalgam/io/colormap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "amalgam/io/srgb.h"

namespace amalgam {
namespace {

/// The viridis colour map (van der Walt & Smith, released CC0 with matplotlib), sampled at
/// t = k / 32 in sRGB; linear interpolation between samples stays within 2/255 of the full
/// 256-entry table.
constexpr std::array<std::array<float, 3>, 33> kViridisSrgb = {{
    {0.2670f, 0.0049f, 0.3294f}, {0.2770f, 0.0502f, 0.3755f}, {0.2823f, 0.0946f, 0.4170f},
    {0.2829f, 0.1354f, 0.4530f}, {0.2789f, 0.1749f, 0.4830f}, {0.2708f, 0.2133f, 0.5066f},
    {0.2593f, 0.2507f, 0.5244f}, {0.2454f, 0.2867f, 0.5370f}, {0.2302f, 0.3213f, 0.5455f},
    {0.2148f, 0.3545f, 0.5510f}, {0.2000f, 0.3864f, 0.5545f}, {0.1861f, 0.4173f, 0.5567f},
    {0.1733f, 0.4474f, 0.5579f}, {0.1613f, 0.4770f, 0.5581f}, {0.1497f, 0.5064f, 0.5573f},
    {0.1384f, 0.5358f, 0.5551f}, {0.1281f, 0.5651f, 0.5509f}, {0.1209f, 0.5945f, 0.5442f},
    {0.1203f, 0.6238f, 0.5343f}, {0.1310f, 0.6529f, 0.5208f}, {0.1554f, 0.6815f, 0.5032f},
    {0.1930f, 0.7096f, 0.4812f}, {0.2415f, 0.7366f, 0.4545f}, {0.2986f, 0.7624f, 0.4230f},
    {0.3629f, 0.7867f, 0.3866f}, {0.4330f, 0.8091f, 0.3453f}, {0.5081f, 0.8292f, 0.2992f},
    {0.5873f, 0.8470f, 0.2489f}, {0.6694f, 0.8622f, 0.1954f}, {0.7529f, 0.8751f, 0.1427f},
    {0.8359f, 0.8861f, 0.1025f}, {0.9166f, 0.8961f, 0.1008f}, {0.9932f, 0.9062f, 0.1439f},
}};

}  // namespace

Vec3 viridis(double t) {
  constexpr int kSegments = static_cast<int>(kViridisSrgb.size()) - 1;
  const double s = std::clamp(t, 0.0, 1.0) * kSegments;
  const int k = std::min(static_cast<int>(s), kSegments - 1);
  const double f = s - k;
  Vec3 out;
  for (int c = 0; c < 3; ++c) {
    const double srgb = kViridisSrgb[k][c] * (1.0 - f) + kViridisSrgb[k + 1][c] * f;
    out[c] = static_cast<float>(srgb_to_linear(srgb));
  }
  return out;
}

std::vector<Vec3> false_colour(const std::vector<double>& values, bool log_scale,
                               double* vmax_out) {
  double vmax = 0.0;
  for (double v : values)
    if (std::isfinite(v) && v > vmax) vmax = v;
  const double denom = log_scale ? std::log1p(vmax) : vmax;
  std::vector<Vec3> colours;
  colours.reserve(values.size());
  for (double v : values) {
    double t;
    if (std::isnan(v) || v <= 0.0)
      t = 0.0;
    else if (v >= vmax)  // the maximum itself, or +inf
      t = 1.0;
    else  // here 0 < v < vmax, so denom > 0
      t = (log_scale ? std::log1p(v) : v) / denom;
    colours.push_back(viridis(t));
  }
  if (vmax_out) *vmax_out = vmax;
  return colours;
}

}  // namespace amalgam

namespace amalgam {

LogRange own_range(const std::vector<double>& values) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (double v : values)
    if (std::isfinite(v) && v > 0.0) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!(hi > 0.0)) return {1.0, 1.0};
  return {lo, hi};
}

double log_position(double v, const LogRange& r) {
  if (std::isnan(v) || v <= r.min) return v >= r.max ? 1.0 : 0.0;
  if (v >= r.max) return 1.0;
  return std::clamp((std::log(v) - std::log(r.min)) / (std::log(r.max) - std::log(r.min)), 0.0,
                    1.0);
}

std::vector<Vec3> log_colours(const std::vector<double>& values, const LogRange& r) {
  std::vector<Vec3> out;
  out.reserve(values.size());
  for (double v : values) out.push_back(viridis(log_position(v, r)));
  return out;
}

std::vector<Vec3> with_colour_bar(const std::vector<Vec3>& image, int width, int height,
                                  const LogRange& r, int& out_height) {
  const int bar = std::max(6, height / 10);
  out_height = height + 1 + bar;
  std::vector<Vec3> out(image);
  out.resize(static_cast<std::size_t>(width) * out_height, Vec3{});  // the black row
  const double lmin = std::log(r.min), lmax = std::log(r.max);
  std::vector<bool> tick(static_cast<std::size_t>(width), false);
  if (lmax > lmin)
    for (double p = std::ceil(std::log10(r.min)); p <= std::log10(r.max); p += 1.0) {
      const double t = (p * std::log(10.0) - lmin) / (lmax - lmin);
      const int x = std::clamp(static_cast<int>(t * width), 0, width - 1);
      tick[static_cast<std::size_t>(x)] = true;
    }
  for (int y = height + 1; y < out_height; ++y)
    for (int x = 0; x < width; ++x) {
      const bool top = y < height + 1 + bar / 3;
      out[static_cast<std::size_t>(y) * width + x] =
          top && tick[static_cast<std::size_t>(x)] ? Vec3{1, 1, 1} : viridis((x + 0.5) / width);
    }
  return out;
}

}  // namespace amalgam

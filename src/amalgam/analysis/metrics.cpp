#include "amalgam/analysis/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace amalgam {
namespace {

void check_same_size(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  if (a.size() != b.size())
    throw MetricsError("images differ in size: " + std::to_string(a.size()) + " vs " +
                       std::to_string(b.size()) + " pixels");
}

void check_dims(const std::vector<Vec3>& a, const std::vector<Vec3>& b, int width, int height) {
  check_same_size(a, b);
  if (width < 0 || height < 0 ||
      a.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    throw MetricsError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                       " does not match " + std::to_string(a.size()) + " pixels");
}

double clamped_luminance(Vec3 c) {
  const double y = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
  return std::isnan(y) ? 0.0 : std::clamp(y, 0.0, 1.0);
}

/// Normalised 1D Gaussian of `size` taps (the 2D window is its outer product).
std::vector<double> gaussian_taps(int size, double sigma) {
  std::vector<double> w(static_cast<std::size_t>(size));
  const int r = size / 2;
  double sum = 0;
  for (int i = 0; i < size; ++i) {
    const double d = i - r;
    w[static_cast<std::size_t>(i)] = std::exp(-d * d / (2 * sigma * sigma));
    sum += w[static_cast<std::size_t>(i)];
  }
  for (double& v : w) v /= sum;
  return w;
}

/// Separable weighted sums of `in` (width x height) with taps `w` clipped at the image
/// border: out(x, y) = sum over in-image (i, j) of w_i w_j in(x + i - r, y + j - r).
/// Filtering an all-ones image gives the weight used at each pixel (1 away from the border).
std::vector<double> filter(const std::vector<double>& in, int width, int height,
                           const std::vector<double>& w) {
  const int r = static_cast<int>(w.size()) / 2;
  std::vector<double> tmp(in.size(), 0.0), out(in.size(), 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double s = 0;
      for (int i = -r; i <= r; ++i) {
        const int xi = x + i;
        if (xi < 0 || xi >= width) continue;
        s += w[static_cast<std::size_t>(i + r)] * in[static_cast<std::size_t>(y) * width + xi];
      }
      tmp[static_cast<std::size_t>(y) * width + x] = s;
    }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double s = 0;
      for (int j = -r; j <= r; ++j) {
        const int yj = y + j;
        if (yj < 0 || yj >= height) continue;
        s += w[static_cast<std::size_t>(j + r)] * tmp[static_cast<std::size_t>(yj) * width + x];
      }
      out[static_cast<std::size_t>(y) * width + x] = s;
    }
  return out;
}

}  // namespace

double rmse(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  check_same_size(a, b);
  if (a.empty()) return 0.0;
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(a[i][c]) - b[i][c];
      sum += d * d;
    }
  return std::sqrt(sum / (3.0 * static_cast<double>(a.size())));
}

double rel_mse(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double epsilon) {
  check_same_size(a, b);
  if (a.empty()) return 0.0;
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double ref = b[i][c];
      const double d = static_cast<double>(a[i][c]) - ref;
      sum += d * d / (ref * ref + epsilon);
    }
  return sum / (3.0 * static_cast<double>(a.size()));
}

double psnr(double rmse, double peak) {
  if (rmse == 0.0) return std::numeric_limits<double>::infinity();
  return 20.0 * std::log10(peak / rmse);
}

double ssim(const std::vector<Vec3>& a, const std::vector<Vec3>& b, int width, int height,
            const SsimConfig& config) {
  check_dims(a, b, width, height);
  if (a.empty()) throw MetricsError("cannot compute SSIM of an empty image");
  if (config.window < 1 || config.window % 2 == 0 || !(config.sigma > 0))
    throw MetricsError("SSIM window must be odd and positive with sigma > 0");
  const std::size_t n = a.size();
  std::vector<double> x(n), y(n), xx(n), yy(n), xy(n), ones(n, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = clamped_luminance(a[i]);
    y[i] = clamped_luminance(b[i]);
    xx[i] = x[i] * x[i];
    yy[i] = y[i] * y[i];
    xy[i] = x[i] * y[i];
  }
  const std::vector<double> w = gaussian_taps(config.window, config.sigma);
  const auto mx = filter(x, width, height, w), my = filter(y, width, height, w);
  const auto mxx = filter(xx, width, height, w), myy = filter(yy, width, height, w);
  const auto mxy = filter(xy, width, height, w), norm = filter(ones, width, height, w);
  const double c1 = (config.k1 * config.range) * (config.k1 * config.range);
  const double c2 = (config.k2 * config.range) * (config.k2 * config.range);

  const int r = config.window / 2;
  const bool valid = width >= config.window && height >= config.window;
  const int x0 = valid ? r : 0, x1 = valid ? width - r : width;
  const int y0 = valid ? r : 0, y1 = valid ? height - r : height;
  double sum = 0;
  for (int py = y0; py < y1; ++py)
    for (int px = x0; px < x1; ++px) {
      const std::size_t i = static_cast<std::size_t>(py) * width + px;
      const double k = norm[i];
      const double ux = mx[i] / k, uy = my[i] / k;
      const double vx = std::max(0.0, mxx[i] / k - ux * ux);
      const double vy = std::max(0.0, myy[i] / k - uy * uy);
      const double cxy = mxy[i] / k - ux * uy;
      sum += ((2 * ux * uy + c1) * (2 * cxy + c2)) / ((ux * ux + uy * uy + c1) * (vx + vy + c2));
    }
  return sum / (static_cast<double>(x1 - x0) * static_cast<double>(y1 - y0));
}

std::vector<double> error_map(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  check_same_size(a, b);
  std::vector<double> e(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    double s = 0;
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(a[i][c]) - b[i][c];
      s += d * d;
    }
    e[i] = std::sqrt(s / 3.0);
  }
  return e;
}

std::string non_finite_pixels(const std::vector<Vec3>& image) {
  std::size_t bad = 0;
  for (const Vec3& p : image)
    bad += !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  if (bad == 0) return {};
  return std::to_string(bad) + " of " + std::to_string(image.size()) +
         " pixels are not finite (NaN or infinity): compare needs finite values";
}

ImageComparison compare_images(const std::vector<Vec3>& a, const std::vector<Vec3>& b, int width,
                               int height, const SsimConfig& config) {
  check_dims(a, b, width, height);
  ImageComparison r;
  r.rmse = rmse(a, b);
  r.psnr = psnr(r.rmse);
  r.ssim = a.empty() ? 1.0 : ssim(a, b, width, height, config);
  double sum = 0, mx = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = std::fabs(static_cast<double>(a[i][c]) - b[i][c]);
      sum += d;
      mx = std::max(mx, d);
    }
  r.mean_abs = a.empty() ? 0.0 : sum / (3.0 * static_cast<double>(a.size()));
  r.max_abs = mx;
  r.rel_mse = rel_mse(a, b);
  return r;
}

std::string dark_view(const std::vector<Vec3>& image, const std::vector<float>& depth) {
  constexpr float kDark = 0.02f;
  bool hit = false;
  float brightest = 0.0f;
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (i < depth.size() && !std::isfinite(depth[i])) continue;  // a miss: the background
    hit = true;
    const Vec3 c = image[i];
    brightest = std::max({brightest, c.x, c.y, c.z});
  }
  if (image.empty()) return {};
  if (!hit)
    return "no camera ray met the scene: the view looks away from it (`amalgam info` prints its "
           "bounds and cameras; the camera, eye and look-at options set the view)";
  if (brightest >= kDark) return {};
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3g", brightest);
  return std::string("almost no light reaches what the camera sees (brightest pixel ") + buf +
         "): the view may face the unlit side, or the file's lights be too weak for its size "
         "(`amalgam info` lists them; docs/import.md, light units)";
}

}  // namespace amalgam

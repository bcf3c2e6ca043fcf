#pragma once
/// \file An image-based sky: an equirectangular radiance map over all directions, looked up by
/// direction and importance-sampled in proportion to its luminance (render/lights.h).
///
/// Layout (y up): column x of a W x H map covers azimuth phi in [2 pi x / W, 2 pi (x + 1) / W)
/// measured from -z toward +x (the centre column looks along +z), row y (from the top) covers
/// polar angle theta in [pi y / H, pi (y + 1) / H) from +y: the top row is the zenith. Each
/// pixel holds linear radiance, constant over its patch of the sphere.
///
/// Sampling draws a pixel with probability proportional to luminance x sin(theta of its row
/// centre) (the patch's solid angle), then a direction uniformly in (phi, theta) inside it:
/// the density in solid angle is p = P(pixel) W H / (2 pi^2 sin theta). Pixels of zero
/// luminance are never drawn; a map with no light at all is refused when built.

#include <cstdint>
#include <memory>
#include <vector>

#include "amalgam/math/vec.h"

namespace amalgam {

class SkyMap {
 public:
  /// A map of width x height linear radiance pixels, rows from the top, scaled by `scale`
  /// (RGB) and turned `rotate_y_deg` about +y. Throws InputError (util/error.h) when the sizes do
  /// not match, a value is negative or not finite, or no pixel has positive luminance.
  SkyMap(int width, int height, std::vector<Vec3> pixels, Vec3 scale = {1, 1, 1},
         float rotate_y_deg = 0.0f);

  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<Vec3>& pixels() const { return pixels_; }
  float rotate_y_deg() const { return rotate_deg_; }

  /// Radiance arriving from unit direction `dir` (the pixel it falls in).
  Vec3 radiance(Vec3 dir) const;

  /// A direction drawn by luminance from (u1, u2) in [0, 1)^2, its radiance and its density in
  /// solid angle (> 0).
  struct Sample {
    Vec3 dir;
    Vec3 radiance;
    float pdf = 0.0f;
  };
  Sample sample(float u1, float u2) const;
  /// The density in solid angle with which sample() draws `dir`.
  float pdf(Vec3 dir) const;

 private:
  int pixel_of(Vec3 dir) const;

  int width_ = 0, height_ = 0;
  std::vector<Vec3> pixels_;
  float rotate_deg_ = 0.0f, cos_r_ = 1.0f, sin_r_ = 0.0f;
  std::vector<double> row_cdf_;    ///< height + 1 entries, 0 .. 1
  std::vector<double> pixel_cdf_;  ///< per row, width + 1 entries, 0 .. 1
  std::vector<double> weight_;     ///< the probability of each pixel
};

}  // namespace amalgam

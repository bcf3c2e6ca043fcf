#pragma once
/// \file Image comparison metrics: RMSE, PSNR, SSIM on luminance, absolute errors and a
/// per-pixel error map. Pure functions on linear-RGB pixel arrays laid out as in
/// write_image (pixel (x, y) at index y * width + x). No I/O.

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "amalgam/math/vec.h"
#include "amalgam/util/error.h"

namespace amalgam {

/// Thrown when two images cannot be compared (different sizes, or a size that does not match
/// the pixel count): a precondition the caller must ensure, so an InternalError (exit status 1).
struct MetricsError : InternalError {
  using InternalError::InternalError;
};

/// Root-mean-square error over all pixels and all three channels of linear RGB (no
/// clamping). 0 for two empty images. Throws MetricsError if the sizes differ.
double rmse(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

/// Peak signal-to-noise ratio in dB for a given RMSE and peak value:
/// 20 log10(peak / rmse); +infinity when rmse == 0.
double psnr(double rmse, double peak = 1.0);

/// Settings of `ssim`; the defaults are those of Wang, Bovik, Sheikh, Simoncelli, "Image
/// Quality Assessment: From Error Visibility to Structural Similarity" (IEEE TIP 2004).
struct SsimConfig {
  int window = 11;     ///< side of the Gaussian window (odd)
  double sigma = 1.5;  ///< standard deviation of the window, in pixels
  double k1 = 0.01;    ///< C1 = (k1 L)^2
  double k2 = 0.03;    ///< C2 = (k2 L)^2
  double range = 1.0;  ///< L, the dynamic range of the compared values
};

/// Mean structural similarity (Wang et al. 2004, Eq. 13 averaged as in Eq. 17) of the
/// luminances (Rec. 709 weights, clamped to [0, 1]) of two width x height linear-RGB images.
/// Local statistics use a normalised Gaussian window. As in the authors' reference code, the
/// mean is taken over the positions where the whole window lies inside the image; an image
/// smaller than the window in either dimension instead uses, at every pixel, the part of the
/// window inside the image (renormalised). 1 for identical images; in [-1, 1]. Throws
/// MetricsError on size mismatch or an empty image.
double ssim(const std::vector<Vec3>& a, const std::vector<Vec3>& b, int width, int height,
            const SsimConfig& config = {});

/// Per-pixel error: the root-mean-square over the three channels of a - b (linear RGB).
/// Throws MetricsError if the sizes differ.
std::vector<double> error_map(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

/// Relative mean squared error of `a` against the reference `b`, as in the denoising
/// literature (e.g. Rousselle et al. 2011): the mean over all pixels and the three channels of
/// linear RGB of (a - b)^2 / (b^2 + epsilon), epsilon = 0.01 keeping dark reference pixels
/// from dominating. 0 for two empty images. Throws MetricsError if the sizes differ.
double rel_mse(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double epsilon = 0.01);

/// Every figure `amalgam compare` prints.
struct ImageComparison {
  double rmse = 0;      ///< over all channels, linear RGB
  double psnr = 0;      ///< dB, peak 1; +inf for identical images
  double ssim = 1;      ///< on clamped luminance
  double mean_abs = 0;  ///< mean |a - b| over all channels
  double max_abs = 0;   ///< largest |a - b| over all channels
  double rel_mse = 0;   ///< rel_mse(a, b): b is the reference

  /// The figures as (name, value), in the order and with the names both `amalgam compare
  /// --json` and Python's `amalgam.compare` give them (psnr_db: +inf for identical images).
  std::array<std::pair<const char*, double>, 6> named() const {
    return {{{"rmse", rmse},
             {"psnr_db", psnr},
             {"ssim", ssim},
             {"mean_abs_error", mean_abs},
             {"max_abs_error", max_abs},
             {"rel_mse", rel_mse}}};
  }
};

/// "N of M pixels are not finite (NaN or infinity): compare needs finite values" when some of
/// `image`'s are not finite, else "" (NaN compares false with everything: an all-NaN pair
/// would come out as SSIM 1 and max error 0).
std::string non_finite_pixels(const std::vector<Vec3>& image);

/// Why a rendered image shows almost nothing, for a warning, or "": no camera ray met the
/// scene (every `depth` infinite), or the brightest pixel where one did is below 0.02 in every
/// channel (a view of the unlit side, or a file's lights too weak for its size). `depth` is
/// the render's mean primary-hit distance per pixel (empty: every pixel counts as a hit).
std::string dark_view(const std::vector<Vec3>& image, const std::vector<float>& depth);

/// All the metrics above for two width x height images. Throws MetricsError if either
/// pixel count differs from width * height.
ImageComparison compare_images(const std::vector<Vec3>& a, const std::vector<Vec3>& b, int width,
                               int height, const SsimConfig& config = {});

}  // namespace amalgam

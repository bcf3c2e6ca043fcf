/// `amalgam compare A B`: image error metrics (RMSE, PSNR, SSIM, mean and max absolute error)
/// and an optional false-colour error image.

#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "amalgam/analysis/metrics.h"
#include "amalgam/builtin/params.h"
#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "common.h"

namespace amalgam::cli {
namespace {

/// Reads an input image; an unreadable input is bad input (exit status 2), not a runtime
/// failure.
std::vector<Vec3> read_input(const std::string& path, int& w, int& h) {
  try {
    return read_image(path, w, h);
  } catch (const ImageIoError& e) {
    throw InputError(e.what());
  }
}

std::string format_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

int run_compare(const CompareOptions& o) {
  int wa = 0, ha = 0, wb = 0, hb = 0;
  const std::vector<Vec3> a = read_input(o.a, wa, ha);
  const std::vector<Vec3> b = read_input(o.b, wb, hb);
  if (wa != wb || ha != hb)
    throw InputError(o.a + " is " + std::to_string(wa) + "x" + std::to_string(ha) + " but " + o.b +
                     " is " + std::to_string(wb) + "x" + std::to_string(hb) +
                     ": compare needs images of the same size");
  const ImageComparison c = compare_images(a, b, wa, ha);

  double vmax = 0;
  if (!o.error_image.empty())
    write_image(o.error_image, wa, ha, false_colour(error_map(a, b), false, &vmax));

  if (o.json) {
    nlohmann::json j;
    j["a"] = o.a;
    j["b"] = o.b;
    j["width"] = wa;
    j["height"] = ha;
    j["rmse"] = c.rmse;
    if (std::isinf(c.psnr))
      j["psnr_db"] = "inf";  // JSON has no infinity
    else
      j["psnr_db"] = c.psnr;
    j["ssim"] = c.ssim;
    j["mean_abs_error"] = c.mean_abs;
    j["max_abs_error"] = c.max_abs;
    if (!o.error_image.empty()) {
      j["error_image"] = o.error_image;
      j["error_image_max"] = vmax;
    }
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "size      " << wa << "x" << ha << "\n"
              << "rmse      " << format_number(c.rmse) << "\n"
              << "psnr_db   " << format_number(c.psnr) << "\n"
              << "ssim      " << format_number(c.ssim) << "\n"
              << "mean_abs  " << format_number(c.mean_abs) << "\n"
              << "max_abs   " << format_number(c.max_abs) << "\n";
    if (!o.error_image.empty())
      std::cout << "error image " << o.error_image
                << " (viridis, per-pixel RMS error, top = " << format_number(vmax) << ")\n";
  }
  return 0;
}

}  // namespace amalgam::cli

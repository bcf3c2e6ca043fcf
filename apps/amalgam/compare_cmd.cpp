/// `amalgam compare A B`: image error metrics (RMSE, PSNR, SSIM, mean and max absolute error,
/// relative MSE) and an optional false-colour error image. The text output prints the same keys
/// as the JSON output, one "key value" per line.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "amalgam/analysis/metrics.h"
#include "amalgam/builtin/params.h"
#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "amalgam/io/legend.h"
#include "amalgam/util/atomic_file.h"
#include "common.h"
#include "render_setup.h"

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
  if (!o.error_image.empty()) {  // the one output check of every subcommand, before any work
    if (!is_image_path(o.error_image))
      throw InputError("--error-image " + o.error_image +
                       ": unsupported image format (expected .png, .exr or .pfm)");
    for (const std::string* in : {&o.a, &o.b}) check_files({{"--error-image", o.error_image}}, *in);
  }
  int wa = 0, ha = 0, wb = 0, hb = 0;
  const auto same_size = [&] {
    if (wa != wb || ha != hb)
      throw InputError(o.a + " is " + std::to_string(wa) + "x" + std::to_string(ha) + " but " +
                       o.b + " is " + std::to_string(wb) + "x" + std::to_string(hb) +
                       ": compare needs images of the same size");
  };
  if (image_size(o.a, wa, ha) && image_size(o.b, wb, hb)) same_size();  // before decoding
  const std::vector<Vec3> a = read_input(o.a, wa, ha);
  const std::vector<Vec3> b = read_input(o.b, wb, hb);
  same_size();
  for (const auto& [path, image] : {std::pair{&o.a, &a}, std::pair{&o.b, &b}})
    if (const std::string why = non_finite_pixels(*image); !why.empty())
      throw InputError(*path + ": " + why);
  const ImageComparison c = compare_images(a, b, wa, ha);

  double vmax = 0;
  if (!o.error_image.empty()) {
    const std::vector<Vec3> colours = false_colour(error_map(a, b), false, &vmax);
    const Canvas c = with_linear_legend(colours, wa, ha, vmax, "error (RMS over R, G, B), linear",
                                        "error, linear");
    write_image(o.error_image, c.width, c.height, c.pixels);
  }

  // One list of (key, value) for both outputs, so the text and JSON keys are the same.
  nlohmann::ordered_json j;
  j["a"] = o.a;
  j["b"] = o.b;
  j["width"] = wa;
  j["height"] = ha;
  for (const auto& [name, value] : c.named()) {
    if (std::isinf(value))
      j[name] = "inf";  // JSON has no infinity (psnr_db of identical images)
    else
      j[name] = value;
  }
  if (!o.error_image.empty()) {
    j["error_image"] = o.error_image;
    j["error_image_max"] = vmax;
  }
  if (o.json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  for (const auto& [key, value] : j.items()) {
    std::cout << key << std::string(key.size() < 16 ? 16 - key.size() : 1, ' ');
    if (value.is_string())
      std::cout << value.get<std::string>();
    else if (value.is_number_integer())
      std::cout << value.get<long long>();
    else
      std::cout << format_number(value.get<double>());
    std::cout << "\n";
  }
  return 0;
}

}  // namespace amalgam::cli

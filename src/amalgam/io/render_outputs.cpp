#include "amalgam/io/render_outputs.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>

#include "amalgam/io/exr.h"
#include "amalgam/io/legend.h"
#include "amalgam/util/atomic_file.h"
#include "amalgam/util/version.h"

namespace amalgam {
namespace {

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::vector<Vec3> grey(const std::vector<float>& v) {
  std::vector<Vec3> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = {v[i], v[i], v[i]};
  return out;
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace

bool is_png_path(const std::string& path) {
  return lower_extension(path) == ".png";
}
bool is_exr_path(const std::string& path) {
  return lower_extension(path) == ".exr";
}

std::vector<std::string> render_exr_channels() {
  return {"R",   "G",   "B",   "cost.Y",   "level.Y",  "Z",
          "N.X", "N.Y", "N.Z", "albedo.R", "albedo.G", "albedo.B"};
}

double write_render_exr(const std::string& path, const RenderOutput& r, const ImageText& attributes,
                        bool counted) {
  // The totals as float32: exact integers up to 2^24 per pixel.
  std::vector<float> cost(r.tests.size());
  double top = 0.0;
  for (std::size_t i = 0; i < cost.size(); ++i) {
    cost[i] = static_cast<float>(r.tests[i]);
    top = std::max(top, static_cast<double>(r.tests[i]));
  }
  const auto vec = [](const std::vector<Vec3>& v, int c) {
    return v.empty() ? nullptr : &v[0].x + c;
  };
  const std::vector<std::string> names = render_exr_channels();
  const std::vector<const float*> bases = {vec(r.image, 0),  vec(r.image, 1),  vec(r.image, 2),
                                           cost.data(),      r.level.data(),   r.depth.data(),
                                           vec(r.normal, 0), vec(r.normal, 1), vec(r.normal, 2),
                                           vec(r.albedo, 0), vec(r.albedo, 1), vec(r.albedo, 2)};
  std::vector<codec::ExrChannel> channels;
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (!counted && names[k] == "cost.Y") continue;
    const bool packed = names[k] == "cost.Y" || names[k] == "level.Y" || names[k] == "Z";
    channels.push_back({names[k], bases[k], packed ? sizeof(float) : sizeof(Vec3)});
  }
  write_atomically<ImageIoError>(path, [&](AtomicFile& out) {
    codec::write_exr_channels(out, r.width, r.height, channels, attributes);
  });
  return top;
}

void write_cost_image(const std::string& path, const RenderOutput& r, const LogRange& range,
                      const std::string& legend) {
  if (is_png_path(path)) {
    const std::string title = "intersection tests per sample, log scale";
    int h = 0;
    Canvas c{r.width, 0, {}};
    if (legend.empty()) {
      c.pixels = with_colour_bar(log_colours(r.cost, range), r.width, r.height, range, h);
      c.height = h;
      append_labels(c, log_bar_labels(range, r.width), title, "tests/sample (log)");
    } else {
      c.pixels = log_colours(r.cost, range), c.height = r.height;
    }
    const std::string range_text = number(range.min) + "," + number(range.max);
    write_image(
        path, c.width, c.height, c.pixels,
        {{"Software", std::string("amalgam ") + version()},
         {"amalgam:cost-range", range_text},
         {"amalgam:cost-scale", "log"},
         {"amalgam:cost-unit", "intersection tests per primary sample"},
         {"Description",
          "intersection tests per primary sample (its shadow rays included), mean over "
          "the pixel's samples, viridis on a log scale from " +
              number(range.min) + " to " + number(range.max) +
              (legend.empty() ? "; below the picture: the colour bar, its numbers and its title"
                              : "; the colour bar: " + legend)}});
    if (!legend.empty()) {
      const int width = std::max(r.width, 240);  // room for the numbers of a small film
      Canvas bar{width, 0, with_colour_bar({}, width, 0, range, h)};
      bar.height = h;
      append_labels(bar, log_bar_labels(range, width), title, "tests/sample (log)");
      write_image(legend, bar.width, bar.height, bar.pixels,
                  {{"Software", std::string("amalgam ") + version()},
                   {"amalgam:cost-range", range_text},
                   {"Description", "the colour bar of the cost image " + path}});
    }
    return;
  }
  std::vector<float> raw(r.cost.size());
  for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = static_cast<float>(r.cost[i]);
  write_image(path, r.width, r.height, grey(raw));
}

std::vector<Vec3> level_colours(const RenderOutput& r, int max_level) {
  std::vector<Vec3> img(r.level.size());
  for (std::size_t i = 0; i < img.size(); ++i) {
    const float l = r.level[i];
    img[i] = l == kLevelNothing     ? kLevelNothingColour
             : l == kLevelPrimitive ? kLevelPrimitiveColour
                                    : viridis(max_level > 0 ? l / max_level : 0.0);
  }
  return img;
}

void write_level_image(const std::string& path, const RenderOutput& r, int max_level) {
  if (!is_png_path(path)) {
    write_image(path, r.width, r.height, grey(r.level));
    return;
  }
  const std::vector<Vec3> img = level_colours(r, max_level);
  const Canvas c = with_level_legend(img, r.width, r.height, max_level, kLevelPrimitiveColour,
                                     kLevelNothingColour);
  write_image(path, c.width, c.height, c.pixels,
              {{"Software", std::string("amalgam ") + version()},
               {"amalgam:level-range", "0," + std::to_string(max_level)},
               {"Description",
                "rendered level: viridis from level 0 to level " + std::to_string(max_level) +
                    "; light grey: primitives; black: nothing hit; the legend below the picture"}});
}

}  // namespace amalgam

#include "amalgam/io/legend.h"

#include <stb/stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace amalgam {
namespace {

constexpr int kGlyphHeight = 7;  // capitals and digits of stb_easy_font, in pixels
constexpr int kPad = 2;          // pixels around a row of text, at scale 1
const Vec3 kWhite{1, 1, 1};

/// Grows the canvas by `rows` black rows at the bottom.
void add_rows(Canvas& c, int rows) {
  c.height += rows;
  c.pixels.resize(static_cast<std::size_t>(c.width) * c.height, Vec3{});
}

/// The colour bar's rows: one black row, then max(6, picture height / 10) rows.
int bar_rows(int picture_height) {
  return std::max(6, picture_height / 10);
}

Canvas start(const std::vector<Vec3>& image, int width, int height) {
  return Canvas{width, height, image};
}

}  // namespace

int text_scale(int width) {
  return width >= 1280 ? 3 : width >= 480 ? 2 : 1;
}

int text_width(const std::string& text, int scale) {
  std::vector<char> s(text.begin(), text.end());
  s.push_back('\0');
  return stb_easy_font_width(s.data()) * scale;
}

int text_height(int scale) {
  return kGlyphHeight * scale;
}

void draw_text(Canvas& c, int x, int y, const std::string& text, int scale, Vec3 colour) {
  std::vector<char> s(text.begin(), text.end());
  s.push_back('\0');
  // About 270 bytes per character (the header's estimate); twice that, so nothing is cut.
  std::vector<char> quads(600 * (text.size() + 1));
  const int n =
      stb_easy_font_print(0, 0, s.data(), nullptr, quads.data(), static_cast<int>(quads.size()));
  for (int q = 0; q < n; ++q) {
    // Each quad is an axis-aligned rectangle: four vertices of x, y, z (float) and a colour.
    float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
    for (int v = 0; v < 4; ++v) {
      float p[2];
      std::memcpy(p, quads.data() + (static_cast<std::size_t>(q) * 4 + v) * 16, sizeof p);
      x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]);
      y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
    }
    const int px0 = x + static_cast<int>(std::lround(x0 * scale));
    const int px1 = x + static_cast<int>(std::lround(x1 * scale));
    const int py0 = y + static_cast<int>(std::lround(y0 * scale));
    const int py1 = y + static_cast<int>(std::lround(y1 * scale));
    for (int py = std::max(py0, 0); py < std::min(py1, c.height); ++py)
      for (int px = std::max(px0, 0); px < std::min(px1, c.width); ++px) c.at(px, py) = colour;
  }
}

void append_labels(Canvas& c, const std::vector<BarLabel>& labels, const std::string& title,
                   const std::string& short_title) {
  const int scale = text_scale(c.width);
  const int row = text_height(scale) + 2 * kPad * scale;
  const int top = c.height;
  if (!labels.empty()) add_rows(c, row);
  // The ends first, so the range is always stated; then the inner labels that fit.
  std::vector<std::size_t> order;
  if (!labels.empty()) order.push_back(0);
  if (labels.size() > 1) order.push_back(labels.size() - 1);
  for (std::size_t i = 1; i + 1 < labels.size(); ++i) order.push_back(i);
  std::vector<std::pair<int, int>> placed;  // [x0, x1) of each label drawn
  const int gap = 3 * scale;
  for (std::size_t i : order) {
    const int w = text_width(labels[i].text, scale);
    int x0 = static_cast<int>(std::lround(labels[i].x)) - w / 2;
    x0 = std::clamp(x0, 0, std::max(0, c.width - w));
    const int x1 = x0 + w;
    if (x1 > c.width) continue;
    bool clash = false;
    for (const auto& [a, b] : placed) clash = clash || (x0 < b + gap && a < x1 + gap);
    if (clash) continue;
    placed.push_back({x0, x1});
    draw_text(c, x0, top + kPad * scale, labels[i].text, scale, kWhite);
  }
  for (const std::string* t : {&title, &short_title}) {
    if (t->empty() || text_width(*t, scale) > c.width) continue;
    const int y = c.height;
    add_rows(c, row);
    draw_text(c, 0, y + kPad * scale, *t, scale, kWhite);
    break;
  }
}

std::string bar_number(double v) {
  char buf[32];
  const double a = std::fabs(v);
  if (a != 0 && (a >= 1e4 || a < 1e-3))
    std::snprintf(buf, sizeof buf, "%.2g", v);
  else if (a >= 1000)  // %.3g would write 1e+03
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::vector<BarLabel> log_bar_labels(const LogRange& r, int width) {
  const double lmin = std::log(r.min), lmax = std::log(r.max);
  if (!(lmax > lmin)) return {{bar_number(r.min), width / 2.0}};
  std::vector<BarLabel> out{{bar_number(r.min), 0}};
  for (double p = std::ceil(std::log10(r.min)); p <= std::log10(r.max); p += 1.0) {
    const std::string text = bar_number(std::pow(10.0, p));
    if (text == out.front().text || text == bar_number(r.max)) continue;
    const double t = (p * std::log(10.0) - lmin) / (lmax - lmin);
    // The tick's column, as with_colour_bar draws it.
    const int x = std::clamp(static_cast<int>(t * width), 0, width - 1);
    out.push_back({text, x + 0.5});
  }
  out.push_back({bar_number(r.max), static_cast<double>(width)});
  return out;
}

Canvas with_linear_legend(const std::vector<Vec3>& image, int width, int height, double vmax,
                          const std::string& title, const std::string& short_title) {
  Canvas c = start(image, width, height);
  add_rows(c, 1);
  const int y0 = c.height;
  add_rows(c, bar_rows(height));
  for (int y = y0; y < c.height; ++y)
    for (int x = 0; x < width; ++x) c.at(x, y) = viridis((x + 0.5) / width);
  append_labels(c, {{"0", 0}, {bar_number(vmax / 2), width / 2.0}, {bar_number(vmax), 1.0 * width}},
                title, short_title);
  return c;
}

Canvas with_level_legend(const std::vector<Vec3>& image, int width, int height, int max_level,
                         Vec3 primitive, Vec3 nothing) {
  Canvas c = start(image, width, height);
  add_rows(c, 1);
  const int y0 = c.height;
  add_rows(c, bar_rows(height));
  const int levels = max_level + 1;
  for (int y = y0; y < c.height; ++y)
    for (int x = 0; x < width; ++x) {
      const int l = std::min(levels - 1, x * levels / width);
      c.at(x, y) = viridis(max_level > 0 ? static_cast<double>(l) / max_level : 0.0);
    }
  std::vector<BarLabel> labels;
  for (int l = 0; l < levels; ++l)
    labels.push_back({std::to_string(l), (l + 0.5) * width / levels});
  append_labels(c, labels, "", "");
  // The two special values: a swatch each (outlined in white, so black shows) and its name.
  const int scale = text_scale(width);
  const int row = text_height(scale) + 2 * kPad * scale;
  const int y = c.height;
  add_rows(c, row);
  int x = 0;
  for (const auto& [colour, name] : {std::pair{primitive, "primitive"}, {nothing, "nothing"}}) {
    const int side = text_height(scale);
    if (x + side + 2 + text_width(name, scale) > width) break;
    for (int dy = 0; dy < side; ++dy)
      for (int dx = 0; dx < side; ++dx) {
        const bool edge = dx == 0 || dy == 0 || dx == side - 1 || dy == side - 1;
        c.at(x + dx, y + kPad * scale + dy) = edge ? kWhite : colour;
      }
    draw_text(c, x + side + 2 * scale, y + kPad * scale, name, scale, kWhite);
    x += side + 2 * scale + text_width(name, scale) + 4 * scale;
  }
  append_labels(c, {}, "level rendered", "level");
  return c;
}

}  // namespace amalgam

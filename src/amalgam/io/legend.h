#pragma once
/// \file Legends for the false-colour pictures amalgam writes (the cost and level PNGs of
/// `render`, the error image of `compare`): a colour bar with its numbers and a title, appended
/// below the picture, so that every picture states its scale. Text is drawn with stb_easy_font
/// (Debian's libstb-dev): a small bitmap font built from rectangles, needing no font file.

#include <string>
#include <vector>

#include "amalgam/io/colormap.h"
#include "amalgam/math/vec.h"

namespace amalgam {

/// A picture being composed: width x height pixels in linear RGB, rows from the top.
struct Canvas {
  int width = 0, height = 0;
  std::vector<Vec3> pixels;
  Vec3& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

/// The text scale for a picture `width` pixels wide: 1 (glyphs 7 pixels tall) below 480
/// pixels, 2 from 480, 3 from 1280.
int text_scale(int width);

/// Width and height in pixels of `text` at `scale` (height: one line, capitals and digits).
int text_width(const std::string& text, int scale);
int text_height(int scale);

/// Draws `text` (ASCII) with its top-left corner at (x, y); pixels outside the canvas are
/// clipped.
void draw_text(Canvas& c, int x, int y, const std::string& text, int scale, Vec3 colour);

/// A label of a colour bar: its text and the column (in the bar's pixels) it names.
struct BarLabel {
  std::string text;
  double x = 0;
};

/// Appends below `c`, on black: a label row under a bar already drawn in the last `bar_rows`
/// rows of `c`. Each label is centred on its column and kept inside the canvas; a label that
/// would overlap one already placed is left out (the first and last are placed first). Then
/// `title` on a row of its own, if it fits the width (else `short_title`, else nothing).
void append_labels(Canvas& c, const std::vector<BarLabel>& labels, const std::string& title,
                   const std::string& short_title);

/// A number as a bar label: 3 significant digits (all digits from 1000 to 9999), no trailing
/// zeros, exponent form with 2 digits (1e+04, 2.5e-05) from 10^4 up and below 10^-3.
std::string bar_number(double v);

/// The labels of a log-scale colour bar of `width` columns over `r` (colormap.h's
/// with_colour_bar): the ends of the range (first and last, so append_labels places them
/// first) and between them the powers of ten inside the range, at their ticks.
std::vector<BarLabel> log_bar_labels(const LogRange& r, int width);

/// `image` with a legend below: one black row, a bar of max(6, height / 10) rows in which
/// column x shows viridis((x + 0.5) / width), the colour of the value (x + 0.5) / width * vmax
/// (linear from 0), labelled 0, vmax / 2 and vmax, and `title`.
Canvas with_linear_legend(const std::vector<Vec3>& image, int width, int height, double vmax,
                          const std::string& title, const std::string& short_title);

/// `image` (a level picture: viridis from level 0 to `max_level`, primitives `primitive`,
/// nothing `nothing`) with a legend below: one black row, a bar of max(6, height / 10) rows of
/// one block per level in its colour, labelled with the level numbers that fit; then the
/// swatches of primitives and of nothing hit with their names, and the title.
Canvas with_level_legend(const std::vector<Vec3>& image, int width, int height, int max_level,
                         Vec3 primitive, Vec3 nothing);

}  // namespace amalgam

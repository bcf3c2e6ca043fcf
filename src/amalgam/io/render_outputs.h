#pragma once
/// \file The files `amalgam render` writes besides the stats JSON (docs/outputs.md): the
/// multi-layer float32 OpenEXR, the cost image with its colour bar, the rendered-level image.
/// Every writer is atomic and throws ImageIoError naming the file.

#include <string>
#include <vector>

#include "amalgam/io/colormap.h"
#include "amalgam/io/image.h"
#include "amalgam/render/render.h"

namespace amalgam {

/// The channels of `write_render_exr`, in the order documented in docs/outputs.md.
std::vector<std::string> render_exr_channels();

/// Writes every output of `r` as float32 OpenEXR: R, G, B (the beauty, at the top level so
/// RGB-only readers see it), cost.Y (intersection tests, total over the pixel's samples),
/// level.Y, Z (depth), N.X, N.Y, N.Z (normal), albedo.R, albedo.G, albedo.B, with `attributes`
/// as string attributes of the header. Returns the largest cost value written; totals above
/// 2^24 are not exact in float32 (the caller warns). `counted` false (a tracer that counts no
/// tests, e.g. Embree): no cost.Y channel, rather than one of zeros.
double write_render_exr(const std::string& path, const RenderOutput& r, const ImageText& attributes,
                        bool counted = true);

/// The cost image: .png in viridis on the log scale of `range` (tests per primary sample, the
/// mean over the pixel's samples) with the range as tEXt metadata and, unless `legend` names a
/// PNG of its own for it, a colour bar appended below (colormap.h); with `legend`, the PNG is
/// the film's size (it overlays the image) and `legend` holds the bar, its numbers and title.
/// .pfm/.exr: the raw mean tests per sample, grey, film-sized.
void write_cost_image(const std::string& path, const RenderOutput& r, const LogRange& range,
                      const std::string& legend = {});

/// The colours of the rendered-level picture: levels in viridis from level 0 to `max_level`
/// (linear), primitives light grey, nothing black.
inline constexpr Vec3 kLevelPrimitiveColour{0.6f, 0.6f, 0.6f};
inline constexpr Vec3 kLevelNothingColour{0, 0, 0};
std::vector<Vec3> level_colours(const RenderOutput& r, int max_level);

/// The rendered-level image: .png in viridis from level 0 to `max_level` (linear), primitives
/// light grey, nothing black; .pfm/.exr the raw level (kLevelPrimitive, kLevelNothing), grey.
void write_level_image(const std::string& path, const RenderOutput& r, int max_level);

/// Whether `path` names a PNG, or an OpenEXR file (by extension, any case).
bool is_png_path(const std::string& path);
bool is_exr_path(const std::string& path);

}  // namespace amalgam

#pragma once
/// \file The renderer options as a user gives them (the CLI's flags, Python's keywords, and so
/// MPI, which runs the CLI) and the one place they are checked and combined into
/// RenderOptions. Every message names the option as the user spelled it: `--level` on the
/// command line, `level=` in Python.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "amalgam/render/options.h"

namespace amalgam {

/// The range of --footprint (`footprint=`): pixels of the ray's cone, or for the volumetric
/// renderer cone widths per cell. Held as a float and multiplied by cone widths and distances,
/// so bounded well inside float's normal range: [1e-30, 1e30].
inline constexpr double kMinFootprint = 1e-30;
inline constexpr double kMaxFootprint = 1e30;

/// Options as given; unset: not given (the default applies).
struct OptionRequest {
  std::optional<std::string> renderer, opacity, order, sampler, tracer;
  std::optional<int> level;
  std::optional<double> footprint;
  std::optional<int> width, height, spp, threads;
  std::uint64_t seed = 0;
};

/// Option `flag` (as on the command line, `--look-at`) as `spelling` names it, with `value`
/// if not empty: `--look-at 1,2,3` or `look_at=1,2,3`; alone `--look-at` or `look_at=`.
std::string option_text(std::string_view flag, OptionSpelling spelling,
                        const std::string& value = {});

/// The options checked and combined; throws InputError (one line, naming the option in
/// `spelling`) on a value out of range, an unknown name, or an option that does not apply to
/// the renderer or tracer chosen. Scene-dependent checks (the level's range, cells for the
/// volumetric renderer) are check_options' (render.h).
RenderOptions resolve_options(const OptionRequest& r, OptionSpelling spelling);

}  // namespace amalgam

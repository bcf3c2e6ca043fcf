#pragma once
// What the tests on tests/data/bias-meadow.json share (bias_reference_test.cpp,
// volumetric_test.cpp): the scene, its stored converged reference, the frame and tile size, and
// whether this is the sanitizer build (about 10x slower: there only the top row of tiles, the
// far grass, is rendered; render_tile gives those pixels the bytes of the whole-frame render,
// so the same per-tile figures are checked).

#include <string>

#include "../sanitized.h"

namespace amalgam {

inline const std::string kScene = std::string(AMALGAM_SOURCE_DIR) + "/tests/data/bias-meadow.json";
inline const std::string kReference =
    std::string(AMALGAM_SOURCE_DIR) + "/tests/data/bias-meadow-ref.pfm";
inline constexpr int kWidth = 128, kHeight = 96, kTile = 32;

}  // namespace amalgam

#pragma once
/// \file A default view of geometry that comes without one (a bare mesh, a scene file without
/// camera or lights): a camera that sees all of it and lights that leave nothing black.

#include <vector>

#include "amalgam/geometry/bbox.h"
#include "amalgam/scene/scene.h"

namespace amalgam {

/// A camera that sees all of `bounds` from a 3/4 view (front-right, above; y is up).
Camera frame_camera(const Bbox& bounds, float vfov_deg = 40.0f);

/// A directional key light from above-left and a weaker point light at the camera (so that
/// no visible surface is black).
std::vector<Light> default_lights(const Bbox& bounds, const Camera& camera);

}  // namespace amalgam

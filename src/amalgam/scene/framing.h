#pragma once
/// \file A default view of geometry that comes without one (a bare mesh, a scene file without
/// camera or lights): a camera that sees all of it and lights that leave nothing black.

#include <vector>

#include "amalgam/geometry/bbox.h"
#include "amalgam/scene/scene.h"

namespace amalgam {

/// A camera that sees all of `bounds` from a 3/4 view (front-right, above) with `up` up: for
/// y up, from 35 degrees right of +z, 25 degrees above; for another `up`, that view turned by
/// the shortest rotation taking +y to `up` (z up: from the -y side, as CAD and STL files are
/// seen from the front). A zero `up` is taken as +y.
Camera frame_camera(const Bbox& bounds, float vfov_deg = 40.0f, Vec3 up = {0, 1, 0});

/// A directional key light from above-left (above along `camera.up`) and a weaker point light
/// at the camera (so that no visible surface is black).
std::vector<Light> default_lights(const Bbox& bounds, const Camera& camera);

}  // namespace amalgam

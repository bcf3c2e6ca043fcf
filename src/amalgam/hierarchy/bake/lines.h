#pragma once
/// \file Random lines crossing a box: the bake's samples.
///
/// "Random line crossing a box" is the isotropic (motion-invariant) line measure restricted to
/// the box: pick a face with probability proportional to its area, a uniform point on it and
/// a cosine-weighted direction into the box (Santalo, "Integral Geometry and Geometric
/// Probability", ch. 12).

#include "amalgam/geometry/bbox.h"

namespace amalgam {

/// A random line crossing `box` as a ray (unit direction) that starts outside it. `u` are
/// six uniform numbers in [0, 1); u[0] picks the face (stratify it), u[1] the side.
Ray sample_line(const Bbox& box, const float u[6]);

}  // namespace amalgam

#pragma once
/// \file Level-of-detail policies: the one question a traversal asks of each amalgam it meets,
/// "render it, or descend into it?".

#include "amalgam/geometry/bbox.h"

namespace amalgam {

/// Traditional renderer: amalgams are plain bounding volumes, always descended.
struct TraditionalLod {
  bool may_render(int /*level*/) const { return false; }
  bool render(const Bbox&, int /*level*/, const Ray&, float /*t*/, bool /*inside*/) const {
    return false;
  }
};

/// Scale-sensitive, fixed level: render the amalgams met on level `level`, never deeper.
/// Nodes above it are only ever containers (counted as bounding volumes). A ray that starts
/// inside an amalgam on that level renders it too: the level is never passed.
struct FixedLevelLod {
  int level = 0;
  bool may_render(int l) const { return l == level; }
  bool render(const Bbox&, int l, const Ray&, float, bool /*inside*/) const { return l == level; }
};

/// Scale-sensitive, footprint: render an amalgam once its size (box diagonal) is smaller than
/// `pixels` times the width of the ray's cone where the ray enters it. An amalgam that
/// contains the ray's origin (a shadow ray leaving a surface inside it) is descended instead:
/// its opacity describes rays that cross it, not rays that start within it.
struct FootprintLod {
  float pixels = 1.0f;
  bool may_render(int) const { return true; }
  bool render(const Bbox& b, int, const Ray& r, float t, bool inside) const {
    return !inside && b.diagonal() < pixels * r.footprint(t);
  }
};

}  // namespace amalgam

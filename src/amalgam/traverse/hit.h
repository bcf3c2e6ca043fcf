#pragma once
/// \file What a traversal reports: the closest hit of a primary ray and, under deterministic
/// opacity, the translucent amalgams in front of it.

#include <cstdint>

#include "amalgam/geometry/intersect.h"
#include "amalgam/hierarchy/hierarchy.h"

namespace amalgam {

/// What a closest-hit query found.
struct TraceHit {
  enum class Kind : std::uint8_t { kNone, kPrimitive, kAmalgam };
  Kind kind = Kind::kNone;
  float t = kInfinity;
  std::uint64_t id = 0;  ///< PrimId or NodeId
  int level = 0;
  SurfaceHit surf{};  ///< point, normal facing the ray (box entry face for amalgams)
};

/// A translucent amalgam met by a closest-hit ray under deterministic opacity.
struct TranslucentHit {
  float t;
  NodeId id;
  int level;
  SurfaceHit surf;
  float opacity;
};

}  // namespace amalgam

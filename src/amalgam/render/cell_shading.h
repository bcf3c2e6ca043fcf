#pragma once
/// \file Shading of a cell of volumetric amalgams from its normal histogram (an object's cells,
/// hierarchy/volume/cells.h, or world cells, world_cells.h): used by render/volume_integrator.h.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/math/vec.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// The normal histogram `hist` (bins `dirs`) as seen from unit direction `o`: its bins'
/// normals, turned toward o unless `oriented`, weighted by their projected area toward o.
inline Vec3 seen_normal(const std::uint16_t* hist, const std::vector<Vec3>& dirs, bool oriented,
                        Vec3 o) {
  Vec3 sum{};
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    const Vec3 m = dirs[k];
    const float c = dot(m, o);
    if (oriented ? c > 0.0f : c != 0.0f) sum += (c < 0 ? -m : m) * (hist[k] * std::fabs(c));
  }
  return sum;
}

/// What a normal histogram reflects toward unit direction `o` from unit light direction `l`,
/// per unit irradiance and unit weight, without shadows: each bin weighted by its projected
/// area toward o and its response to l (Lambert plus the Blinn-Phong lobe). A histogram
/// that is not `oriented` shows each facet's side facing o. `facing_light`: the share (x
/// 65535) of an oriented histogram's area facing the light, weighted by its cosine.
inline Vec3 reflected(const std::uint16_t* hist, const std::vector<Vec3>& dirs, bool oriented,
                      const CellSurface& s, float shininess, Vec3 o, Vec3 l, float& facing_light) {
  constexpr float inv_pi = std::numbers::inv_pi_v<float>;
  const bool spec = s.reflectance > 0.0f;
  const Vec3 half = spec ? normalize(o + l) : Vec3{};
  float seen = 0.0f, diffuse = 0.0f, specular = 0.0f;
  facing_light = 0.0f;
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    if (!hist[k]) continue;
    const float hk = static_cast<float>(hist[k]);
    Vec3 m = dirs[k];
    const float co = dot(m, o), cl = dot(m, l);
    float w, lit;
    if (oriented) {
      w = std::max(co, 0.0f);
      lit = std::max(cl, 0.0f);
      facing_light += hk * lit;
    } else {
      w = std::fabs(co);
      if (co < 0.0f) m = -m;
      lit = std::max(co < 0.0f ? -cl : cl, 0.0f);
    }
    seen += hk * w;
    diffuse += hk * w * lit;
    if (spec && lit > 0.0f)
      specular += hk * w * lit * std::pow(std::max(0.0f, dot(m, half)), shininess);
  }
  if (!(seen > 0.0f)) return {};
  Vec3 f = s.albedo * (inv_pi * diffuse / seen);
  if (spec) {
    const float lobe = s.reflectance * (shininess + 8.0f) * (inv_pi / 8.0f) * (specular / seen);
    f += Vec3{lobe, lobe, lobe};
  }
  return f;
}

AMALGAM_ISA_END
}  // namespace amalgam

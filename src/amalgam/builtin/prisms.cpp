#include "amalgam/builtin/prisms.h"

#include <cmath>

#include "amalgam/util/check.h"

namespace amalgam {

PrismsHierarchy::PrismsHierarchy(const Config& c) : c_(c) {
  AMALGAM_CHECK(c_.split >= 2 && c_.split * c_.split * c_.split <= kMaxChildren,
                "PrismsHierarchy: split^3 children must fit kMaxChildren");
  AMALGAM_CHECK(c_.leaf >= 1 && c_.leaf <= kMaxChildren, "PrismsHierarchy: leaf out of range");
  AMALGAM_CHECK(c_.depth >= 1 && c_.depth < kMaxLevels, "PrismsHierarchy: depth out of range");
  double w = 2.0;
  for (int l = 0; l < c_.depth; ++l) {
    cell_[l] = static_cast<float>(w);
    w /= c_.split;
  }
}

Vec3 PrismsHierarchy::colour_at(Vec3 p) const {
  const Vec3 u = (p + Vec3{1, 1, 1}) * 0.5f;  // [0, 1]^3
  return {0.15f + 0.75f * u.x, 0.2f + 0.6f * u.y, 0.9f - 0.7f * u.z};
}

Appearance PrismsHierarchy::appearance(NodeId id) const {
  Appearance a;
  a.surface.colour = colour_at(bounds(id).center());
  a.surface.reflectance = 0.15f;
  a.surface.shininess = 24.0f;
  a.opacity = static_cast<float>(c_.fill * c_.fill);
  return a;
}

Bbox PrismsHierarchy::prim_box(PrimId id) const {
  const float w = cell_[c_.depth - 1];
  const float h = w / static_cast<float>(c_.leaf);
  const Vec3 lo{-1.0f + w * static_cast<float>(ix(id)), -1.0f + w * static_cast<float>(iy(id)),
                -1.0f + h * static_cast<float>(iz(id))};
  const Vec3 hi = lo + Vec3{w, w, h};
  const Vec3 c = (lo + hi) * 0.5f;
  const Vec3 half = (hi - lo) * (0.5f * static_cast<float>(c_.fill));
  return Bbox{c - half, c + half};
}

Surface PrismsHierarchy::surface(PrimId id) const {
  Surface s;
  s.colour = colour_at(prim_box(id).center());
  s.reflectance = 0.15f;
  s.shininess = 24.0f;
  return s;
}

HierarchyInfo PrismsHierarchy::info() const {
  HierarchyInfo i;
  double per_level = 1;
  for (int l = 0; l < c_.depth; ++l) {
    i.nodes += per_level;
    if (l + 1 < c_.depth) per_level *= std::pow(c_.split, 3);
  }
  i.primitives = per_level * c_.leaf;
  i.levels = c_.depth + 1;
  return i;
}

Environment PrismsHierarchy::environment(const std::string& view, int lights) const {
  Environment e;
  if (view == "corner") {
    e.camera.position = {2.7f, 2.1f, 3.3f};
    e.camera.look_at = {0, -0.1f, 0};
  } else {
    e.camera.position = {0.1f, 0.1f, 4.0f};
    e.camera.look_at = {0.1f, 0.1f, 0.0f};
  }
  e.camera.vfov_deg = 40.0f;
  for (int i = 0; i < lights; ++i) {
    Light l;
    l.kind = LightKind::kDirectional;
    const float a = 0.6f + 2.0f * 3.14159265f * static_cast<float>(i) / static_cast<float>(lights);
    l.direction = normalize(Vec3{-0.5f * std::cos(a), -0.6f, -0.5f * std::sin(a) - 0.6f});
    const float s = 2.6f / static_cast<float>(lights);
    l.intensity = {s, s, s};
    e.lights.push_back(l);
  }
  return e;
}

}  // namespace amalgam

#include "amalgam/builtin/tube.h"

#include <cmath>
#include <numbers>

#include "amalgam/math/random.h"
#include "amalgam/util/check.h"

namespace amalgam {

TubeHierarchy::TubeHierarchy(const Config& c) : c_(c) {
  AMALGAM_CHECK(c_.n >= 2 && c_.n <= kMaxChildren, "TubeHierarchy: n must be in [2, kMaxChildren]");
  AMALGAM_CHECK(c_.depth >= 1 && c_.depth < kMaxLevels, "TubeHierarchy: depth out of range");
  AMALGAM_CHECK(c_.m >= 0 && c_.n + c_.m <= kMaxChildren,
                "TubeHierarchy: n + m must be at most kMaxChildren");
  count_[0] = 1;
  for (int l = 1; l <= c_.depth; ++l) {
    count_[l] = count_[l - 1] * static_cast<std::uint64_t>(c_.n);
    offset_[l] = offset_[l - 1] + count_[l - 1];
  }
  for (int l = 0; l <= c_.depth; ++l)
    width_[l] = static_cast<double>(count_[c_.depth]) / static_cast<double>(count_[l]);
  // Put the primary hits where coordinates are most precise, near x = 0: the line's hit is its
  // last primitive, so the line ends at x = 0; a Poisson realisation is hit first near the
  // camera's end (within a few cells of it once p is large), so it starts at x = 0. A hit
  // 2^20 from the origin would have float spacing 1/16 there, and the shadow ray's offset by the
  // hit's rounding-error bound (gamma(5) |p|, 0.31 at 2^20) would leave the unit cell the hit
  // lies in, starting the shadow ray past the cells it has to cross.
  x0_ = c_.mode == Mode::kLine ? -width_[0] : 0.0;
}

bool TubeHierarchy::on_axis(PrimId k) const {
  if (k >= count_[c_.depth]) return false;  // a failed object
  if (c_.mode == Mode::kLine) return k + 1 == count_[c_.depth];
  // Poisson: hits per unit cell are Bernoulli(q) with q = 1 - exp(-p / n^l_max), so the
  // probability of no hit in a level-l node is exactly exp(-p / n^l).
  const double q = -std::expm1(-c_.p / static_cast<double>(count_[c_.depth]));
  const double u = static_cast<double>(mix64(hash_combine(c_.seed, k)) >> 11) * 0x1.0p-53;
  return u < q;
}

Vec3 TubeHierarchy::prim_centre(PrimId k) const {
  if (k < count_[c_.depth])
    return {static_cast<float>(x0_ + static_cast<double>(k) + 0.5), on_axis(k) ? 0.0f : 0.3f, 0.0f};
  // A failed object: find its node (level l, index i) and place it at the node's centre, on a
  // circle of radius 0.3 around the axis (radius 0.2: inside the node's box, off the axis).
  const std::uint64_t g = (k - count_[c_.depth]) / static_cast<std::uint64_t>(c_.m);
  const int j = static_cast<int>((k - count_[c_.depth]) % static_cast<std::uint64_t>(c_.m));
  int l = 0;
  while (l + 1 < c_.depth && g >= offset_[l + 1]) ++l;
  const double i = static_cast<double>(g - offset_[l]);
  const double a = 2.0 * std::numbers::pi * j / c_.m;
  return {static_cast<float>(x0_ + (i + 0.5) * width_[l]), static_cast<float>(0.3 * std::cos(a)),
          static_cast<float>(0.3 * std::sin(a))};
}

Appearance TubeHierarchy::appearance(NodeId id) const {
  const int l = level_of(id);
  const std::uint64_t k = index_of(id);
  Appearance a;
  const float hue = static_cast<float>((static_cast<double>(k) + 0.5) / count_[l]);
  a.surface.colour = {0.3f + 0.6f * hue, 0.5f, 0.9f - 0.6f * hue};
  if (c_.mode == Mode::kLine)
    a.opacity = (k + 1 == count_[l]) ? 1.0f : static_cast<float>(c_.alpha);
  else
    a.opacity = static_cast<float>(-std::expm1(-c_.p / static_cast<double>(count_[l])));
  return a;
}

Surface TubeHierarchy::surface(PrimId k) const {
  Surface s;
  const float hue = k < count_[c_.depth]
                        ? static_cast<float>((static_cast<double>(k) + 0.5) / count_[c_.depth])
                        : 0.5f;
  s.colour = {0.3f + 0.6f * hue, 0.5f, 0.9f - 0.6f * hue};
  return s;
}

HierarchyInfo TubeHierarchy::info() const {
  HierarchyInfo i;
  for (int l = 0; l < c_.depth; ++l) i.nodes += static_cast<double>(count_[l]);
  i.primitives = static_cast<double>(count_[c_.depth]) + i.nodes * c_.m;
  i.levels = c_.depth + 1;
  return i;
}

Environment TubeHierarchy::environment(int lights) const {
  Environment e;
  const float cam = static_cast<float>(x0_ - width_[0]);
  e.camera.position = {cam, 0, 0};
  e.camera.look_at = {0, 0, 0};
  e.camera.up = {0, 1, 0};
  e.camera.vfov_deg = 10.0f;
  const double far = 2.0 * width_[0];
  for (int i = 0; i < lights; ++i) {
    Light l;
    l.kind = LightKind::kPoint;
    l.position = {cam, 0, 0};
    const float s = static_cast<float>(far * far) / static_cast<float>(lights);
    l.intensity = {s, s, s};
    e.lights.push_back(l);
  }
  return e;
}

}  // namespace amalgam

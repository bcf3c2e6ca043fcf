#include "amalgam/hierarchy/bake/combine.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "amalgam/geometry/intersect.h"
#include "amalgam/hierarchy/bake/lines.h"
#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/util/check.h"

namespace amalgam {

void orient(BakeResult& r, Vec3 outward, float weight) {
  if (r.app.shading != Shading::kNormal || !(weight > 0.0f)) return;
  const float along = dot(outward, r.app.normal) / weight;
  if (!(std::fabs(along) >= 0.5f)) return;
  if (along < 0.0f) r.app.normal = -r.app.normal;
  r.app.shading = Shading::kOriented;
}

ChildBoxes::ChildBoxes(std::span<const BakeChild> kids) : count_(static_cast<int>(kids.size())) {
  AMALGAM_CHECK(kids.size() <= static_cast<std::size_t>(kMaxChildren),
                "ChildBoxes: more children than kMaxChildren");
  for (int k = 0; k < (count_ + 3) / 4 * 4; ++k) {
    // Lanes beyond the children hold the empty box; the caller masks them out.
    const Bbox b = k < count_ ? kids[static_cast<std::size_t>(k)].bounds : Bbox{};
    for (int a = 0; a < 3; ++a) {
      groups_[k / 4].lo[a][k % 4] = b.lo[a];
      groups_[k / 4].hi[a][k % 4] = b.hi[a];
    }
  }
}

namespace {

/// The surface and normal of a bake from sums over what the lines met, `weight` in all (> 0):
/// mean colour, reflectance and shininess; the normal tensor scaled to trace 1, its dominant
/// normal, and kCloud when it has none (contents not predominantly flat), else kNormal.
void set_means(BakeResult& r, float weight, Vec3 colour, float spec, float shine,
               NormalTensor normals) {
  const float inv = 1.0f / weight;
  r.app.surface.colour = colour * inv;
  r.app.surface.reflectance = spec * inv;
  r.app.surface.shininess = shine * inv;
  const float tr = normals.trace();
  if (tr > 0.0f) normals.scale(1.0f / tr);
  r.normals = normals;
  r.app.normal = dominant_normal(normals);
  r.app.shading = r.app.normal == Vec3{} ? Shading::kCloud : Shading::kNormal;
}

}  // namespace

BakeResult finish_bake(int rays, int hits, Vec3 colour, float spec, float shine,
                       NormalTensor normals) {
  BakeResult r;
  r.app.opacity = rays > 0 ? static_cast<float>(hits) / static_cast<float>(rays) : 0.0f;
  if (hits > 0) set_means(r, static_cast<float>(hits), colour, spec, shine, normals);
  return r;
}

BakeResult bake_from_children(const Bbox& box, std::span<const BakeChild> kids, int rays,
                              std::uint64_t key) {
  struct Entry {
    float t;
    int k;
  };
  Entry entries[kMaxChildren];
  Vec3 colour{};
  float spec = 0.0f, shine = 0.0f, weight = 0.0f, opacity = 0.0f;
  NormalTensor normals;
  Vec3 outward{};
  bool oriented = true;  // every child seen has an outward normal
  rays = std::max(rays, 1);
  const LineSampler lines(box);
  const ChildBoxes boxes(kids);  // checks that `entries` has room for every child
  std::uint64_t seen = 0;  // the children that can stop a line
  for (int k = 0; k < static_cast<int>(kids.size()); ++k)
    if (kids[k].app.opacity > 0.0f) seen |= std::uint64_t{1} << k;
  alignas(16) float t0[(kMaxChildren + 3) / 4 * 4];
  for (int r = 0; r < rays; ++r) {
    float u[6];
    line_uniforms(key, r, rays, u);
    const Ray ray = lines(u);
    int n = 0;
    for (std::uint64_t m = boxes.entries(ray, t0) & seen; m; m &= m - 1) {
      const int k = std::countr_zero(m);
      int i = n++;
      while (i > 0 && entries[i - 1].t > t0[k]) entries[i] = entries[i - 1], --i;
      entries[i] = {t0[k], k};
    }
    float through = 1.0f;
    for (int i = 0; i < n && through > 0.0f; ++i) {
      const BakeChild& c = kids[entries[i].k];
      const float a = std::clamp(c.app.opacity, 0.0f, 1.0f);
      const float w = through * a;
      colour += c.app.surface.colour * w;
      spec += c.app.surface.reflectance * w;
      shine += c.app.surface.shininess * w;
      normals.add(c.normals, w);
      if (c.app.shading == Shading::kOriented)
        outward += c.app.normal * w;
      else
        oriented = false;
      weight += w;
      through *= 1.0f - a;
    }
    opacity += 1.0f - through;
  }
  BakeResult out;
  out.app.opacity = std::clamp(opacity / static_cast<float>(rays), 0.0f, 1.0f);
  if (weight > 0.0f) {
    set_means(out, weight, colour, spec, shine, normals);
    if (oriented) orient(out, outward, weight);
  }
  return out;
}

}  // namespace amalgam

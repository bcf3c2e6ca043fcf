#include "amalgam/hierarchy/explicit.h"

#include <algorithm>
#include <numeric>

namespace amalgam {
namespace {

float box_mean_projected_area(const Bbox& b) {
  const Vec3 e = b.extent();
  return 0.5f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

struct Builder {
  ExplicitHierarchy& h;
  const BuildConfig& cfg;
  std::vector<Vec3> centroids;
  int max_level = 0;

  // Fills node `index` with prims [begin, end) of h.prims (already permuted in place).
  void build(std::uint32_t index, std::uint32_t begin, std::uint32_t end, int level) {
    max_level = std::max(max_level, level + 1);
    Bbox box;
    for (std::uint32_t i = begin; i < end; ++i) box.extend(bounds(h.prims[i]));
    h.nodes[index].bounds = box;
    const std::uint32_t count = end - begin;
    if (count <= static_cast<std::uint32_t>(cfg.leaf_size)) {
      h.nodes[index].first = begin;
      h.nodes[index].count = static_cast<std::uint16_t>(count);
      h.nodes[index].leaf = true;
      return;
    }
    // Split into `arity` groups of nearly equal size by repeated median splits.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> groups{{begin, end}};
    while (groups.size() < static_cast<std::size_t>(cfg.arity)) {
      auto it = std::max_element(groups.begin(), groups.end(), [](auto a, auto b) {
        return a.second - a.first < b.second - b.first;
      });
      auto [b, e] = *it;
      if (e - b < 2) break;
      Bbox cb;
      for (std::uint32_t i = b; i < e; ++i) cb.extend(centroids[i]);
      const Vec3 ext = cb.extent();
      const int axis = ext.x > ext.y ? (ext.x > ext.z ? 0 : 2) : (ext.y > ext.z ? 1 : 2);
      const std::uint32_t mid = b + (e - b) / 2;
      std::vector<std::uint32_t> order(e - b);
      std::iota(order.begin(), order.end(), b);
      std::nth_element(order.begin(), order.begin() + (mid - b), order.end(),
                       [&](std::uint32_t x, std::uint32_t y) {
                         return centroids[x][axis] < centroids[y][axis];
                       });
      std::vector<Primitive> p(e - b);
      std::vector<Vec3> c(e - b);
      for (std::uint32_t i = 0; i < e - b; ++i) p[i] = h.prims[order[i]], c[i] = centroids[order[i]];
      std::copy(p.begin(), p.end(), h.prims.begin() + b);
      std::copy(c.begin(), c.end(), centroids.begin() + b);
      *it = {b, mid};
      groups.insert(it + 1, {mid, e});
    }
    const auto first = static_cast<std::uint32_t>(h.nodes.size());
    h.nodes[index].first = first;
    h.nodes[index].count = static_cast<std::uint16_t>(groups.size());
    h.nodes[index].leaf = false;
    h.nodes.resize(h.nodes.size() + groups.size());
    for (std::size_t g = 0; g < groups.size(); ++g)
      build(first + static_cast<std::uint32_t>(g), groups[g].first, groups[g].second, level + 1);
  }
};

}  // namespace

ExplicitHierarchy build_explicit(std::vector<Primitive> prims, std::vector<Surface> materials,
                                 const BuildConfig& config) {
  ExplicitHierarchy h;
  h.prims = std::move(prims);
  h.materials = std::move(materials);
  if (h.materials.empty()) h.materials.push_back(Surface{});
  h.nodes.resize(1);
  Builder b{h, config, {}, 0};
  b.centroids.reserve(h.prims.size());
  for (const Primitive& p : h.prims) b.centroids.push_back(bounds(p).center());
  b.build(0, 0, static_cast<std::uint32_t>(h.prims.size()), 0);
  h.levels = b.max_level + 1;
  h.appearances.resize(h.nodes.size());
  bake(h);
  return h;
}

void bake(ExplicitHierarchy& h) {
  h.appearances.resize(h.nodes.size());
  // Children always have larger indices than their parent: bake in reverse order.
  for (std::size_t i = h.nodes.size(); i-- > 0;) {
    const ExplicitNode& n = h.nodes[i];
    const float area = std::max(box_mean_projected_area(n.bounds), 1e-30f);
    Vec3 colour{};
    float weight = 0.0f, spec = 0.0f, shine = 0.0f, transmit = 1.0f;
    for (std::uint32_t c = 0; c < n.count; ++c) {
      float a, cover;
      Surface s;
      if (n.leaf) {
        const Primitive& p = h.prims[n.first + c];
        s = h.materials[p.material];
        a = 1.0f;
        cover = mean_projected_area(p);
      } else {
        const Appearance& ca = h.appearances[n.first + c];
        s = ca.surface;
        a = ca.opacity;
        cover = box_mean_projected_area(h.nodes[n.first + c].bounds);
      }
      const float w = a * cover;
      colour += s.colour * w;
      spec += s.reflectance * w;
      shine += s.shininess * w;
      weight += w;
      transmit *= 1.0f - std::min(1.0f, w / area);
    }
    Appearance& out = h.appearances[i];
    if (weight > 0) {
      out.surface.colour = colour / weight;
      out.surface.reflectance = spec / weight;
      out.surface.shininess = shine / weight;
    }
    out.opacity = std::clamp(1.0f - transmit, 0.0f, 1.0f);
  }
}

}  // namespace amalgam

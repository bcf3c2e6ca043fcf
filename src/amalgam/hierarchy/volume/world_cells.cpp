#include "amalgam/hierarchy/volume/world_cells.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "amalgam/util/error.h"

namespace amalgam {
namespace {

/// What one cell sums while it is baked: per direction bin the cross-sections (world area),
/// per normal bin the surface area, then area, area x albedo (3), area x reflectance,
/// area x reflectance x shininess, and the grain weighted by the mean cross-section and that
/// weight.
struct Sums {
  int dirs = 0, nb = 0;
  int stride() const { return dirs + nb + 8; }
};

/// One level while it is baked: its cells' dense keys (sorted) and their sums.
struct LevelSums {
  std::vector<std::uint64_t> keys;
  std::vector<double> acc;
};

/// The coordinates of cell `key` in a level with counts `n`.
std::array<std::uint64_t, 3> cell_xyz(const std::array<int, 3>& n, std::uint64_t key) {
  const auto nx = static_cast<std::uint64_t>(n[0]), ny = static_cast<std::uint64_t>(n[1]);
  return {key % nx, key / nx % ny, key / (nx * ny)};
}

class WorldBake {
 public:
  WorldBake(const InstancedHierarchy& h, const std::vector<CellGrid>& grids,
            const std::vector<float>& scale, WorldCells& w)
      : h_(h), grids_(grids), scale_(scale), w_(w), s_{w.dirs(), w.normal_bins()} {
    for (int b = 0; b < w.dirs(); ++b) dir_bins_.push_back(octahedral_bin_dir(b, w.dir_res));
  }

  const CellGrid* cells_of(std::uint32_t instance) const {
    const std::uint32_t mesh = h_.instances[instance].mesh;
    if (mesh >= grids_.size()) return nullptr;
    const CellGrid& g = grids_[mesh];
    return g.cells() > 0 && g.at(0, 0, 0, 0) != 0 ? &g : nullptr;
  }

  /// The size that decides where instance `i` is absorbed: its grid's longest edge times its
  /// scale, the same for every rotation of a mesh (its world box is not: a crowd of one mesh
  /// at random headings would otherwise be split between two levels).
  float size_of(std::uint32_t i) const { return cells_of(i)->longest() * scale_[i]; }

  std::uint64_t key_of(int level, Vec3 p) const {
    const std::array<int, 3>& n = w_.counts[static_cast<std::size_t>(level)];
    const float s = w_.cell_size(level);
    std::uint64_t c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = static_cast<std::uint64_t>(
          std::clamp(static_cast<int>(std::floor((p[a] - w_.lo[a]) / s)), 0, n[a] - 1));
    return (c[2] * static_cast<std::uint64_t>(n[1]) + c[1]) * static_cast<std::uint64_t>(n[0]) +
           c[0];
  }
  /// The key on `level` of the parent of cell `key` of level + 1.
  std::uint64_t parent_key(int level, std::uint64_t key) const {
    const std::array<std::uint64_t, 3> c =
        cell_xyz(w_.counts[static_cast<std::size_t>(level) + 1], key);
    const std::array<int, 3>& p = w_.counts[static_cast<std::size_t>(level)];
    return ((c[2] / 2) * static_cast<std::uint64_t>(p[1]) + c[1] / 2) *
               static_cast<std::uint64_t>(p[0]) +
           c[0] / 2;
  }

  /// Adds instance `i` (absorbed, with cells) to the sums `acc` of one cell.
  void add_instance(std::uint32_t i, double* acc) const {
    const InstancedHierarchy::InstanceData& in = h_.instances[i];
    const CellGrid& g = *cells_of(i);
    const std::uint32_t c0 = g.at(0, 0, 0, 0) - 1;
    const double s2 = static_cast<double>(scale_[i]) * scale_[i];
    double cross = 0.0;
    for (int b = 0; b < s_.dirs; ++b) {
      const Vec3 d = dir_bins_[static_cast<std::size_t>(b)];
      const Vec3 od = in.identity ? d : normalize(in.to_object.vector(d));
      const double c = s2 * g.projected_area(0, od) * g.coverage_of(c0, g.lerp(od));
      acc[b] += c;
      cross += c;
    }
    const CellSurface& cs = g.surface[c0];
    const double area = s2 * cs.area;
    const int nb = g.normal_bins();
    const std::uint16_t* hist = g.normals.data() + static_cast<std::size_t>(c0) * nb;
    double* normals = acc + s_.dirs;
    for (int k = 0; k < nb; ++k) {
      if (!hist[k]) continue;
      const Vec3 m = g.normal_dirs[static_cast<std::size_t>(k)];
      const Vec3 wn = in.identity
                          ? m
                          : normalize(Vec3{dot(in.normal_rows[0], m), dot(in.normal_rows[1], m),
                                           dot(in.normal_rows[2], m)});
      normals[octahedral_bin(wn, w_.normal_res)] += area * (hist[k] / 65535.0);
    }
    double* surf = normals + s_.nb;
    surf[0] += area;
    surf[1] += area * cs.albedo.x, surf[2] += area * cs.albedo.y, surf[3] += area * cs.albedo.z;
    surf[4] += area * cs.reflectance;
    surf[5] += area * cs.reflectance * g.shininess;
    surf[6] += cross * g.grain * scale_[i];
    surf[7] += cross;
  }

  /// Bakes every level, finest first; returns them coarsest first.
  std::vector<LevelSums> bake(const std::vector<std::uint32_t>& absorbed, BakeCharge& charge) {
    // The absorbed instances by (absorb level, cell there, instance): each cell's instances
    // are summed in instance order, whatever the thread count.
    struct Item {
      int level;
      std::uint64_t key;
      std::uint32_t instance;
    };
    std::vector<Item> items;
    charge.transient(static_cast<double>(absorbed.size() * sizeof(Item)));
    items.reserve(absorbed.size());
    for (std::uint32_t i : absorbed)
      items.push_back(
          {w_.absorb[i], key_of(w_.absorb[i], h_.instances[i].world_bounds.center()), i});
    std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
      return a.level != b.level ? a.level < b.level
             : a.key != b.key   ? a.key < b.key
                                : a.instance < b.instance;
    });
    const int levels = w_.levels;
    const std::size_t stride = static_cast<std::size_t>(s_.stride());
    std::vector<LevelSums> out(static_cast<std::size_t>(levels));
    for (int level = levels - 1; level >= 0; --level) {
      LevelSums& ls = out[static_cast<std::size_t>(level)];
      const auto first = std::lower_bound(items.begin(), items.end(), level,
                                          [](const Item& it, int l) { return it.level < l; });
      const auto last = std::upper_bound(items.begin(), items.end(), level,
                                         [](int l, const Item& it) { return l < it.level; });
      // Groups of one cell's instances: [starts[g], starts[g + 1]).
      std::vector<std::size_t> starts;
      for (auto it = first; it != last; ++it)
        if (it == first || it->key != (it - 1)->key) {
          starts.push_back(static_cast<std::size_t>(it - items.begin()));
          ls.keys.push_back(it->key);
        }
      starts.push_back(static_cast<std::size_t>(last - items.begin()));
      const LevelSums* finer =
          level + 1 < levels ? &out[static_cast<std::size_t>(level) + 1] : nullptr;
      if (finer)
        for (std::uint64_t k : finer->keys) ls.keys.push_back(parent_key(level, k));
      std::sort(ls.keys.begin(), ls.keys.end());
      ls.keys.erase(std::unique(ls.keys.begin(), ls.keys.end()), ls.keys.end());
      charge.transient(static_cast<double>(ls.keys.size() * (stride * sizeof(double) + 8)));
      ls.acc.assign(ls.keys.size() * stride, 0.0);
      const auto slot = [&](std::uint64_t key) {
        return static_cast<std::size_t>(std::lower_bound(ls.keys.begin(), ls.keys.end(), key) -
                                        ls.keys.begin());
      };
      tbb::parallel_for(std::size_t{0}, starts.size() - 1, [&](std::size_t g) {
        double* acc = ls.acc.data() + slot(items[starts[g]].key) * stride;
        for (std::size_t j = starts[g]; j < starts[g + 1]; ++j)
          add_instance(items[j].instance, acc);
      });
      if (finer)
        for (std::size_t c = 0; c < finer->keys.size(); ++c) {
          double* acc = ls.acc.data() + slot(parent_key(level, finer->keys[c])) * stride;
          const double* from = finer->acc.data() + c * stride;
          for (std::size_t j = 0; j < stride; ++j) acc[j] += from[j];
        }
    }
    return out;
  }

 private:
  const InstancedHierarchy& h_;
  const std::vector<CellGrid>& grids_;
  const std::vector<float>& scale_;
  WorldCells& w_;
  Sums s_;
  std::vector<Vec3> dir_bins_;
};

/// Levels down to where an instance of size `smallest` is absorbed, as long as the dense index
/// keeps within `max_index` entries: fills w.counts and w.index_offset, returns the entries.
std::size_t lay_out_levels(WorldCells& w, float smallest, std::size_t max_index) {
  const float ratio = w.size0 / std::max(smallest, std::ldexp(w.size0, -20));
  const int finest = std::clamp(static_cast<int>(std::floor(std::log2(ratio))), 0, 20);
  std::size_t entries = 0;
  for (int level = 0; level <= finest; ++level) {
    const float s = w.cell_size(level);
    std::array<int, 3> n{};
    std::size_t cells = 1;
    for (std::size_t a = 0; a < 3; ++a) {
      n[a] =
          std::clamp(static_cast<int>(std::ceil(w.extent[static_cast<int>(a)] / s)), 1, 1 << level);
      cells *= static_cast<std::size_t>(n[a]);
    }
    if (level > 0 && entries + cells > max_index) break;
    w.counts.push_back(n);
    w.index_offset.push_back(entries);
    entries += cells;
  }
  w.levels = static_cast<int>(w.counts.size());
  return entries;
}

/// Appends the cell `key` of `level` with sums `acc` (Sums' layout) to `w`, its index entry
/// included.
void store_cell(WorldCells& w, int level, std::uint64_t key, const double* acc) {
  const int dirs = w.dirs(), nb = w.normal_bins();
  // The part of the cell inside the box, where rays cross it (march_world clips to the box):
  // a thin layer of instances fills a cubic cell only as deep as the layer.
  const std::array<std::uint64_t, 3> xyz = cell_xyz(w.counts[static_cast<std::size_t>(level)], key);
  const double size = w.cell_size(level);
  double volume = 1.0;
  for (int a = 0; a < 3; ++a)
    volume *=
        std::max(std::min(size, static_cast<double>(w.extent[a]) -
                                    static_cast<double>(xyz[static_cast<std::size_t>(a)]) * size),
                 1e-9 * size);
  w.index[w.index_offset[static_cast<std::size_t>(level)] + key] =
      static_cast<std::uint32_t>(w.surface.size()) + 1u;
  for (int b = 0; b < dirs; ++b) w.sigma.push_back(static_cast<float>(acc[b] / volume));
  double total = 0.0;
  for (int k = 0; k < nb; ++k) total += acc[dirs + k];
  for (int k = 0; k < nb; ++k)
    w.normals.push_back(
        static_cast<std::uint16_t>(total > 0.0 ? std::lround(65535.0 * acc[dirs + k] / total) : 0));
  const double* surf = acc + dirs + nb;
  CellSurface s;
  s.area = static_cast<float>(surf[0]);
  if (surf[0] > 0.0) {
    s.albedo = Vec3{static_cast<float>(surf[1] / surf[0]), static_cast<float>(surf[2] / surf[0]),
                    static_cast<float>(surf[3] / surf[0])};
    s.reflectance = static_cast<float>(surf[4] / surf[0]);
  }
  w.surface.push_back(s);
  w.grain.push_back(surf[7] > 0.0 ? static_cast<float>(surf[6] / surf[7]) : 0.0f);
}

/// Each top node's smallest absorb level (children come after their parent).
void absorb_top(WorldCells& w, const InstancedHierarchy& h) {
  for (std::size_t n = h.top_nodes.size(); n-- > 0;) {
    const ExplicitNode& t = h.top_nodes[n];
    if (!t.leaf && t.count > 0 && t.first <= n)
      throw InternalError("bake_world_cells: a top node's children before it");
    int a = 127;
    for (std::uint32_t c = 0; c < t.count; ++c)
      a = std::min<int>(a, t.leaf ? w.absorb[h.top_items[t.first + c]] : w.top_absorb[t.first + c]);
    w.top_absorb[n] = static_cast<std::int8_t>(t.count ? a : -1);
  }
}

}  // namespace

WorldCells bake_world_cells(const InstancedHierarchy& h, const std::vector<CellGrid>& grids,
                            const std::vector<float>& scale, const VolumeConfig& config,
                            std::size_t max_index) {
  WorldCells w;
  w.dir_res = config.dir_res;
  w.normal_res = config.normal_res;
  w.absorb.assign(h.instances.size(), -1);
  w.top_absorb.assign(h.top_nodes.size(), -1);
  WorldBake bake(h, grids, scale, w);

  // The box of every instance with cells, and the smallest of them.
  Bbox box;
  float smallest = kInfinity;
  std::vector<std::uint32_t> absorbed;
  for (std::uint32_t i = 0; i < h.instances.size(); ++i) {
    if (!bake.cells_of(i)) continue;
    box.extend(h.instances[i].world_bounds);
    smallest = std::min(smallest, bake.size_of(i));
    absorbed.push_back(i);
  }
  if (absorbed.empty()) return w;
  const Vec3 ext = box.extent();
  const float pad = 1e-5f * (max_component(ext) + max_component(abs(box.center())));
  w.lo = box.lo - Vec3{pad, pad, pad};
  w.extent = ext + Vec3{2.0f * pad, 2.0f * pad, 2.0f * pad};
  w.size0 = max_component(w.extent);
  const std::size_t entries = lay_out_levels(w, smallest, max_index);
  for (std::uint32_t i : absorbed) {
    const float size = bake.size_of(i);
    const int a = size > 0.0f ? static_cast<int>(std::floor(std::log2(w.size0 / size))) : w.levels;
    w.absorb[i] = static_cast<std::int8_t>(std::clamp(a, 0, w.levels - 1));
  }

  // Bake, then number the cells level by level and fill the dense index.
  BakeCharge charge(config);
  const std::vector<LevelSums> levels = bake.bake(absorbed, charge);
  const auto stride = static_cast<std::size_t>(Sums{w.dirs(), w.normal_bins()}.stride());
  // The cells as stored: the dense index, then per cell its extinctions, normal histogram,
  // surface and grain.
  double cells = 0.0;
  for (const LevelSums& ls : levels) cells += static_cast<double>(ls.keys.size());
  charge.kept(entries * 4.0 + cells * (w.dirs() * sizeof(float) + w.normal_bins() * 2.0 +
                                       sizeof(CellSurface) + sizeof(float)));
  w.index.assign(entries, 0u);
  double shine = 0.0, shine_w = 0.0;
  for (int level = 0; level < w.levels; ++level) {
    const LevelSums& ls = levels[static_cast<std::size_t>(level)];
    for (std::size_t c = 0; c < ls.keys.size(); ++c) {
      const double* acc = ls.acc.data() + c * stride;
      store_cell(w, level, ls.keys[c], acc);
      const double* surf = acc + w.dirs() + w.normal_bins();
      if (level == 0) shine += surf[5], shine_w += surf[4];
    }
  }
  if (shine_w > 0.0) w.shininess = static_cast<float>(shine / shine_w);
  for (int b = 0; b < w.normal_bins(); ++b)
    w.normal_dirs.push_back(octahedral_bin_dir(b, w.normal_res));
  absorb_top(w, h);
  return w;
}

}  // namespace amalgam

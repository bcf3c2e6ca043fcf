#pragma once
/// \file World cells: volumetric amalgams of whole instances, in world space, across the
/// instances of a scene (docs/volumetric.md, "World cells").
///
/// Cubic cells on levels 0 .. levels - 1 over the box of every object instance (level L cuts
/// the box's longest edge into 2^L). Instance i is *absorbed* at every level whose cells are at
/// least as large as it (its cells' longest edge times its scale), down to its absorb level A_i
/// (capped at the finest level): there it adds to the cell that holds its box's centre, and through
/// the coarser levels to that cell's ancestors. A ray whose cone is so wide that it reads level L
/// at depth t reads, for every instance absorbed at L, the cells instead of the instance: one
/// cell per cone width, however many instances crowd in it. An instance not absorbed at the
/// ray's level is left to the instance walk (its own cells or its triangles: object_lod.h),
/// whole.
///
/// Different instances are independent (their silhouettes uncorrelated), so a cell is a medium:
/// per direction bin its extinction per unit length, the sum of its instances' mean
/// cross-sections (the instance's box's projected area times its level-0 coverage, cells.h)
/// over the cell's volume, and a chord of length s passes with probability exp(-sigma s). A
/// cell's surfaces: area, area-weighted albedo and specular weight and a normal histogram in
/// world normal bins (each instance's histogram rotated into world space), and the grain of its
/// instances' surfaces, the width of the gaps a ray comes through: a shadow ray from a point a
/// camera ray reached stays in that gap, and unattenuated, for as long as it is within a grain
/// of the camera ray (the hot spot).
///
/// Baked once, camera- and light-independent, after the instances' own cells
/// (volume_set.cpp): deterministic (grouped by cell, summed in instance order) for any thread
/// count.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "amalgam/hierarchy/instanced.h"
#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/math/random.h"

namespace amalgam {

struct WorldCells {
  Vec3 lo{};
  Vec3 extent{};       ///< the box [lo, lo + extent] of every absorbed instance (padded)
  float size0 = 0.0f;  ///< edge of the level-0 cell (the box's longest edge)
  int levels = 0;      ///< 0: no world cells
  int dir_res = 0, normal_res = 0;
  float shininess = 32.0f;  ///< area-weighted Blinn-Phong exponent of the specular surfaces
  /// Per level: cell counts per axis and where its dense index starts in `index`.
  std::vector<std::array<int, 3>> counts;
  std::vector<std::size_t> index_offset;
  std::vector<std::uint32_t> index;
  /// sigma[cell * dirs() + bin]: extinction per unit length (world) along bin `bin`'s
  /// direction.
  std::vector<float> sigma;
  /// As CellGrid::normals, over world normal bins.
  std::vector<std::uint16_t> normals;
  std::vector<CellSurface> surface;  ///< areas in world units
  /// Per cell: its instances' grain (CellGrid::grain, world units), weighted by their mean
  /// cross-section: the width of the hot spot (volume_integrator.h, world_shadow).
  std::vector<float> grain;
  std::vector<Vec3> normal_dirs;
  /// Per instance: its absorb level, -1 if never absorbed (no cells, or larger than the box).
  std::vector<std::int8_t> absorb;
  /// Per top-tree node: the smallest absorb level of the instances under it (-1: some never).
  std::vector<std::int8_t> top_absorb;

  bool empty() const { return levels == 0; }
  int dirs() const { return dir_res * dir_res; }
  int normal_bins() const { return normal_res * normal_res; }
  std::size_t cells() const { return surface.size(); }
  float cell_size(int level) const { return std::ldexp(size0, -level); }
  GridLevelView view(int level) const {
    const std::array<int, 3>& n = counts[static_cast<std::size_t>(level)];
    const float s = cell_size(level);
    return {lo,
            {s, s, s},
            {n[0], n[1], n[2]},
            index.data() + index_offset[static_cast<std::size_t>(level)]};
  }
  /// The extinction of `cell` along a direction, interpolated between four bins.
  float sigma_of(std::uint32_t cell, const OctahedralLerp& l) const {
    const float* c =
        sigma.data() + static_cast<std::size_t>(cell) * static_cast<std::size_t>(dirs());
    return l.w[0] * c[l.bin[0]] + l.w[1] * c[l.bin[1]] + l.w[2] * c[l.bin[2]] +
           l.w[3] * c[l.bin[3]];
  }
  /// The level a cone of width `footprint` (world) reads at cells of `cell_pixels` cone widths:
  /// ceil(log2(size0 / (cell_pixels footprint)) - u), at least 0, which is log2 rounded down or
  /// up with probability by its fraction (`u` uniform in [0, 1), one per ray), so that the
  /// expected image is the exact mix of the two nearest levels; >= levels: finer than the
  /// finest (nothing absorbed there). Non-increasing along a ray, as its footprint grows.
  int level_at(float footprint, float cell_pixels, float u) const {
    if (levels == 0 || !(footprint > 0.0f)) return levels;
    const float lambda = std::log2(size0 / (cell_pixels * footprint));
    if (!(lambda - u < static_cast<float>(levels))) return levels;
    return std::max(0, static_cast<int>(std::ceil(lambda - u)));
  }
  /// The depth along ray r where level_at falls below `level` (infinity if never): where the
  /// footprint reaches size0 / (cell_pixels 2^(level - 1 + u)).
  float level_end(const Ray& r, int level, float cell_pixels, float u) const {
    if (level <= 0 || !(r.cone_spread > 0.0f)) return kInfinity;
    const float fp = size0 / (cell_pixels * std::exp2(static_cast<float>(level - 1) + u));
    return (fp - r.cone_width) / r.cone_spread;
  }
  std::size_t bytes() const {
    return index.size() * 4 + sigma.size() * 4 + normals.size() * 2 +
           surface.size() * sizeof(CellSurface) + grain.size() * 4 +
           normal_dirs.size() * sizeof(Vec3) + absorb.size() + top_absorb.size() +
           counts.size() * 12 + index_offset.size() * 8;
  }
};

/// The uniform number of the world level choice for the ray keyed `key` (world cells and the
/// instance walk must draw the same one).
inline float world_level_u(std::uint64_t key) {
  return to_unit_float(hash_combine(key ^ 0x776f726c64ull, 0x63656c6cull));
}

/// Calls f(cell, t_in, t_out, level) for each world cell with content that ray r crosses in
/// [t0, t1], each depth read at the level its cone chooses there (level_at), front to back,
/// until f returns false. Returns the grid cells stepped through, empty ones included.
/// `count(level, steps)` is told the grid cells stepped through on each level, empty ones
/// included.
template <class F, class C>
int march_world(const WorldCells& w, const Ray& r, float t0, float t1, float cell_pixels, float u,
                F&& f, C&& count) {
  if (w.empty()) return 0;
  // Clip to the box (inside every level's cells: march_level starts in the cell it is in).
  for (int a = 0; a < 3; ++a) {
    const float inv = 1.0f / r.dir[a];
    float n = (w.lo[a] - r.origin[a]) * inv, fa = (w.lo[a] + w.extent[a] - r.origin[a]) * inv;
    if (n > fa) std::swap(n, fa);
    if (std::isnan(n)) n = -kInfinity;
    if (std::isnan(fa)) fa = kInfinity;
    t0 = std::max(t0, n);
    t1 = std::min(t1, fa);
  }
  if (!(t0 < t1)) return 0;
  int level = w.level_at(r.footprint(t0), cell_pixels, u);
  if (level >= w.levels) {
    level = w.levels - 1;
    t0 = std::max(t0, w.level_end(r, w.levels, cell_pixels, u));
  }
  int steps = 0;
  bool go = true;
  for (; go && level >= 0 && t0 < t1; --level) {
    const float end = std::min(t1, w.level_end(r, level, cell_pixels, u));
    if (!(t0 < end)) continue;
    const int n = march_level(w.view(level), r.origin, r.dir, t0, end,
                              [&](std::uint32_t cell, float a, float b) {
                                go = f(cell, a, b, level);
                                return go;
                              });
    count(level, n);
    steps += n;
    t0 = end;
  }
  return steps;
}

/// Bakes the world cells of the instances of `h` whose mesh has cells in `grids` (`scale`: each
/// instance's cbrt |det M|); at most `max_index` dense index entries over all levels.
WorldCells bake_world_cells(const InstancedHierarchy& h, const std::vector<CellGrid>& grids,
                            const std::vector<float>& scale, const VolumeConfig& config,
                            std::size_t max_index = std::size_t{1} << 23);

}  // namespace amalgam

#pragma once
/// \file Volumetric amalgams of one mesh: a sparse hierarchy of disjoint cubic cells in the
/// mesh's object space (an octree: level L cuts the mesh's bounding cube into 2^L cells per
/// axis), each cell an amalgam with
///
/// - a **coverage** per direction bin (octahedral.h): of the lines in direction d that reach the
///   cell unblocked by the rest of the *whole mesh*, the fraction whose first hit lies inside
///   it. A cone multiplies (1 - coverage) over the cells it crosses, front to back: by the
///   chain rule that is the probability that a line passes them all, exact for the lines that
///   cross the same cells, so one object's cells composite with their correlation (a solid
///   stays opaque, a silhouette is not counted twice, a back face never shows) at every level.
///   Measured by tracing lines through the real triangles (coverage.cpp), per level: the fit of
///   extinction and correlation in one number. Beside it the **first-hit coverage**, the same
///   first hits over all the lines that cross the cell: the share of the cell's projected area
///   where the mesh is first met, which gives the lit share of its surface toward a light.
/// - the **surface inside the cell**: its area, area-weighted albedo and specular weight, and
///   its normal distribution as an area histogram over normal bins (never a mean normal); the
///   integrator weights the bins by their projected area toward the viewer and their response
///   to each light.
///
/// Light-independent and camera-independent: baked once per mesh (bake_cells), shared by every
/// instance of it. The cone march that reads them is traverse/cone_march.h.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "amalgam/geometry/ray.h"
#include "amalgam/hierarchy/volume/octahedral.h"
#include "amalgam/math/vec.h"

namespace amalgam {

class ExplicitHierarchy;

/// Settings of bake_cells.
struct VolumeConfig {
  /// Levels 0 .. levels - 1; the finest has 2^(levels - 1) cells per axis. Finer cones than
  /// the finest cell trace the mesh at full detail.
  int levels = 6;
  int dir_res = 8;     ///< coverage: dir_res^2 direction bins
  int normal_res = 8;  ///< normal histogram: normal_res^2 bins
  /// Lines per finest-cell width of the coverage bake (lines^2 per finest cell seen
  /// face-on).
  int lines = 4;
  std::uint64_t seed = 0x766f6c;
  /// false: the coverage is that of the cell's surfaces alone, as if nothing around them in
  /// the mesh correlated with them: 1 - exp(-tau), tau their projected area over the cell's
  /// (the independent, exponential model of a medium). Only to measure what the fit to the
  /// mesh's first hits buys (docs/volumetric.md); the first-hit coverage is kept either way.
  bool correlated = true;
  bool parallel = true;  ///< oneTBB over the direction bins (the result does not depend on it)
  /// Bake world cells across the instances too (world_cells.h); false: every instance is
  /// marched or traced on its own (to measure what world cells buy).
  bool world = true;
  /// When set, told the bytes the bake is about to allocate, before it does (negative: what it
  /// has freed); it may throw to stop the bake (the loader holds it to --max-memory). Not part
  /// of what is baked.
  class BakeBudget* budget = nullptr;
  void charge(double bytes) const;
};

/// What a bake's allocations are charged to (VolumeConfig::budget).
class BakeBudget {
 public:
  virtual ~BakeBudget() = default;
  virtual void charge(double bytes) = 0;
};

inline void VolumeConfig::charge(double bytes) const {
  if (budget) budget->charge(bytes);
}

/// The bytes one step of a bake charges to VolumeConfig::reserve: `transient` ones are freed
/// (charged back) when the step ends, `kept` ones are the baked result's and stay charged.
class BakeCharge {
 public:
  explicit BakeCharge(const VolumeConfig& config) : config_(config) {}
  BakeCharge(const BakeCharge&) = delete;
  BakeCharge& operator=(const BakeCharge&) = delete;
  ~BakeCharge() {
    if (held_ > 0.0) config_.charge(-held_);  // a release never throws
  }
  void transient(double bytes) {
    config_.charge(bytes);
    held_ += bytes;
  }
  void kept(double bytes) const { config_.charge(bytes); }

 private:
  const VolumeConfig& config_;
  double held_ = 0.0;
};

/// The surface inside one cell.
struct CellSurface {
  Vec3 albedo{};             ///< area-weighted mean diffuse colour (textures: their mean)
  float reflectance = 0.0f;  ///< area-weighted mean specular weight
  float area = 0.0f;         ///< surface area inside the cell, object units
};

class CellGrid {
 public:
  /// The grid's box (object space): the mesh's bounding box, so that a ray that enters its
  /// cells also enters the mesh's hierarchy (and is offered them by the BVH walk).
  Vec3 lo{};
  Vec3 size{};
  /// The areas of a cell's faces across x, y and z over the largest projected area of a cell
  /// (the same for every level): a cell's projected area along unit d is proportional to
  /// dot(face, |d|).
  Vec3 face{};
  int levels = 0;
  int dir_res = 0, normal_res = 0;
  /// The mesh is closed and wound outward (closed_orientation > 0, or < 0 with its normals
  /// flipped here): surfaces are one-sided and only their outer side can be seen or lit.
  bool oriented = false;
  float shininess = 32.0f;  ///< Blinn-Phong exponent of the specular surfaces (area-weighted)
  /// The linear size of the mesh's connected pieces (object units; area-weighted mean of the
  /// square root of each piece's area): how wide the gap a ray came through is, what a shadow
  /// ray from there stays correlated with (the hot spot of world cells, world_cells.h).
  float grain = 0.0f;

  /// Per level L: its dense index (8^L entries, x fastest) starts at index_offset[L]; an entry
  /// is 0 (no surface there) or the cell's id + 1.
  std::vector<std::uint32_t> index_offset;
  std::vector<std::uint32_t> index;
  /// Cells are numbered level by level: those of level L are [level_first[L], level_first[L+1]).
  std::vector<std::uint32_t> level_first;
  /// coverage[cell * dirs() + bin]: the coverage in direction bin `bin` (the direction the
  /// lines travel) times dot(face, |bin direction|), times 65535. The lines crossing a cell
  /// along unit d are proportional to its projected area, which has kinks where d crosses an
  /// axis plane; the first hits behind it vary smoothly: so that product is what is
  /// interpolated between bins, and coverage_of divides by dot(face, |d|) of the actual
  /// direction (lerp).
  std::vector<std::uint16_t> coverage;
  /// first_hit[cell * dirs() + bin]: the first-hit coverage, stored the same way.
  std::vector<std::uint16_t> first_hit;
  /// normals[cell * normal_bins() + bin]: the share of the cell's surface area whose normal
  /// falls in bin `bin`, times 65535 (the shares of a cell add up to 65535 within rounding).
  std::vector<std::uint16_t> normals;
  std::vector<CellSurface> surface;
  /// Unit normal at the centre of each normal bin.
  std::vector<Vec3> normal_dirs;
  /// An open mesh's seen-and-lit correction (traverse/lit_ratio.h), per level L, rise bin e
  /// of the view direction (rise_bin) and angle bin k: lit_ratio[(L * kLitRises + e) *
  /// kLitAngles + k], in [-1, 1]. Of the points of the mesh seen from a direction, the share S'
  /// a light at angle k * 180 / (kLitAngles - 1) degrees from the viewer reaches past the mesh,
  /// against the mean lit share S (lit_share) of the level-L cells holding them: (S' - S) /
  /// (1 - S) when S' >= S, else S' / S - 1 (seen_lit). Empty: not baked (a closed mesh, whose
  /// cells are lit by their first-hit coverage alone).
  static constexpr int kLitRises = 8;
  static constexpr int kLitAngles = 25;
  std::vector<float> lit_ratio;

  int dirs() const { return dir_res * dir_res; }
  int normal_bins() const { return normal_res * normal_res; }
  std::size_t cells() const { return surface.size(); }
  Vec3 cell_size(int level) const { return size / static_cast<float>(1 << level); }
  /// The longest edge of the grid's box: what the cone's width is compared with.
  float longest() const { return max_component(size); }
  /// Projected area along unit `d` of a cell of `level`.
  float projected_area(int level, Vec3 d) const {
    const Vec3 c = cell_size(level);
    return c.y * c.z * std::fabs(d.x) + c.x * c.z * std::fabs(d.y) + c.x * c.y * std::fabs(d.z);
  }
  /// The interpolation of direction `d` (unit) between the coverages' bins.
  OctahedralLerp lerp(Vec3 d) const {
    OctahedralLerp l = OctahedralLerp::of(d, dir_res);
    l.norm = dot(face, abs(d));
    return l;
  }
  /// The cell (id + 1) at integer coordinates (x, y, z) of `level`, or 0 where there is no
  /// surface. Coordinates must lie in [0, 2^level).
  std::uint32_t at(int level, int x, int y, int z) const {
    const std::uint32_t n = 1u << level;
    return index[index_offset[level] + (static_cast<std::uint32_t>(z) * n + y) * n + x];
  }
  /// The coverage of `cell` for a line direction, interpolated between four bins (`l`, from
  /// lerp).
  float coverage_of(std::uint32_t cell, const OctahedralLerp& l) const {
    return lookup(coverage, cell, l);
  }
  /// The first-hit coverage of `cell` for a line direction.
  float first_hit_of(std::uint32_t cell, const OctahedralLerp& l) const {
    return lookup(first_hit, cell, l);
  }
  /// The share of the surfaces of `cell` (of `level`) that unit direction `l` (toward the
  /// light) reaches past the whole mesh, in projected area toward l: the cell's first-hit
  /// coverage seen from the light times its projected area, over its surfaces' projected area
  /// toward l (both sides of every facet).
  float lit_share(int level, std::uint32_t cell, Vec3 l) const {
    const std::uint16_t* hist = normals.data() + static_cast<std::size_t>(cell) * normal_bins();
    float facing = 0.0f;
    for (int k = 0; k < normal_bins(); ++k)
      if (hist[k]) facing += static_cast<float>(hist[k]) * std::fabs(dot(normal_dirs[k], l));
    const float area = surface[cell].area * facing * (1.0f / 65535.0f);
    if (!(area > 0.0f)) return 0.0f;
    return std::min(1.0f, first_hit_of(cell, lerp(-l)) * projected_area(level, l) / area);
  }
  /// The bin of a view direction whose y component (object space) is `rise`: equal steps of y
  /// (of solid angle), so that a mesh standing on y (a tree, a tuft) has its own correction
  /// seen from above, from the side and from below.
  static int rise_bin(float rise) {
    return std::clamp(static_cast<int>((rise + 1.0f) * (0.5f * kLitRises)), 0, kLitRises - 1);
  }
  /// The share of the surfaces a camera sees along a direction with y component `rise` (object
  /// space) in a cell of `level` whose surfaces have lit share `share` that a light at cosine
  /// `cos_apart` from the viewer reaches: the correction k (lit_ratio, linear in the angle
  /// between angle bins and in the rise between the rise bins' centres) moves the share toward
  /// 1 by k (k >= 0: the seen surfaces are lit more often, the hot spot) or scales it by 1 + k
  /// (k < 0). Linear in the share, so that its mean over the seen surfaces is the measured one
  /// whatever the spread of the cells' shares. `share` itself when not baked.
  float seen_lit(int level, float rise, float cos_apart, float share) const {
    if (lit_ratio.empty()) return share;
    const float x = std::acos(std::clamp(cos_apart, -1.0f, 1.0f)) *
                    (static_cast<float>(kLitAngles - 1) / 3.14159265f);
    const int k = std::min(static_cast<int>(x), kLitAngles - 2);
    const float f = std::min(x - static_cast<float>(k), 1.0f);
    const float y = (rise + 1.0f) * (0.5f * kLitRises) - 0.5f;  // in units of rise bins
    const int e = std::clamp(static_cast<int>(std::floor(y)), 0, kLitRises - 2);
    const float g = std::clamp(y - static_cast<float>(e), 0.0f, 1.0f);
    auto at = [&](int bin) {
      const float* r =
          lit_ratio.data() + static_cast<std::size_t>(level * kLitRises + bin) * kLitAngles;
      return r[k] + (r[k + 1] - r[k]) * f;
    };
    const float lo = at(e), c = lo + (at(e + 1) - lo) * g;
    return c >= 0.0f ? share + (1.0f - share) * c : share * (1.0f + c);
  }
  /// Bytes held.
  std::size_t bytes() const {
    return index.size() * 4 + coverage.size() * 2 + first_hit.size() * 2 + normals.size() * 2 +
           surface.size() * sizeof(CellSurface) + normal_dirs.size() * sizeof(Vec3) +
           (index_offset.size() + level_first.size()) * 4 + lit_ratio.size() * 4;
  }

 private:
  float lookup(const std::vector<std::uint16_t>& table, std::uint32_t cell,
               const OctahedralLerp& l) const {
    const std::uint16_t* c = table.data() + static_cast<std::size_t>(cell) * dirs();
    const float q =
        l.w[0] * c[l.bin[0]] + l.w[1] * c[l.bin[1]] + l.w[2] * c[l.bin[2]] + l.w[3] * c[l.bin[3]];
    return std::min(1.0f, q * (1.0f / 65535.0f) / l.norm);
  }
};

/// Bakes the cells of `mesh` (its triangles; spheres and boxes are ignored): the surface in
/// every finest cell by clipping each triangle to the cells it crosses, coarser levels by
/// adding their children, then every level's coverage by tracing lines through the mesh
/// (coverage.cpp). Deterministic: the same grid for any thread count.
CellGrid bake_cells(const ExplicitHierarchy& mesh, const VolumeConfig& config = {});

/// The coverages of every cell of `g` (its surfaces and index already made) for the triangles
/// `tris` (object space, 3 vertices each): fills g.coverage and g.first_hit. (coverage.cpp)
void bake_coverage(CellGrid& g, std::span<const Vec3> tris, const VolumeConfig& config);

/// Clips [t0, t1] to where the ray o + t d (object space) is inside the grid's box; false if
/// it misses it.
inline bool clip_to_grid(const CellGrid& g, Vec3 o, Vec3 d, float& t0, float& t1) {
  for (int a = 0; a < 3; ++a) {
    const float inv = 1.0f / d[a];
    float n = (g.lo[a] - o[a]) * inv, f = (g.lo[a] + g.size[a] - o[a]) * inv;
    if (n > f) std::swap(n, f);
    if (std::isnan(n)) n = -kInfinity;  // d[a] == 0 with o on a face
    if (std::isnan(f)) f = kInfinity;
    t0 = std::max(t0, n);
    t1 = std::min(t1, f);
  }
  return t0 < t1;
}

/// One level of a grid of disjoint box cells as a march reads it: the corner `lo` of cell
/// (0, 0, 0), the cells' size, their counts per axis and the level's dense index (x fastest; an
/// entry is 0, no content there, or the cell's id + 1).
struct GridLevelView {
  Vec3 lo{};
  Vec3 cell{};
  int n[3] = {0, 0, 0};
  const std::uint32_t* index = nullptr;
};

/// Calls f(cell, t_in, t_out) for each cell with content of grid level `v` that the ray
/// o + t d crosses within [t0, t1] (inside the level's box), in order of t (a 3D DDA,
/// Amanatides & Woo 1987), until f returns false. Returns the number of grid cells stepped
/// through, empty ones included.
template <class F>
int march_level(const GridLevelView& v, Vec3 o, Vec3 d, float t0, float t1, F&& f) {
  const Vec3 cs = v.cell;
  const Vec3 p = o + d * (0.5f * (t0 + std::min(t1, t0 + 1e-3f * max_component(cs))));
  int c[3], step[3];
  float next[3], delta[3];
  for (int a = 0; a < 3; ++a) {
    c[a] = std::clamp(static_cast<int>(std::floor((p[a] - v.lo[a]) / cs[a])), 0, v.n[a] - 1);
    if (d[a] > 0.0f) {
      step[a] = 1;
      next[a] = (v.lo[a] + cs[a] * static_cast<float>(c[a] + 1) - o[a]) / d[a];
      delta[a] = cs[a] / d[a];
    } else if (d[a] < 0.0f) {
      step[a] = -1;
      next[a] = (v.lo[a] + cs[a] * static_cast<float>(c[a]) - o[a]) / d[a];
      delta[a] = -cs[a] / d[a];
    } else {
      step[a] = 0;
      next[a] = kInfinity;
      delta[a] = kInfinity;
    }
  }
  const std::size_t nx = static_cast<std::size_t>(v.n[0]);
  const std::size_t nxy = nx * static_cast<std::size_t>(v.n[1]);
  int steps = 0;
  float t = t0;
  for (;;) {
    ++steps;
    const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
    const float out = std::min(next[a], t1);
    const std::uint32_t cell =
        v.index[static_cast<std::size_t>(c[2]) * nxy + static_cast<std::size_t>(c[1]) * nx +
                static_cast<std::size_t>(c[0])];
    if (cell && out > t)
      if (!f(cell - 1, t, out)) break;
    if (next[a] >= t1) break;
    t = next[a];
    c[a] += step[a];
    if (c[a] < 0 || c[a] >= v.n[a]) break;
    next[a] += delta[a];
  }
  return steps;
}

/// march_level over the cells of `level` of `g` (see clip_to_grid for [t0, t1]).
template <class F>
int march_cells(const CellGrid& g, int level, Vec3 o, Vec3 d, float t0, float t1, F&& f) {
  const int n = 1 << level;
  const GridLevelView v{
      g.lo, g.cell_size(level), {n, n, n}, g.index.data() + g.index_offset[level]};
  return march_level(v, o, d, t0, t1, std::forward<F>(f));
}

}  // namespace amalgam

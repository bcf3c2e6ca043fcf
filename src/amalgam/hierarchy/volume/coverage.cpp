// The coverage bake of volumetric amalgams (cells.h): for each direction bin, a jittered grid
// of parallel lines across the mesh's bounding cube finds each line's first hit on the real
// triangles (a z-buffer over the lines: every triangle projected onto the plane across the
// direction and tested against the lines its footprint covers). Each cell of each level counts
// the first hits inside it: over the lines expected to cross it (the line density times its
// projected area) that is its first-hit coverage.
//
// The coverage proper is fitted so that the cone march, which multiplies (1 - coverage) over
// the cells a line crosses, reproduces those first hits: cells are visited front to back (by
// the depth of their centres along the direction, an order every line crosses them in), and a
// cell's coverage is its first hits over the sum, over every line that crosses it, of what the
// march would have left of that line on arriving there (the product of (1 - coverage) of the
// cells before it on the line). Then on average over the lines the march gives each cell
// exactly its share of first hits, and the whole column the probability of a hit, with the
// transmittance of every single line still in [0, 1]: the correlation of one object's cells,
// fitted per level to lines traced through its real triangles.

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/math/random.h"

namespace amalgam {

namespace {

/// First hits of one direction's lines: depth along d (infinity: none) per line.
void first_hits(const CellGrid& g, std::span<const Vec3> tris, Vec3 d, int res, float radius,
                std::uint64_t key, std::vector<float>& depth, std::vector<float>& jx,
                std::vector<float>& jy, Vec3& u, Vec3& v, Vec3& centre) {
  perpendiculars(d, u, v);
  centre = g.lo + g.size * 0.5f;
  const float pitch = 2.0f * radius / static_cast<float>(res);
  const std::size_t lines = static_cast<std::size_t>(res) * res;
  depth.assign(lines, std::numeric_limits<float>::infinity());
  jx.resize(lines), jy.resize(lines);
  for (std::size_t i = 0; i < lines; ++i) {
    const std::uint64_t h = hash_combine(key, i);
    jx[i] = to_unit_float(h);
    jy[i] = to_unit_float(mix64(h));
  }
  const std::size_t count = tris.size() / 3;
  for (std::size_t t = 0; t < count; ++t) {
    float x[3], y[3], z[3];
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = tris[3 * t + k] - centre;
      x[k] = (dot(p, u) + radius) / pitch;  // in lines
      y[k] = (dot(p, v) + radius) / pitch;
      z[k] = dot(p, d);
    }
    const float area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if (!(std::fabs(area) > 0.0f)) continue;  // seen edge-on: no line hits it
    const float inv = 1.0f / area;
    const int i0 = std::max(0, static_cast<int>(std::floor(std::min({x[0], x[1], x[2]}))));
    const int i1 = std::min(res - 1, static_cast<int>(std::floor(std::max({x[0], x[1], x[2]}))));
    const int j0 = std::max(0, static_cast<int>(std::floor(std::min({y[0], y[1], y[2]}))));
    const int j1 = std::min(res - 1, static_cast<int>(std::floor(std::max({y[0], y[1], y[2]}))));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const std::size_t l = static_cast<std::size_t>(j) * res + i;
        const float px = static_cast<float>(i) + jx[l], py = static_cast<float>(j) + jy[l];
        // Barycentric weights of (px, py), their signs matching the triangle's winding.
        const float w0 = ((x[1] - px) * (y[2] - py) - (x[2] - px) * (y[1] - py)) * inv;
        const float w1 = ((x[2] - px) * (y[0] - py) - (x[0] - px) * (y[2] - py)) * inv;
        const float w2 = 1.0f - w0 - w1;
        if (w0 < 0.0f || w1 < 0.0f || w2 < 0.0f) continue;
        const float zd = w0 * z[0] + w1 * z[1] + w2 * z[2];
        if (zd < depth[l]) depth[l] = zd;
      }
  }
}

/// A line of a direction bin that crosses the grid, with its first hit (infinity: none).
struct Line {
  Vec3 o;
  float t0, t1, hit;
};

/// What the direction bins baked at once (one per thread) hold: each its lines' first hits (12
/// bytes) and records (24), the cells' counts, and the crossings of the finest level (each line
/// crosses at most 3 * 2^fine of its cells).
double bins_bytes(const VolumeConfig& config, int dirs, int res, int fine, std::size_t cells) {
  const int at_once = config.parallel ? std::min(dirs, tbb::this_task_arena::max_concurrency()) : 1;
  const double lines = static_cast<double>(res) * res;
  return at_once * (lines * (36.0 + 3.0 * (1 << fine) * sizeof(std::uint32_t)) +
                    static_cast<double>(cells) * 12.0);
}

}  // namespace

void bake_coverage(CellGrid& g, std::span<const Vec3> tris, const VolumeConfig& config) {
  const int dirs = g.dirs();
  const std::size_t cells = g.cells();
  g.coverage.assign(cells * static_cast<std::size_t>(dirs), 0);
  g.first_hit.assign(cells * static_cast<std::size_t>(dirs), 0);
  if (cells == 0) return;
  const int fine = g.levels - 1;
  // The box's silhouette lies within a disc of its half diagonal in every direction; the lines
  // are `config.lines` per finest cell's longest edge.
  const float radius = 0.5f * length(g.size) * 1.0001f;
  const int res = static_cast<int>(
      std::ceil(static_cast<float>(config.lines << fine) * 2.0f * radius / g.longest() * 1.0001f));
  BakeCharge charge(config);
  charge.transient(bins_bytes(config, dirs, res, fine, cells));
  const float pitch = 2.0f * radius / static_cast<float>(res);
  const float density = 1.0f / (pitch * pitch);  // lines per unit area across d

  auto one = [&](int b) {
    const Vec3 d = octahedral_bin_dir(b, g.dir_res);
    std::vector<float> depth, jx, jy;
    Vec3 u, v, centre;
    first_hits(g, tris, d, res, radius, hash_combine(config.seed, static_cast<std::uint64_t>(b)),
               depth, jx, jy, u, v, centre);
    std::vector<Line> lines;           // those that cross the cube
    const float back = 2.0f * radius;  // lines start this far before the centre plane
    for (int j = 0; j < res; ++j)
      for (int i = 0; i < res; ++i) {
        const std::size_t l = static_cast<std::size_t>(j) * res + i;
        Line line{centre + u * ((static_cast<float>(i) + jx[l]) * pitch - radius) +
                      v * ((static_cast<float>(j) + jy[l]) * pitch - radius) - d * back,
                  0.0f, kInfinity, depth[l] + back};
        if (clip_to_grid(g, line.o, d, line.t0, line.t1)) lines.push_back(line);
      }
    std::vector<std::uint32_t> hits(cells, 0), crossing(cells + 1, 0), events;
    std::vector<std::uint32_t> order;
    std::vector<float> left;
    const float norm = dot(g.face, abs(d));
    auto store = [&](std::vector<std::uint16_t>& table, std::uint32_t c, float a) {
      table[static_cast<std::size_t>(c) * dirs + b] =
          static_cast<std::uint16_t>(std::lround(65535.0f * std::clamp(a, 0.0f, 1.0f) * norm));
    };
    for (int L = 0; L <= fine; ++L) {
      const std::uint32_t first = g.level_first[L], last = g.level_first[L + 1];
      // Which lines cross each cell of the level (bucketed by cell), and the first hits in it.
      std::fill(crossing.begin(), crossing.end(), 0);
      auto walk = [&](auto&& visit) {
        for (std::size_t k = 0; k < lines.size(); ++k) {
          const Line& ln = lines[k];
          march_cells(g, L, ln.o, d, ln.t0, ln.t1, [&](std::uint32_t c, float a, float e) {
            visit(k, c, ln.hit >= a && ln.hit < e);
            return true;
          });
        }
      };
      walk([&](std::size_t, std::uint32_t c, bool hit) {
        ++crossing[c + 1];
        hits[c] += hit;
      });
      for (std::uint32_t c = first; c < last; ++c) crossing[c + 1] += crossing[c];
      events.resize(crossing[last]);
      std::vector<std::uint32_t> at(crossing.begin() + first, crossing.begin() + last);
      walk([&](std::size_t k, std::uint32_t c, bool) {
        events[at[c - first]++] = static_cast<std::uint32_t>(k);
      });
      // Front to back: what the march leaves of each line on arriving at each cell.
      order.resize(last - first);
      for (std::uint32_t c = first; c < last; ++c) order[c - first] = c;
      std::vector<float> depth_of(last - first);
      {
        const int n = 1 << L;
        const Vec3 cs = g.cell_size(L);
        for (int z = 0; z < n; ++z)
          for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
              if (const std::uint32_t c = g.at(L, x, y, z))
                depth_of[c - 1 - first] =
                    dot(g.lo + Vec3{(x + 0.5f) * cs.x, (y + 0.5f) * cs.y, (z + 0.5f) * cs.z}, d);
      }
      std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t c) {
        return depth_of[a - first] < depth_of[c - first] ||
               (depth_of[a - first] == depth_of[c - first] && a < c);
      });
      left.assign(lines.size(), 1.0f);
      const float expected = density * g.projected_area(L, d);
      for (const std::uint32_t c : order) {
        double arriving = 0.0;
        for (std::uint32_t e = crossing[c]; e < crossing[c + 1]; ++e) arriving += left[events[e]];
        const float cov = arriving > 0.0 ? static_cast<float>(hits[c] / arriving) : 0.0f;
        const float pass = 1.0f - std::min(cov, 1.0f);
        for (std::uint32_t e = crossing[c]; e < crossing[c + 1]; ++e) left[events[e]] *= pass;
        if (config.correlated) {
          store(g.coverage, c, cov);
        } else {
          const std::uint16_t* h = g.normals.data() + static_cast<std::size_t>(c) * g.normal_bins();
          float mean_cos = 0.0f;
          for (int k = 0; k < g.normal_bins(); ++k)
            mean_cos += static_cast<float>(h[k]) *
                        std::fabs(dot(g.normal_dirs[static_cast<std::size_t>(k)], d));
          const float tau = g.surface[c].area * mean_cos / 65535.0f / g.projected_area(L, d);
          store(g.coverage, c, 1.0f - std::exp(-tau));
        }
        store(g.first_hit, c, static_cast<float>(hits[c]) / expected);
      }
    }
  };
  if (config.parallel)
    tbb::parallel_for(0, dirs, one);
  else
    for (int b = 0; b < dirs; ++b) one(b);
}

}  // namespace amalgam

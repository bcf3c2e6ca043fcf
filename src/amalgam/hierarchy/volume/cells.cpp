#include "amalgam/hierarchy/volume/cells.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "amalgam/hierarchy/bake/orientation.h"
#include "amalgam/hierarchy/explicit.h"
#include "amalgam/util/error.h"

namespace amalgam {

namespace {

/// What a cell's surface adds up to while it is baked.
struct Acc {
  double area = 0.0;
  double albedo[3] = {0, 0, 0};
  double reflectance = 0.0;
  std::vector<double> hist;
  void add(const Acc& o) {
    area += o.area;
    for (int c = 0; c < 3; ++c) albedo[c] += o.albedo[c];
    reflectance += o.reflectance;
    for (std::size_t k = 0; k < hist.size(); ++k) hist[k] += o.hist[k];
  }
};

/// A polygon of up to 9 vertices (a triangle clipped by up to six planes).
struct Poly {
  Vec3 v[12];
  int n = 0;
};

/// `in` clipped to the half-space where sign * (p[axis] - at) <= 0.
void clip(const Poly& in, int axis, float at, float sign, Poly& out) {
  out.n = 0;
  for (int i = 0; i < in.n; ++i) {
    const Vec3 a = in.v[i], b = in.v[(i + 1) % in.n];
    const float da = sign * (a[axis] - at), db = sign * (b[axis] - at);
    if (da <= 0.0f) out.v[out.n++] = a;
    if ((da < 0.0f && db > 0.0f) || (da > 0.0f && db < 0.0f)) {
      const float s = da / (da - db);
      Vec3 p = a + (b - a) * s;
      p[axis] = at;
      out.v[out.n++] = p;
    }
  }
}

double polygon_area(const Poly& p) {
  if (p.n < 3) return 0.0;
  double sx = 0, sy = 0, sz = 0;
  for (int i = 1; i + 1 < p.n; ++i) {
    const Vec3 c = cross(p.v[i] - p.v[0], p.v[i + 1] - p.v[0]);
    sx += c.x, sy += c.y, sz += c.z;
  }
  return 0.5 * std::sqrt(sx * sx + sy * sy + sz * sz);
}

/// The linear size of the surface's pieces: the triangles joined where they share a vertex
/// position into connected pieces (a grass blade, a leaf, a whole closed body), the
/// area-weighted mean of sqrt(piece area). 0 without area.
float surface_grain(const std::vector<Vec3>& tris) {
  const std::size_t n = tris.size() / 3;
  std::vector<std::uint32_t> parent(n);
  for (std::size_t t = 0; t < n; ++t) parent[t] = static_cast<std::uint32_t>(t);
  const auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  // Vertices sorted by position: equal positions adjacent.
  std::vector<std::pair<std::array<float, 3>, std::uint32_t>> verts;
  verts.reserve(tris.size());
  for (std::size_t v = 0; v < tris.size(); ++v)
    verts.push_back({{tris[v].x, tris[v].y, tris[v].z}, static_cast<std::uint32_t>(v / 3)});
  std::sort(verts.begin(), verts.end());
  for (std::size_t v = 1; v < verts.size(); ++v)
    if (verts[v].first == verts[v - 1].first) {
      const std::uint32_t a = find(verts[v].second), b = find(verts[v - 1].second);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<double> area(n, 0.0);
  for (std::size_t t = 0; t < n; ++t)
    area[find(static_cast<std::uint32_t>(t))] +=
        0.5 * static_cast<double>(
                  length(cross(tris[3 * t + 1] - tris[3 * t], tris[3 * t + 2] - tris[3 * t])));
  double sum = 0.0, weighted = 0.0;
  for (const double a : area) sum += a, weighted += a * std::sqrt(a);
  return sum > 0.0 ? static_cast<float>(weighted / sum) : 0.0f;
}

/// Numbers the cells of `per_level` (accumulator indices, -1: empty) level by level, in each
/// level's linear order, and stores the dense indices, the surfaces and the normal histograms.
void store_cells(CellGrid& g, const std::vector<std::vector<int>>& per_level,
                 const std::vector<Acc>& accs, const BakeCharge& charge) {
  const int nb = g.normal_bins();
  // Ids level by level, in each level's linear order; the dense indices; the stored surfaces.
  g.index_offset.resize(static_cast<std::size_t>(g.levels) + 1);
  g.level_first.resize(static_cast<std::size_t>(g.levels) + 1);
  std::uint32_t offset = 0, id = 0;
  for (int L = 0; L < g.levels; ++L) {
    g.index_offset[static_cast<std::size_t>(L)] = offset;
    g.level_first[static_cast<std::size_t>(L)] = id;
    const std::vector<int>& cur = per_level[static_cast<std::size_t>(L)];
    offset += static_cast<std::uint32_t>(cur.size());
    for (int ai : cur) id += ai >= 0 ? 1u : 0u;
  }
  g.index_offset[static_cast<std::size_t>(g.levels)] = offset;
  g.level_first[static_cast<std::size_t>(g.levels)] = id;
  // The grid as baked: its dense index, surfaces, normal histograms and the coverage tables.
  charge.kept(offset * 4.0 +
              id * (sizeof(CellSurface) + nb * 2.0 + 2.0 * g.dirs() * sizeof(std::uint16_t)));
  g.index.assign(offset, 0);
  g.surface.resize(id);
  g.normals.assign(static_cast<std::size_t>(id) * nb, 0);
  id = 0;
  for (int L = 0; L < g.levels; ++L) {
    const std::vector<int>& cur = per_level[static_cast<std::size_t>(L)];
    for (std::size_t lin = 0; lin < cur.size(); ++lin) {
      if (cur[lin] < 0) continue;
      const Acc& a = accs[static_cast<std::size_t>(cur[lin])];
      g.index[g.index_offset[static_cast<std::size_t>(L)] + lin] = id + 1;
      CellSurface& s = g.surface[id];
      s.area = static_cast<float>(a.area);
      s.albedo =
          Vec3{static_cast<float>(a.albedo[0] / a.area), static_cast<float>(a.albedo[1] / a.area),
               static_cast<float>(a.albedo[2] / a.area)};
      s.reflectance = static_cast<float>(a.reflectance / a.area);
      double total = 0.0;
      for (double h : a.hist) total += h;
      for (int k = 0; k < nb; ++k)
        g.normals[static_cast<std::size_t>(id) * nb + k] = static_cast<std::uint16_t>(
            std::lround(65535.0 * a.hist[static_cast<std::size_t>(k)] / total));
      ++id;
    }
  }
}

}  // namespace

CellGrid bake_cells(const ExplicitHierarchy& mesh, const VolumeConfig& config) {
  if (config.levels < 1 || config.levels > 8 || config.dir_res < 1 || config.normal_res < 1 ||
      config.lines < 1)
    throw InternalError("bake_cells: levels in [1, 8], resolutions and lines >= 1");
  CellGrid g;
  g.levels = config.levels;
  g.dir_res = config.dir_res;
  g.normal_res = config.normal_res;
  const int nb = g.normal_bins();
  for (int b = 0; b < nb; ++b) g.normal_dirs.push_back(octahedral_bin_dir(b, g.normal_res));

  // The triangles, their colours and materials.
  std::vector<Primitive> prims = mesh.prims.to_vector();
  const int orientation = closed_orientation(prims);
  g.oriented = orientation != 0;
  std::vector<Vec3> tris;
  std::vector<std::uint32_t> source;
  Vec3 lo{kInfinity, kInfinity, kInfinity}, hi = -lo;
  for (std::size_t i = 0; i < prims.size(); ++i) {
    const Primitive& p = prims[i];
    if (p.kind != PrimKind::kTriangle) continue;
    const Vec3 c = orientation < 0 ? p.b : p.c, b = orientation < 0 ? p.c : p.b;
    tris.insert(tris.end(), {p.a, b, c});
    source.push_back(static_cast<std::uint32_t>(i));
    lo = min(lo, min(p.a, min(p.b, p.c)));
    hi = max(hi, max(p.a, max(p.b, p.c)));
  }
  if (source.empty()) return g;
  BakeCharge charge(config);
  charge.transient(static_cast<double>(prims.size() * sizeof(Primitive) +
                                       tris.size() * sizeof(Vec3) + source.size() * 4));
  // The mesh's box, each edge at least a thousandth of the longest (a flat mesh gets a thin
  // box, not an empty one), widened by a few ulps so every vertex is inside.
  const Vec3 centre = (lo + hi) * 0.5f;
  const float pad = 1e-6f * (1.0f + max_component(abs(centre)));
  g.size = max(hi - lo, Vec3{1, 1, 1} * (1e-3f * max_component(hi - lo))) + Vec3{pad, pad, pad};
  g.lo = centre - g.size * 0.5f;
  const Vec3 face{g.size.y * g.size.z, g.size.x * g.size.z, g.size.x * g.size.y};
  g.face = face / length(face);

  // The surface in each finest cell: every triangle clipped to the cells its box overlaps.
  const int fine = g.levels - 1;
  const int n = 1 << fine;
  const Vec3 cs = g.cell_size(fine);
  // The dense accumulator indices of every level (8/7 of the finest's), and the accumulators
  // in blocks of 1024, charged before they are made.
  charge.transient(static_cast<double>(n) * n * n * sizeof(int) * 8.0 / 7.0);
  const double acc_block = 1024.0 * (sizeof(Acc) + nb * sizeof(double) + 16.0);
  std::vector<int> fine_acc(static_cast<std::size_t>(n) * n * n, -1);
  std::vector<Acc> accs;
  double spec_area = 0.0, spec_shininess = 0.0;
  auto cell_of = [&](float x, int axis) {
    return std::clamp(static_cast<int>((x - g.lo[axis]) / cs[axis]), 0, n - 1);
  };
  for (std::size_t t = 0; t < source.size(); ++t) {
    const Vec3 a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
    const Vec3 cr = cross(b - a, c - a);
    const float len = length(cr);
    if (!(len > 0.0f)) continue;
    // The normal the triangle is shaded with: its vertex normals' at the centroid when it has
    // them (on the side of its facet), else the facet's.
    Vec3 normal = cr / len;
    if (!mesh.vertex_normals.empty()) {
      const Vec3 smooth = interpolate(mesh.vertex_normals[source[t]], 1.0f / 3, 1.0f / 3);
      if (smooth != Vec3{}) normal = dot(smooth, normal) < 0 ? -smooth : smooth;
    }
    const OctahedralLerp nl = OctahedralLerp::of(normal, g.normal_res);
    const Vec3 colour = mesh.bake_colour(source[t]);
    const Surface& m = mesh.materials[mesh.prims.material(source[t])];
    const Vec3 tlo = min(a, min(b, c)), thi = max(a, max(b, c));
    int c0[3], c1[3];
    for (int k = 0; k < 3; ++k) c0[k] = cell_of(tlo[k], k), c1[k] = cell_of(thi[k], k);
    const double whole = 0.5 * static_cast<double>(len);
    if (m.reflectance > 0.0f)
      spec_area += whole * m.reflectance, spec_shininess += whole * m.reflectance * m.shininess;
    for (int z = c0[2]; z <= c1[2]; ++z)
      for (int y = c0[1]; y <= c1[1]; ++y)
        for (int x = c0[0]; x <= c1[0]; ++x) {
          double area = whole;
          if (c0[0] != c1[0] || c0[1] != c1[1] || c0[2] != c1[2]) {
            Poly p, q;
            p.v[0] = a, p.v[1] = b, p.v[2] = c, p.n = 3;
            const int at[3] = {x, y, z};
            for (int k = 0; k < 3 && p.n; ++k) {
              const float l = g.lo[k] + cs[k] * static_cast<float>(at[k]);
              clip(p, k, l, -1.0f, q);         // keep p[k] >= l
              clip(q, k, l + cs[k], 1.0f, p);  // keep p[k] <= l + cs
            }
            area = polygon_area(p);
          }
          if (!(area > 0.0)) continue;
          const std::size_t lin = (static_cast<std::size_t>(z) * n + y) * n + x;
          if (fine_acc[lin] < 0) {
            if (accs.size() % 1024 == 0) charge.transient(acc_block);
            fine_acc[lin] = static_cast<int>(accs.size());
            accs.emplace_back().hist.assign(static_cast<std::size_t>(nb), 0.0);
          }
          Acc& acc = accs[static_cast<std::size_t>(fine_acc[lin])];
          acc.area += area;
          for (int k = 0; k < 3; ++k) acc.albedo[k] += area * colour[k];
          acc.reflectance += area * m.reflectance;
          for (int k = 0; k < 4; ++k)
            acc.hist[static_cast<std::size_t>(nl.bin[k])] += area * nl.w[k];
        }
  }
  if (spec_area > 0.0) g.shininess = static_cast<float>(spec_shininess / spec_area);
  g.grain = surface_grain(tris);

  // Coarser levels: each cell the sum of its children. per_level[L][lin] -> accumulator.
  std::vector<std::vector<int>> per_level(static_cast<std::size_t>(g.levels));
  per_level[static_cast<std::size_t>(fine)] = std::move(fine_acc);
  for (int L = fine - 1; L >= 0; --L) {
    const int m = 1 << L;
    std::vector<int>& cur = per_level[static_cast<std::size_t>(L)];
    const std::vector<int>& child = per_level[static_cast<std::size_t>(L + 1)];
    cur.assign(static_cast<std::size_t>(m) * m * m, -1);
    for (int z = 0; z < 2 * m; ++z)
      for (int y = 0; y < 2 * m; ++y)
        for (int x = 0; x < 2 * m; ++x) {
          const int ci = child[(static_cast<std::size_t>(z) * 2 * m + y) * 2 * m + x];
          if (ci < 0) continue;
          const std::size_t lin = (static_cast<std::size_t>(z / 2) * m + y / 2) * m + x / 2;
          if (cur[lin] < 0) {
            if (accs.size() % 1024 == 0) charge.transient(acc_block);
            cur[lin] = static_cast<int>(accs.size());
            accs.emplace_back().hist.assign(static_cast<std::size_t>(nb), 0.0);
          }
          // (a reference into accs would dangle after emplace_back above: index twice)
          Acc sum = accs[static_cast<std::size_t>(cur[lin])];
          sum.add(accs[static_cast<std::size_t>(ci)]);
          accs[static_cast<std::size_t>(cur[lin])] = std::move(sum);
        }
  }

  store_cells(g, per_level, accs, charge);
  bake_coverage(g, tris, config);
  return g;
}

}  // namespace amalgam

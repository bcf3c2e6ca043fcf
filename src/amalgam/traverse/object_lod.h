#pragma once
/// \file The level-of-detail policy and opacity model of the volumetric renderer: the BVH walk
/// over the instanced hierarchy asks, at each instance's root, whether the ray's cone there is
/// wide enough for the instance's cells (traverse/cone_march.h, choose_cell_level). If so the
/// instance is *deferred*: recorded with the depth where the ray enters it, not descended, and
/// marched through its cells afterwards (render/volume_integrator.h); else the walk descends
/// and traces its triangles. The switch is per whole object, never inside one, so a ray never
/// composites part of an object as cells and part as triangles. Before that, an instance (or a
/// top-tree node whose every instance) is absorbed into the world cells at the level the ray's
/// cone reads there (world_cells.h) is culled: the world cells stand for it.

#include <cstdint>

#include "amalgam/hierarchy/instanced.h"
#include "amalgam/hierarchy/volume/volume_set.h"
#include "amalgam/traverse/cone_march.h"
#include "amalgam/traverse/opacity.h"
#include "amalgam/util/isa.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

struct ObjectLod {
  const InstancedHierarchy* h = nullptr;
  const VolumeSet* volumes = nullptr;
  float cell_pixels = 1.0f;  ///< cells of this many cone widths (--footprint)
  /// The instance (+ 1; 0: none) the ray leaves from: traced at full detail (`self_full`, a
  /// shadow ray from one of its triangles) or deferred and skipped by the integrator (a shadow
  /// query from one of its cells: its self-shadowing is in the cells' bake).
  std::uint64_t self = 0;
  bool self_full = false;
  /// Whether an instance whose box holds the ray's origin may be deferred (shadow queries:
  /// the cells between the origin and the light count); camera rays trace it at full detail.
  bool defer_inside = false;
  /// Whether this query reads cells at all (world cells included): false under the light
  /// probe's camera-triangles (camera rays) or shadow-triangles (shadow rays), util/probe.h.
  bool cells = true;

  /// Every node may be an instance root, so every node tested counts as an amalgam (as under
  /// ScaleSensitiveLod by footprint).
  bool may_render(int) const { return true; }
  bool render(const Bbox&, int, const Ray&, float, bool) const { return false; }

  /// The level of the instance `slot` (index + 1) for this ray: >= grid.levels means full
  /// detail.
  int level_for(const CellGrid& g, std::uint64_t slot, const Ray& r, float t,
                std::uint64_t key) const {
    const float width = r.footprint(t) / volumes->instance_scale[slot - 1];
    return choose_cell_level(g, width, cell_pixels, level_choice_u(key, slot));
  }

  /// Whether node `id` (a top-tree node or an instance root), entered at t by ray r keyed
  /// `key`, is absorbed into the world cells the ray reads there. Consistent down the tree: a
  /// node's instances are entered no nearer, where the level read is no finer.
  bool absorbed(NodeId id, const Ray& r, float t, std::uint64_t key) const {
    const WorldCells& w = volumes->world;
    if (w.empty()) return false;
    const std::uint64_t slot = InstancedHierarchy::slot(id);
    const int a = slot == 0                            ? w.top_absorb[id]
                  : InstancedHierarchy::local(id) == 0 ? w.absorb[slot - 1]
                                                       : -1;
    return a >= 0 && w.level_at(r.footprint(t), cell_pixels, world_level_u(key)) <= a;
  }

  /// Defer node `id` (entered at t by ray r keyed `key`)? Absorbed nodes are deferred too
  /// (and passed by the sink).
  bool render_node(NodeId id, const Bbox&, int, const Ray& r, float t, bool inside,
                   std::uint64_t key) const {
    if (!cells) return false;
    const std::uint64_t slot = InstancedHierarchy::slot(id);
    const bool root = slot != 0 && InstancedHierarchy::local(id) == 0;
    if (root && slot == self) return !self_full;
    if (absorbed(id, r, t, key)) return true;
    if (!root) return false;
    const CellGrid* g = volumes->grid(h->instances[slot - 1].mesh);
    if (!g) return false;
    if (inside && !defer_inside) return false;
    return level_for(*g, slot, r, t, key) < g->levels;
  }
};

/// Where the walk hands a deferred instance as soon as it meets it (render/volume_integrator.h
/// marches it there and then): `ray` is the walk's ray, whose tmax the sink may lower (nothing
/// beyond can show) and whose walk it may end (`done`, with `transmittance` set).
class DeferSink {
 public:
  virtual void deferred(NodeId root, int level, float t, Ray& ray, std::uint64_t key, bool shadow,
                        bool& done, float& transmittance) = 0;

 protected:
  ~DeferSink() = default;
};

/// Every instance the policy renders is deferred, for camera and shadow rays alike: handed to
/// `sink`, or without one recorded (TranslucentHit: entry depth, the root's id and level), and
/// passed.
struct DeferredOpacity {
  static constexpr bool kBlends = true;
  static constexpr bool kSaturates = false;
  static constexpr bool kDefers = true;
  DeferSink* sink = nullptr;
  AmalgamEffect effect(float, std::uint64_t, NodeId, bool) const { return AmalgamEffect::kBlend; }
};

AMALGAM_ISA_END
}  // namespace amalgam

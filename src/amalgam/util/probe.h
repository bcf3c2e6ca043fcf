#pragma once
/// \file Measurement switches of the light path: which terms of the light reaching what the
/// camera sees the renderers compute, so that their error against full detail can be split by
/// term (scripts/bias_terms.py, docs/volumetric/bias-terms.md). Read once per process from
/// the environment variable AMALGAM_LIGHT_PROBE, a comma-separated list of the switches below
/// (unset or empty: every term, the production configuration); the stats JSON records it
/// (`light_probe`). Not a rendering option: a probe changes the estimator on purpose.

#include <string>

namespace amalgam {

struct LightProbe {
  /// `no-shadows`: every shadow ray reaches its light (both renderers; no ray is traced).
  bool shadows = true;
  /// `no-hot-spot` (volumetric): cells attenuate a shadow ray over their whole chord, never
  /// only beside the camera cone that reached its origin.
  bool hot_spot = true;
  /// `no-other-hot-spot` (volumetric): as `no-hot-spot` for the cells of the instances a shadow
  /// ray does not leave from and the world cells only; the cells of its own instance keep theirs
  /// (with `lit-share`, its seen-and-lit correction).
  bool other_hot_spot = true;
  /// `grain-hot-spot` (volumetric): an object's cells keep a shadow ray's hot spot as wide as
  /// two of the object's grains (its pieces' size, as world cells do), not the camera cone's
  /// width: a candidate model, measured beside the production one.
  bool cone_hot_spot = true;
  /// `lit-share` (volumetric): an open object shadows its own surfaces as a closed one does,
  /// by its cells' lit share toward the light from the bake, corrected for the surfaces the
  /// camera sees (CellGrid::seen_lit, traverse/lit_ratio.h, baked only under this switch;
  /// `no-hot-spot` leaves the correction out), instead of marching its own cells from a point
  /// in space; shadow rays leaving at more than 90 degrees from the viewer keep no hot spot in
  /// other objects' cells. A candidate model (docs/volumetric/lit-share.md).
  bool march_self = true;
  /// `no-self-cells`, `no-other-cells`, `no-world-cells` (volumetric): shadow rays pass the
  /// cells of the instance they leave from, of the other instances, or the world cells
  /// (triangles met at full detail always occlude).
  bool self_cells = true, other_cells = true, world_cells = true;
  /// `camera-triangles` (volumetric): camera rays defer nothing and read no world cells (full
  /// detail); shadow rays from their hits still go through cells.
  bool camera_cells = true;
  /// `shadow-triangles` (volumetric): shadow rays defer nothing and read no world cells: every
  /// occluder at full detail, from where the camera side put the shadow ray's origin.
  bool shadow_cells = true;
  /// `lines=N` (N in 1..64): lines per finest-cell width of the cells' coverage bake
  /// (VolumeConfig::lines); 0: the configuration's own.
  int lines = 0;

  bool is_default() const;
  /// The switches as they were given, normalised (sorted, comma-separated; "" by default).
  std::string describe() const;
  /// Parses `text`; throws InputError naming AMALGAM_LIGHT_PROBE on an unknown switch.
  static LightProbe parse(const std::string& text);
};

/// The process's probe (AMALGAM_LIGHT_PROBE, parsed on first use).
const LightProbe& light_probe();

}  // namespace amalgam

#pragma once
/// \file Intel Embree 3 as a Tracer (render/tracer.h): any loaded scene rendered at full detail
/// through the same pass loop and Integrator as amalgam's traversal. Built only when Embree is
/// found (CMake option AMALGAM_EMBREE; library amalgam_embree, macro AMALGAM_HAVE_EMBREE); made
/// through `make_tracer`.
///
/// Embree's copy of the scene: triangles as Embree triangle meshes; spheres and boxes as Embree
/// user geometry whose callbacks call the hierarchy's own intersect() (the same surfaces, bit
/// for bit); an instanced scene as one Embree scene per mesh and one Embree instance per
/// instance with the same 3x4 transform; an implicit builtin's primitives listed once. Closest
/// hits by rtcIntersect1, shadow rays by rtcOccluded1, where a triangle's occlusion filter
/// keeps only hits amalgam's own test of it accepts (Embree's transform into an instance can
/// put a shadow ray behind the triangle it leaves; docs/embree.md). A hit's surface (point,
/// normal, error bound for the shadow-ray origin) is recomputed by the hierarchy's own test of
/// the one primitive Embree found, so shading matches the traditional renderer wherever both
/// hit the same primitive. Embree counts no intersection tests: the counters hold rays only.

#include <memory>

#include "amalgam/render/tracer.h"

namespace amalgam {

/// The most primitives of an implicit builtin Embree's copy lists (2^26: some GB).
inline constexpr double kMaxEmbreeListedPrimitives = 67108864.0;

/// Builds Embree's BVHs of `scene` (which must outlive the tracer). `threads` > 0 caps Embree's
/// build threads (device config "threads=N"); 0: Embree's default (all hardware threads).
/// Throws InputError when an implicit builtin has more primitives than
/// kMaxEmbreeListedPrimitives, RuntimeError when Embree fails (e.g. out of memory). Called by
/// make_tracer, which checks the options first.
std::unique_ptr<Tracer> make_embree_tracer(const LoadedScene& scene, int threads,
                                           const EmbreeBuild& build);

}  // namespace amalgam

// The AVX2 copy of the hot paths (util/isa.h). Everything below the traversal is included
// first, compiled for the baseline like the rest of the library; then AMALGAM_AVX2_BEGIN (a
// target pragma, util/isa.h) compiles the traversal, its kernels, the integrator and the pass
// loop for AVX2, in the inline namespace isa_avx2 (AMALGAM_ISA_AVX2), so no symbol is shared
// with the portable copy. Every header included after AMALGAM_AVX2_BEGIN must be one of those
// ISA-namespaced hot-path headers: a lower header first included there would give an AVX2 body
// to a function of the portable library.
#if defined(AMALGAM_BUILD_AVX2_COPY)
#define AMALGAM_ISA_AVX2 1  // before any include: util/isa.h reads it once

// Standard and third-party headers the hot paths use, before the pragma.
#include <oneapi/tbb/blocked_range2d.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <numbers>
#include <type_traits>
#include <utility>
#include <vector>

// The lower layers, before the pragma: compiled for the baseline.
#include "amalgam/geometry/intersect.h"
#include "amalgam/geometry/wide.h"
#include "amalgam/hierarchy/hierarchy.h"
#include "amalgam/hierarchy/volume/cells.h"
#include "amalgam/hierarchy/volume/octahedral.h"
#include "amalgam/hierarchy/volume/volume_set.h"
#include "amalgam/hierarchy/wide.h"
#include "amalgam/math/random.h"
#include "amalgam/render/loaded_scene.h"
#include "amalgam/render/pass_blocks.h"
#include "amalgam/render/render.h"
#include "amalgam/render/render_isa.h"
#include "amalgam/stats/counters.h"
#include "amalgam/traverse/hit.h"
#include "amalgam/traverse/lod.h"
#include "amalgam/traverse/opacity.h"
#include "amalgam/traverse/order.h"
#include "amalgam/util/isa.h"

AMALGAM_AVX2_BEGIN
#include "amalgam/render/render_isa.inl"
AMALGAM_AVX2_END

#endif

#pragma once
/// \file Which SIMD instruction set the hot paths run with, chosen at run time.
///
/// The library is compiled for the portable x86-64 baseline (SSE2; a scalar loop elsewhere).
/// The traversal, its kernels and the integrator are compiled a second time for AVX2 (between
/// AMALGAM_AVX2_BEGIN and AMALGAM_AVX2_END, in render/render_avx2.cpp) into the inline namespace
/// `isa_avx2`, so the two copies never share a symbol; `render` and `trace` pick one per call with
/// `active_simd`. Both give the same bits (tests/traverse/simd_test.cpp,
/// tests/render/isa_test.cpp).
///
/// Headers of the hot paths wrap their code in `AMALGAM_ISA_BEGIN` / `AMALGAM_ISA_END`; a
/// translation unit that defines AMALGAM_ISA_AVX2 before including them gets the AVX2 copy.

#include <string>

#if defined(AMALGAM_ISA_AVX2)
#define AMALGAM_ISA_NS isa_avx2
#else
#define AMALGAM_ISA_NS isa_portable
#endif
#define AMALGAM_ISA_BEGIN inline namespace AMALGAM_ISA_NS {
#define AMALGAM_ISA_END }

namespace amalgam {

enum class Simd : unsigned char { kPortable, kAvx2 };

/// Whether this binary holds the AVX2 copy (GCC and clang builds for x86-64).
bool simd_avx2_built();
/// Whether the CPU running this process supports AVX2.
bool simd_avx2_supported();

/// The instruction set used: the environment variable AMALGAM_SIMD ("portable", "avx2" or
/// "auto"; unset = "auto") read once; "auto" is AVX2 when built and supported. Throws
/// InputError for another value, or for "avx2" on a CPU or build without it.
Simd active_simd();

/// "portable" or "avx2".
std::string simd_name(Simd s);

}  // namespace amalgam

/// `name` with the suffix of the instruction set being compiled: the entry points of the
/// per-ISA copies (render/render_isa.h).
#if defined(AMALGAM_ISA_AVX2)
#define AMALGAM_ISA_SUFFIXED(name) name##_avx2
#else
#define AMALGAM_ISA_SUFFIXED(name) name##_portable
#endif

/// Everything between these two is compiled for AVX2: GCC's target pragma, or on clang a target
/// attribute pushed onto every function declared in between.
#if defined(__clang__)
#define AMALGAM_AVX2_BEGIN \
  _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define AMALGAM_AVX2_END _Pragma("clang attribute pop")
#else
#define AMALGAM_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define AMALGAM_AVX2_END _Pragma("GCC pop_options")
#endif

#include "amalgam/util/isa.h"

#include <cstdlib>

#include "amalgam/util/error.h"

namespace amalgam {

bool simd_avx2_built() {
#if defined(AMALGAM_BUILD_AVX2_COPY)
  return true;
#else
  return false;
#endif
}

bool simd_avx2_supported() {
#if defined(__x86_64__) && defined(__GNUC__)
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

Simd active_simd() {
  static const Simd chosen = [] {
    const char* env = std::getenv("AMALGAM_SIMD");
    const std::string v = env ? env : "auto";
    const bool avx2 = simd_avx2_built() && simd_avx2_supported();
    if (v == "auto" || v.empty()) return avx2 ? Simd::kAvx2 : Simd::kPortable;
    if (v == "portable") return Simd::kPortable;
    if (v == "avx2") {
      if (!avx2)
        throw InputError(
            std::string("AMALGAM_SIMD=avx2: ") +
            (simd_avx2_built() ? "this CPU does not support AVX2" : "this build has no AVX2 code"));
      return Simd::kAvx2;
    }
    throw InputError("AMALGAM_SIMD=" + one_line(v, 40) + ": expected portable, avx2 or auto");
  }();
  return chosen;
}

std::string simd_name(Simd s) {
  return s == Simd::kAvx2 ? "avx2" : "portable";
}

}  // namespace amalgam

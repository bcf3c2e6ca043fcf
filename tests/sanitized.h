#pragma once
/// \file Whether this test binary runs under AddressSanitizer (GCC defines __SANITIZE_ADDRESS__,
/// clang answers __has_feature): tests that cannot run there, or run 10x slower, ask this.

#if defined(__SANITIZE_ADDRESS__)
#define AMALGAM_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define AMALGAM_TEST_ASAN 1
#endif
#endif
#if !defined(AMALGAM_TEST_ASAN)
#define AMALGAM_TEST_ASAN 0
#endif

namespace amalgam {
inline constexpr bool kSanitized = AMALGAM_TEST_ASAN != 0;
}  // namespace amalgam

#pragma once
/// \file AMALGAM_CHECK: internal invariants, checked in every build type.
///
/// For conditions that only a bug can violate (a fixed-size buffer about to overflow, a count
/// that must fit its field): throws InternalError naming the file, line and condition. Never
/// for user input (that is an InputError, error.h). Cheap enough for build and load paths; not
/// used inside per-ray loops.

#include <string>

#include "amalgam/util/error.h"

namespace amalgam::detail {
[[noreturn]] void check_failed(const char* cond, const char* file, int line,
                               const std::string& what);
}  // namespace amalgam::detail

#define AMALGAM_CHECK(cond, what)                                         \
  do {                                                                    \
    if (!(cond)) [[unlikely]]                                             \
      ::amalgam::detail::check_failed(#cond, __FILE__, __LINE__, (what)); \
  } while (false)

namespace amalgam {

/// `value` converted to the narrower integer type `To`, checked to fit (AMALGAM_CHECK).
template <class To, class From>
To checked_narrow(From value, const char* what) {
  const To to = static_cast<To>(value);
  AMALGAM_CHECK(static_cast<From>(to) == value && ((to < To{}) == (value < From{})), what);
  return to;
}

}  // namespace amalgam

#pragma once
/// \file AMALGAM_CHECK: internal invariants, checked in every build type.
///
/// For conditions that only a bug can violate (a fixed-size buffer about to overflow, a count
/// that must fit its field): throws InternalError naming the file, line and condition. Never
/// for user input (that is an InputError, error.h). Cheap enough for build and load paths; not
/// used inside per-ray loops.

#include <sstream>
#include <string>
#include <type_traits>

#include "amalgam/util/error.h"

namespace amalgam::detail {
[[noreturn]] void check_failed(const char* cond, const char* file, int line,
                               const std::string& what);

/// A value as a check failure prints it: numbers and enums as numbers, else "?".
template <class T>
std::string check_value(const T& v) {
  if constexpr (std::is_enum_v<T>) {
    return std::to_string(static_cast<long long>(v));
  } else if constexpr (std::is_arithmetic_v<T>) {
    std::ostringstream o;
    o << +v;
    return o.str();
  } else {
    return "?";
  }
}

template <class A, class B>
[[noreturn]] void check_op_failed(const char* cond, const A& a, const B& b, const char* file,
                                  int line, const std::string& what) {
  const std::string c = std::string(cond) + " (" + check_value(a) + " vs " + check_value(b) + ")";
  check_failed(c.c_str(), file, line, what);
}
}  // namespace amalgam::detail

#define AMALGAM_CHECK(cond, what)                                         \
  do {                                                                    \
    if (!(cond)) [[unlikely]]                                             \
      ::amalgam::detail::check_failed(#cond, __FILE__, __LINE__, (what)); \
  } while (false)

/// AMALGAM_CHECK_EQ(a, b, what) and its kin: the comparison a OP b, each side evaluated once;
/// a failure names both values ("n <= kMaxChildren (9 vs 8)"), as pbrt-v4's CHECK_EQ does.
#define AMALGAM_CHECK_OP(a, op, b, what)                                                        \
  do {                                                                                          \
    const auto& amalgam_check_a_ = (a);                                                         \
    const auto& amalgam_check_b_ = (b);                                                         \
    if (!(amalgam_check_a_ op amalgam_check_b_)) [[unlikely]]                                   \
      ::amalgam::detail::check_op_failed(#a " " #op " " #b, amalgam_check_a_, amalgam_check_b_, \
                                         __FILE__, __LINE__, (what));                           \
  } while (false)
#define AMALGAM_CHECK_EQ(a, b, what) AMALGAM_CHECK_OP(a, ==, b, what)
#define AMALGAM_CHECK_NE(a, b, what) AMALGAM_CHECK_OP(a, !=, b, what)
#define AMALGAM_CHECK_LT(a, b, what) AMALGAM_CHECK_OP(a, <, b, what)
#define AMALGAM_CHECK_LE(a, b, what) AMALGAM_CHECK_OP(a, <=, b, what)
#define AMALGAM_CHECK_GT(a, b, what) AMALGAM_CHECK_OP(a, >, b, what)
#define AMALGAM_CHECK_GE(a, b, what) AMALGAM_CHECK_OP(a, >=, b, what)

/// AMALGAM_DCHECK and AMALGAM_DCHECK_EQ, ...: the same checks in debug builds only (NDEBUG
/// unset), for invariants on hot paths. In release builds the condition is compiled (so it
/// stays valid code) but never evaluated.
#ifdef NDEBUG
#define AMALGAM_DCHECK(cond, what) \
  do {                             \
    if (false) {                   \
      (void)(cond);                \
      (void)(what);                \
    }                              \
  } while (false)
#define AMALGAM_DCHECK_OP(a, op, b, what) AMALGAM_DCHECK((a)op(b), what)
#else
#define AMALGAM_DCHECK(cond, what) AMALGAM_CHECK(cond, what)
#define AMALGAM_DCHECK_OP(a, op, b, what) AMALGAM_CHECK_OP(a, op, b, what)
#endif
#define AMALGAM_DCHECK_EQ(a, b, what) AMALGAM_DCHECK_OP(a, ==, b, what)
#define AMALGAM_DCHECK_LT(a, b, what) AMALGAM_DCHECK_OP(a, <, b, what)
#define AMALGAM_DCHECK_LE(a, b, what) AMALGAM_DCHECK_OP(a, <=, b, what)

namespace amalgam {

/// `value` converted to the narrower integer type `To`, checked to fit (AMALGAM_CHECK).
template <class To, class From>
To checked_narrow(From value, const char* what) {
  const To to = static_cast<To>(value);
  AMALGAM_CHECK(static_cast<From>(to) == value && ((to < To{}) == (value < From{})), what);
  return to;
}

}  // namespace amalgam

// util/error.h: one classification of failures, from which the CLI's exit status and the
// Python module's exception both follow (python/amalgam_module.cpp translates by the same
// types).

#include "amalgam/util/error.h"

#include <gtest/gtest.h>

#include <new>
#include <stdexcept>

#include "amalgam/analysis/formulas.h"
#include "amalgam/analysis/metrics.h"
#include "amalgam/scene/sky.h"
#include "amalgam/util/check.h"

namespace amalgam {
namespace error_test {

TEST(ErrorKind, EveryFailureHasOneKindAndOneExitStatus) {
  EXPECT_EQ(error_kind(InputError("scene.json: bad")), ErrorKind::kInput);
  EXPECT_EQ(exit_status(InputError("x")), 2);
  EXPECT_EQ(error_kind(RuntimeError("disk full")), ErrorKind::kRuntime);
  EXPECT_EQ(exit_status(RuntimeError("x")), 1);
  EXPECT_EQ(error_kind(InternalError("broken invariant")), ErrorKind::kInternal);
  EXPECT_EQ(error_kind(MetricsError("sizes differ")), ErrorKind::kInternal);
  EXPECT_EQ(error_kind(std::invalid_argument("x")), ErrorKind::kInternal);
  EXPECT_EQ(exit_status(InternalError("x")), 1);
  EXPECT_EQ(error_kind(std::runtime_error("x")), ErrorKind::kRuntime);
  EXPECT_EQ(error_kind(std::bad_alloc()), ErrorKind::kRuntime);
}

// What the library throws is in the taxonomy: a formula called outside its domain is a bug
// of the caller; a sky map with no light is bad input.
TEST(ErrorKind, LibraryFunctionsThrowTheirKind) {
  try {
    formulas::c_t0(0, 3);
    FAIL() << "no throw";
  } catch (const std::exception& e) {
    EXPECT_EQ(error_kind(e), ErrorKind::kInternal) << e.what();
  }
  try {
    SkyMap(1, 1, {Vec3{}});
    FAIL() << "no throw";
  } catch (const std::exception& e) {
    EXPECT_EQ(error_kind(e), ErrorKind::kInput) << e.what();
  }
}

// A failed comparison check names both values; each side is evaluated once.
TEST(Check, ComparisonsPrintTheValuesCompared) {
  int evaluated = 0;
  const auto nine = [&] { return ++evaluated, 9; };
  try {
    AMALGAM_CHECK_LE(nine(), 8, "too many children");
    FAIL() << "no throw";
  } catch (const InternalError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("nine() <= 8 (9 vs 8)"), std::string::npos) << m;
    EXPECT_NE(m.find("too many children"), std::string::npos) << m;
  }
  EXPECT_EQ(evaluated, 1);
  AMALGAM_CHECK_EQ(nine(), 9, "passes");
  EXPECT_EQ(evaluated, 2);
}

// AMALGAM_DCHECK runs in debug builds only: in a release build its condition is not evaluated.
TEST(Check, DcheckRunsOnlyInDebugBuilds) {
  int evaluated = 0;
  const auto fails = [&] { return ++evaluated, false; };
#ifdef NDEBUG
  AMALGAM_DCHECK(fails(), "not evaluated");
  EXPECT_EQ(evaluated, 0);
#else
  EXPECT_THROW(AMALGAM_DCHECK(fails(), "evaluated"), InternalError);
  EXPECT_EQ(evaluated, 1);
#endif
}

}  // namespace error_test
}  // namespace amalgam

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

}  // namespace error_test
}  // namespace amalgam

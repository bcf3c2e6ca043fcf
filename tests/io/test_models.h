#pragma once
/// \file Debian's assimp-testmodels for the import tests: real and broken models no one here
/// wrote, which scripts/deps.sh installs. Missing is a failure, not a skip (a skipped test
/// guards nothing).

#include <gtest/gtest.h>

#include <filesystem>

namespace amalgam::test {

inline const std::filesystem::path kModels = "/usr/share/assimp/models";

}  // namespace amalgam::test

#define REQUIRE_MODELS()                                             \
  ASSERT_TRUE(std::filesystem::is_directory(amalgam::test::kModels)) \
      << amalgam::test::kModels                                      \
      << " is missing: install Debian's assimp-testmodels package "  \
         "(scripts/deps.sh)"

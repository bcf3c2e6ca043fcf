#pragma once
/// \file The library's version (CMake's PROJECT_VERSION), for `--version`, stats and headers.

namespace amalgam {

/// "MAJOR.MINOR.PATCH", as the project declares it in CMakeLists.txt.
const char* version();

}  // namespace amalgam

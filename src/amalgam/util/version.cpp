#include "amalgam/util/version.h"

namespace amalgam {

const char* version() {
  return AMALGAM_VERSION;
}

}  // namespace amalgam

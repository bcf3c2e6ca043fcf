#include "amalgam/scene/coordinate_limit.h"

#include <algorithm>
#include <sstream>

#include "amalgam/util/error.h"

namespace amalgam {

void check_extent(const Bbox& b, const std::string& where) {
  const double m = std::max(max_component(abs(b.lo)), max_component(abs(b.hi)));
  if (!(m <= kMaxCoordinate)) {
    std::ostringstream reach;
    reach << m;
    throw InputError(where + ": the geometry reaches a coordinate of " + reach.str() +
                     ", beyond the supported range [-1e12, 1e12]");
  }
}

}  // namespace amalgam

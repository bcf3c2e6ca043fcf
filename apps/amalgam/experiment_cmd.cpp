#include "common.h"

namespace amalgam::cli {

int run_experiment(const std::string& name, const std::string&, bool, int) {
  throw InputError("experiment '" + name + "': no experiments are built into this version");
}

}  // namespace amalgam::cli

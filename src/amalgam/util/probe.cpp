#include "amalgam/util/probe.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <string_view>
#include <vector>

#include "amalgam/util/error.h"

namespace amalgam {
namespace {

constexpr std::string_view kVariable = "AMALGAM_LIGHT_PROBE";

struct Flag {
  std::string_view name;
  bool LightProbe::*member;
};
constexpr Flag kFlags[] = {
    {"no-shadows", &LightProbe::shadows},
    {"no-hot-spot", &LightProbe::hot_spot},
    {"no-other-hot-spot", &LightProbe::other_hot_spot},
    {"no-self-cells", &LightProbe::self_cells},
    {"no-other-cells", &LightProbe::other_cells},
    {"no-world-cells", &LightProbe::world_cells},
    {"camera-triangles", &LightProbe::camera_cells},
    {"shadow-triangles", &LightProbe::shadow_cells},
    {"grain-hot-spot", &LightProbe::cone_hot_spot},
    {"lit-share", &LightProbe::march_self},
};

}  // namespace

bool LightProbe::is_default() const {
  return describe().empty();
}

std::string LightProbe::describe() const {
  std::vector<std::string> parts;
  for (const Flag& f : kFlags)
    if (!(this->*f.member)) parts.emplace_back(f.name);
  if (lines > 0) parts.push_back("lines=" + std::to_string(lines));
  std::sort(parts.begin(), parts.end());
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : ",") + p;
  return out;
}

LightProbe LightProbe::parse(const std::string& text) {
  LightProbe p;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.empty()) continue;
    const auto flag = std::find_if(std::begin(kFlags), std::end(kFlags),
                                   [&](const Flag& f) { return f.name == item; });
    if (flag != std::end(kFlags)) {
      p.*(flag->member) = false;
    } else if (item.rfind("lines=", 0) == 0) {
      const std::string n = item.substr(6);
      char* end = nullptr;
      const long v = std::strtol(n.c_str(), &end, 10);
      if (n.empty() || *end != '\0' || v < 1 || v > 64)
        fail_input(std::string(kVariable), "'" + item + "': lines must be 1 .. 64");
      p.lines = static_cast<int>(v);
    } else {
      fail_input(std::string(kVariable),
                 "unknown switch '" + item +
                     "' (no-shadows, no-hot-spot, no-other-hot-spot, no-self-cells, "
                     "no-other-cells, no-world-cells, camera-triangles, shadow-triangles, "
                     "grain-hot-spot, lit-share, lines=N)");
    }
  }
  return p;
}

const LightProbe& light_probe() {
  static const LightProbe probe = [] {
    const char* e = std::getenv(kVariable.data());
    return e == nullptr ? LightProbe{} : LightProbe::parse(e);
  }();
  return probe;
}

}  // namespace amalgam

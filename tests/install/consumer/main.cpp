// Renders a small image of a builtin scene and a mesh through the installed library and prints
// what a user would check: the version, the exact test count and the mean pixel value.
#include <cstdio>
#include <string>

#include "amalgam/analysis/experiments.h"
#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "amalgam/util/version.h"

int main(int argc, char** argv) {
  using namespace amalgam;
  const std::string spec = argc > 1 ? argv[1] : "builtin:line";
  const LoadedScene scene = load_scene(spec, Params{});
  RenderOptions o;
  o.width = 32;
  o.height = 24;
  o.spp = 2;
  o.threads = 1;
  const RenderOutput r = render(scene, o);
  double sum = 0;
  for (const Vec3& c : r.image) sum += c.x + c.y + c.z;
  std::printf("amalgam %s: %s %dx%d, %llu tests, mean %.6f, %zu experiments\n", version(),
              spec.c_str(), r.width, r.height, static_cast<unsigned long long>(r.counters.total()),
              sum / (3.0 * r.image.size()), experiments::names().size());
  return 0;
}

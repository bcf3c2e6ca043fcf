// Kernel benchmarks. Run: ./build/bench/amalgam_bench
// CountersOverhead/*: the same primary rays traced with exact counters and with counting
// compiled out (NullCounters), side by side in one process; the ratio is the counters' cost.

#include <benchmark/benchmark.h>

#include "amalgam/load/load_scene.h"
#include "amalgam/render/integrator.h"

namespace amalgam {
namespace {

template <class Stats, class Lod>
void trace_image(benchmark::State& state, const char* scene_depth, Lod lod) {
  Params p("builtin:prisms");
  p.set("depth", scene_depth);
  p.set("view", "corner");
  const LoadedScene scene = load_scene("builtin:prisms", p);
  const auto& h = std::get<PrismsHierarchy>(scene.hierarchy);
  Stats stats;
  Integrator<PrismsHierarchy, Lod, StochasticOpacity, SortedOrder, Stats> integ(h, scene.env, lod,
                                                                                stats);
  const int w = 128, hgt = 128;
  std::uint64_t rays = 0;
  for (auto _ : state) {
    Vec3 sum{};
    for (int y = 0; y < hgt; ++y)
      for (int x = 0; x < w; ++x) {
        const Ray r = scene.env.camera.generate(x + 0.5f, y + 0.5f, w, hgt);
        sum += integ.li(r, hash_combine(y, x)).colour;
      }
    benchmark::DoNotOptimize(sum);
    rays += static_cast<std::uint64_t>(w) * hgt;
  }
  state.counters["primary_rays_per_s"] =
      benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
}

void Traditional_Counted(benchmark::State& s) {
  trace_image<Counters>(s, "7", TraditionalLod{});
}
void Traditional_Uncounted(benchmark::State& s) {
  trace_image<NullCounters>(s, "7", TraditionalLod{});
}
void Footprint_Counted(benchmark::State& s) {
  trace_image<Counters>(s, "10", ScaleSensitiveLod::by_footprint(1.0f));
}
void Footprint_Uncounted(benchmark::State& s) {
  trace_image<NullCounters>(s, "10", ScaleSensitiveLod::by_footprint(1.0f));
}
BENCHMARK(Traditional_Counted)->Unit(benchmark::kMillisecond);
BENCHMARK(Traditional_Uncounted)->Unit(benchmark::kMillisecond);
BENCHMARK(Footprint_Counted)->Unit(benchmark::kMillisecond);
BENCHMARK(Footprint_Uncounted)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace amalgam

BENCHMARK_MAIN();

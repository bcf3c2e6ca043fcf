#pragma once
/// \file Helpers shared by the experiments (analysis/experiments/<name>.cpp, one file per
/// experiment): scene loading and tracing of the default (centre) ray.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "amalgam/analysis/experiments.h"
#include "amalgam/render/render.h"

namespace amalgam::experiments::detail {

/// Running mean of samples with its standard error.
struct Mean {
  double sum = 0, sum2 = 0;
  int count = 0;
  void add(double v) { sum += v, sum2 += v * v, ++count; }
  double mean() const { return sum / count; }
  double se() const {
    const double m = mean();
    const double var = std::max(0.0, (sum2 / count - m * m)) * count / std::max(1, count - 1);
    return std::sqrt(var / count);
  }
};

/// Loads builtin:`name` with the given key=value parameters.
inline LoadedScene scene(const std::string& name,
                         std::initializer_list<std::pair<std::string, std::string>> kv) {
  Params p("builtin:" + name);
  for (const auto& [k, v] : kv) p.set(k, v);
  return load_builtin("builtin:" + name, p);
}

inline std::string str(double v) {
  return fmt(v);
}

/// Traces the scene's default ray (the centre pixel's ray of `trace`).
inline TraceOutput trace_centre(const LoadedScene& s, const RenderOptions& o) {
  return trace(s, o, s.env.camera.centre_ray(o.width, o.height));
}

inline RenderOptions traditional() {
  RenderOptions o;
  o.lod = FullDetail{};
  return o;
}

inline RenderOptions at_level(int l1, OpacityKind op = OpacityKind::kStochastic) {
  RenderOptions o;
  o.lod = OnLevel{l1};
  o.opacity = op;
  return o;
}

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Gives every check added since the last call (those with no statement yet) statement `id`.
inline void tag(ExperimentResult& r, const std::string& id) {
  for (Check& c : r.checks)
    if (c.statement.empty()) c.statement = id;
}

inline double u(std::uint64_t v) {
  return static_cast<double>(v);
}

/// Exact shadow tests of deterministic opacity on builtin:line (alpha < 1) at level l1:
/// b + n sum_{m=0}^{l1-1} (b (n^m + 1)/2 - n^m), b = n^l1 (tests/traverse/paper_counts_test).
inline double line_deterministic_shadow(int n, int l1) {
  double b = 1;
  for (int i = 0; i < l1; ++i) b *= n;
  double total = b, nm = 1;
  for (int m = 0; m < l1; ++m, nm *= n) total += n * (b * (nm + 1) / 2 - nm);
  return total;
}

/// Rec. 709 luma of a pixel, in double precision (the noise experiments' variance is taken on it).
inline double luma(const Vec3& v) {
  return 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
}

}  // namespace amalgam::experiments::detail

#include "amalgam/analysis/experiments.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "amalgam/util/error.h"

namespace amalgam::experiments {

std::size_t Table::col(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return i;
  throw std::out_of_range("experiment table: no column '" + name + "'");
}

bool Check::passed() const {
  if (std::isnan(measured) || std::isnan(predicted)) return false;
  return std::fabs(measured - predicted) <= tolerance;
}

const char* to_string(Verdict v) {
  switch (v) {
    case Verdict::kHolds:
      return "holds";
    case Verdict::kHoldsWithCorrection:
      return "holds with correction";
    case Verdict::kDoesNotHold:
      return "does not hold";
    case Verdict::kNotMeasured:
      return "not checked";
  }
  return "?";
}

Verdict verdict_of(const std::vector<Check>& checks) {
  bool corrected = false, evidence = false, harness_failed = false;
  for (const Check& c : checks) {
    if (c.role == Role::kSupports && !c.passed()) return Verdict::kDoesNotHold;
    if (c.role == Role::kRefutesPrinted && c.passed()) corrected = true;
    if (c.role == Role::kHarness && !c.passed()) harness_failed = true;
    evidence = evidence || is_evidence(c);
  }
  if (!evidence || harness_failed) return Verdict::kNotMeasured;
  return corrected ? Verdict::kHoldsWithCorrection : Verdict::kHolds;
}

std::optional<Verdict> verdict_of(const std::vector<Check>& checks, const std::string& id) {
  std::vector<Check> mine;
  for (const Check& c : checks)
    if (c.statement == id) mine.push_back(c);
  if (mine.empty()) return std::nullopt;
  return verdict_of(mine);
}

double predict(const Config& config, const std::string& name, double value) {
  return config.perturb ? config.perturb(name, value) : value;
}

const std::vector<std::string>& names() {
  static const std::vector<std::string> n = {"worst-traditional",
                                             "worst-stochastic",
                                             "worst-deterministic",
                                             "expected",
                                             "traversed",
                                             "failed-tests",
                                             "lights",
                                             "noise",
                                             "noise-baked",
                                             "more-levels",
                                             "linear-cost",
                                             "p-vs-P",
                                             "sorting",
                                             "premise"};
  return n;
}

ExperimentResult run(const std::string& name, const Config& config) {
  using Fn = ExperimentResult (*)(const Config&);
  static const std::vector<std::pair<std::string, Fn>> table = {
      {"worst-traditional", worst_traditional},
      {"worst-stochastic", worst_stochastic},
      {"worst-deterministic", worst_deterministic},
      {"expected", expected},
      {"traversed", traversed},
      {"failed-tests", failed_tests},
      {"lights", lights},
      {"noise", noise},
      {"noise-baked", noise_baked},
      {"more-levels", more_levels},
      {"linear-cost", linear_cost},
      {"p-vs-P", p_vs_primitives},
      {"sorting", sorting},
      {"premise", premise}};
  for (const auto& [n, f] : table) {
    if (n != name) continue;
    const auto t0 = std::chrono::steady_clock::now();
    ExperimentResult r = f(config);
    r.name = name;
    r.verdict = verdict_of(r.checks);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  }
  throw InputError("unknown experiment '" + name + "'");
}

LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = std::min(x.size(), y.size());
  LinearFit f;
  if (n < 2) return f;
  double sx = 0, sy = 0;
  for (std::size_t i = 0; i < n; ++i) sx += x[i], sy += y[i];
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  f.b = sxx > 0 ? sxy / sxx : 0;
  f.a = my - f.b * mx;
  f.r2 = (sxx > 0 && syy > 0) ? (sxy * sxy) / (sxx * syy) : 1.0;
  if (n >= 3 && sxx > 0) {
    // Residual variance s^2 = (syy - b sxy)/(n - 2); se(b) = s / sqrt(sxx).
    const double s2 = std::max(0.0, syy - f.b * sxy) / double(n - 2);
    f.se_b = std::sqrt(s2 / sxx);
    // Two-sided 97.5% quantiles of Student's t for 1..30 degrees of freedom; beyond, the
    // expansion 1.96 + 2.5/df (within 0.2% of the true quantile for df > 30).
    static const double t975[30] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306,
                                    2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
                                    2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                    2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
    const std::size_t df = n - 2;
    f.ci95_b = f.se_b * (df <= 30 ? t975[df - 1] : 1.96 + 2.5 / double(df));
  }
  return f;
}

std::string fmt(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  if (v == std::floor(v) && std::fabs(v) < 1e15)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace amalgam::experiments

#pragma once
/// \file The paper's analyses as measured sweeps (issue 3, `amalgam experiment`).
///
/// Every measured figure comes from rays traced through the renderer (`amalgam::trace` /
/// `amalgam::render` on builtin scenes), except the 2D searches of "Linear Cost", which are
/// self-contained 2D hierarchies whose node visits are counted exactly. The paper's
/// predictions come from analysis/formulas.h; they sit beside the measurements in one table.
///
/// This module computes; it writes no files. The CLI (apps/amalgam/experiment_cmd.cpp) turns
/// an ExperimentResult into DIR/<name>.csv, a gnuplot script and PNG, and a report section.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace amalgam::experiments {

/// A numeric table: the CSV of one experiment.
struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;

  /// Index of a column; throws std::out_of_range for an unknown name.
  std::size_t col(const std::string& name) const;
  /// rows[r][col(name)].
  double at(std::size_t r, const std::string& name) const { return rows.at(r).at(col(name)); }
  void add(std::vector<double> row) { rows.push_back(std::move(row)); }
};

/// One curve of a plot: column `y` against column `x`, optionally only the rows whose column
/// `filter` equals `filter_value`.
struct Series {
  Series(std::string x_, std::string y_, std::string title_, bool lines_ = false,
         std::string filter_ = "", double filter_value_ = 0)
      : x(std::move(x_)),
        y(std::move(y_)),
        title(std::move(title_)),
        lines(lines_),
        filter(std::move(filter_)),
        filter_value(filter_value_) {}
  std::string x, y, title;
  bool lines = false;  ///< lines (a prediction) or points (a measurement)
  std::string filter;
  double filter_value = 0;
};

/// One panel of a plot.
struct Panel {
  std::string title, xlabel, ylabel;
  bool logx = false, logy = false;
  std::vector<Series> series;
};

/// A measured figure checked against a prediction: |measured - predicted| <= tolerance.
struct Check {
  std::string what;
  double measured = 0, predicted = 0, tolerance = 0;
  bool passed() const;
};

enum class Verdict { kHolds, kHoldsWithCorrection, kDoesNotHold };
const char* to_string(Verdict v);

struct ExperimentResult {
  std::string name;                          ///< e.g. "worst-traditional"
  std::string title;                         ///< section heading
  std::string claim;                         ///< what the paper says (markdown)
  std::string prediction;                    ///< the formula(s) used (markdown)
  Table table;                               ///< everything measured, written to <name>.csv
  std::vector<std::string> summary_columns;  ///< the report's short table (subset of columns)
  std::vector<std::size_t> summary_rows;     ///< rows shown in the report (empty: up to 12)
  std::vector<Panel> panels;                 ///< the PNG (panels side by side)
  std::vector<Check> checks;
  Verdict verdict = Verdict::kHolds;
  std::string findings;  ///< measured key figures and the reasoning for the verdict (markdown)
  double seconds = 0;
};

struct Config {
  bool quick = false;
  int threads = 0;  ///< 0: all cores
};

/// The nine experiment names in report order.
const std::vector<std::string>& names();

/// Runs one experiment by name; throws std::invalid_argument for an unknown name.
ExperimentResult run(const std::string& name, const Config& config);

// The experiments, one function each (issue 3, items 1-9).
ExperimentResult worst_traditional(const Config& c);
ExperimentResult worst_stochastic(const Config& c);
ExperimentResult worst_deterministic(const Config& c);
ExperimentResult expected(const Config& c);
ExperimentResult failed_tests(const Config& c);
ExperimentResult lights(const Config& c);
ExperimentResult noise(const Config& c);
ExperimentResult more_levels(const Config& c);
ExperimentResult linear_cost(const Config& c);

/// Least-squares fit y = a + b x; returns {a, b, r^2}.
struct LinearFit {
  double a = 0, b = 0, r2 = 0;
};
LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

/// Formats a number compactly for the report (integers exactly, others with 4 significant
/// digits).
std::string fmt(double v);

}  // namespace amalgam::experiments

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
#include <optional>
#include <string>
#include <vector>

#include "amalgam/render/loaded_scene.h"

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

/// How a curve is drawn: a line (a prediction) or points (a measurement).
enum class Draw { kPoints, kLine };

/// The scale of a plot's axis.
enum class Scale { kLinear, kLog };

/// One curve of a plot: column `y` against column `x`, optionally only the rows whose column
/// `filter` equals `filter_value`.
struct Series {
  Series(std::string x_, std::string y_, std::string title_, Draw draw_ = Draw::kPoints,
         std::string filter_ = "", double filter_value_ = 0)
      : x(std::move(x_)),
        y(std::move(y_)),
        title(std::move(title_)),
        draw(draw_),
        filter(std::move(filter_)),
        filter_value(filter_value_) {}
  std::string x, y, title;
  Draw draw = Draw::kPoints;
  std::string filter;
  double filter_value = 0;
};

/// One panel of a plot.
struct Panel {
  std::string title, xlabel, ylabel;
  Scale x = Scale::kLinear, y = Scale::kLinear;
  std::vector<Series> series;
};

/// What a check says about the paper. kSupports: the measurement agrees with the paper's
/// statement (or with our correction of a printed formula) -- if it fails, the statement does
/// not hold. kRefutesPrinted: the measurement disagrees with a formula or claim as printed --
/// if it passes, the statement holds only with a correction. kHarness: a check of the measuring
/// apparatus, not of the paper (a timing loop repeated the count it timed; a pixel's variance
/// falls as 1/spp): not counted as evidence; if it fails, the measurement is not trusted and
/// the verdict is "not measured".
enum class Role { kSupports, kRefutesPrinted, kHarness };

/// A measured figure checked against a prediction: |measured - predicted| <= tolerance.
/// `statement` names the paper statement it bears on (an id of statements(), e.g. "Eq. 12";
/// empty: the experiment's own claim).
struct Check {
  Check() = default;
  Check(std::string what_, double measured_, double predicted_, double tolerance_,
        Role role_ = Role::kSupports, std::string statement_ = "")
      : what(std::move(what_)),
        measured(measured_),
        predicted(predicted_),
        tolerance(tolerance_),
        role(role_),
        statement(std::move(statement_)) {}
  std::string what;
  double measured = 0, predicted = 0, tolerance = 0;
  Role role = Role::kSupports;
  std::string statement;
  bool passed() const;
};

/// kNotMeasured ("not checked"): no check was made (a claim about wall time only, or the scenes
/// an experiment needs could not be loaded).
enum class Verdict { kHolds, kHoldsWithCorrection, kDoesNotHold, kNotMeasured };
const char* to_string(Verdict v);

/// Whether `c` is evidence about the paper (every role but kHarness).
inline bool is_evidence(const Check& c) {
  return c.role != Role::kHarness;
}

/// The verdict that follows from checks (never written by hand): not measured if there are
/// none; does not hold if a kSupports check fails; else holds with correction if a
/// kRefutesPrinted check passes; else holds.
Verdict verdict_of(const std::vector<Check>& checks);

/// The verdict of the checks bearing on one paper statement (Check::statement == id), or
/// std::nullopt when none does.
std::optional<Verdict> verdict_of(const std::vector<Check>& checks, const std::string& id);

/// One statement of the paper (an equation or a claim in words) and where it is checked.
struct Statement {
  std::string id;                        ///< "Eq. 12", "Sec. noise", ...
  std::string says;                      ///< what the paper says, in brief
  std::vector<std::string> experiments;  ///< those whose checks bear on it (none: derived only)
};

/// Every equation and statement of the paper, in the paper's order (the report's first table;
/// hand derivations of each are in docs/paper-derivations.md).
const std::vector<Statement>& statements();

/// A slip of the printed text that no measurement can refute: a symbol, a cross-reference or a
/// summary that says something other than what the paper means or shows.
struct PrintedSlip {
  std::string where;    ///< the section or paragraph
  std::string printed;  ///< the printed words
  std::string meant;    ///< what the paper means or shows, and why
};

/// The report's list of printed slips (after the statements; docs/paper-derivations.md too).
const std::vector<PrintedSlip>& printed_slips();

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
  Verdict verdict = Verdict::kHolds;  ///< set by run() from `checks` (verdict_of)
  std::string findings;  ///< measured key figures and the reasoning for the verdict (markdown)
  /// Parts that could not be measured (a scene file that would not load), one line each: the
  /// report is then partial, which the CLI says and refuses unless --allow-partial.
  std::vector<std::string> not_measured;
  double seconds = 0;
};

struct Config {
  bool quick = false;
  int threads = 0;  ///< 0: all cores
  /// Test hook: every prediction an experiment takes from a named formula passes through
  /// perturb(formula name, value) (see predict()); a deliberately wrong formula injected here
  /// must turn the verdict (tests/analysis/experiments_test.cpp). Empty: predictions as computed.
  std::function<double(const std::string& formula, double value)> perturb;
  /// Loads a scene file or mesh (the analysis layer cannot: load/ sits above it). Set by the
  /// CLI and the tests; empty: experiments that need files report them as not measured.
  std::function<LoadedScene(const std::string& path)> load;
};

/// The prediction `value` of formula `name` as the experiment uses it: value itself, or
/// config.perturb(name, value) when the hook is set.
double predict(const Config& config, const std::string& name, double value);

/// The nine experiment names in report order.
const std::vector<std::string>& names();

/// Runs one experiment by name; throws InputError for an unknown name.
ExperimentResult run(const std::string& name, const Config& config);

// The experiments, one function each (issue 3, items 1-9).
ExperimentResult worst_traditional(const Config& c);
ExperimentResult worst_stochastic(const Config& c);
ExperimentResult worst_deterministic(const Config& c);
ExperimentResult expected(const Config& c);
ExperimentResult traversed(const Config& c);
ExperimentResult failed_tests(const Config& c);
ExperimentResult lights(const Config& c);
ExperimentResult noise(const Config& c);
ExperimentResult noise_baked(const Config& c);
ExperimentResult more_levels(const Config& c);
ExperimentResult linear_cost(const Config& c);
ExperimentResult p_vs_primitives(const Config& c);
ExperimentResult premise(const Config& c);
ExperimentResult sorting(const Config& c);

/// Wall times of repeated runs of a render against those of a reference render (premise's "no
/// slower"). Each median gets a distribution-free confidence interval [x(k), x(n+1-k)] of its n
/// sorted runs, k the largest rank with a coverage of at least 95% (9 runs: the 2nd to the 8th,
/// 96.1%), or the whole range (k = 1, coverage 1 - 2^(1-n)) when n is too small for 95%.
struct TimeRatio {
  double median = 0;  ///< median(seconds) / median(reference)
  /// The ratio's interval: [seconds' low / reference's high, seconds' high / reference's low].
  double lo = 0, hi = 0;
  double coverage = 0;  ///< of each median's interval (the smaller of the two)
  /// +1 slower (lo > 1), -1 faster (hi < 1), 0 a tie (the interval holds 1).
  int order = 0;
};
/// Throws std::invalid_argument when either list is empty.
TimeRatio time_ratio(const std::vector<double>& seconds, const std::vector<double>& reference);

/// premise's checks of "no slower" for one scale-sensitive render (`label`) against the
/// traditional render of the same scene: it makes no more tests (`tests_ratio` <= 1) and is not
/// slower in wall time (a tie passes; only `time.order` > 0 fails). Statement "No slower".
std::vector<Check> no_slower_checks(const std::string& label, double tests_ratio,
                                    const TimeRatio& time);

/// Least-squares fit y = a + b x; returns {a, b, r^2} and the slope's standard error and
/// 95% confidence half-width (Student t with n - 2 degrees of freedom; 0 for n < 3).
struct LinearFit {
  double a = 0, b = 0, r2 = 0;
  double se_b = 0, ci95_b = 0;
};
LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

/// Formats a number compactly for the report (integers exactly, others with 4 significant
/// digits).
std::string fmt(double v);

}  // namespace amalgam::experiments

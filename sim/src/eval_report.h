// plinth-eval's report of a runs file: the levels the box showed, today's reactive risk and the
// ensemble's signals as thresholds move (the ROC), and thresholds calibrated on half of the
// records and reported on the other half.
#pragma once

#include <string>
#include <vector>

#include "plinth/host/eval_metrics.h"

namespace plinth::sim {

// The calibration's targets per level (the issue's: alarm within 5 % false alarms, warning
// within 15 %; advisory within 30 %), each with no missed collapse wanted. The false alarms are
// `false_alarm`'s (for every level and the frontier): unneeded alarms (collapse margin >= 2) or
// alarms in quiet runs (docs/forecast.md says why the margin is the default).
struct CalibrationTargets {
  host::LevelTarget advisory{0.30, 0};
  host::LevelTarget warning{0.15, 0};
  host::LevelTarget alarm{0.05, 0};
  host::FalseAlarm false_alarm = host::FalseAlarm::kMargin;
};

struct FoldResult {
  std::vector<std::string> calibration_records;
  std::vector<std::string> report_records;
  host::Choice chosen;           // on the calibration records
  host::WarningOutcome held_out;  // the same rule on the report records
};

struct LevelReport {
  std::string level;
  host::WarningOutcome shown;     // as the box showed it (its configured thresholds)
  host::WarningOutcome reactive;  // today's box: the nominal statue's risk at the default threshold
  std::vector<FoldResult> folds;  // two: calibrated on one half, reported on the other
  host::Choice all_records;       // the rule chosen on every record (the shipped defaults)
  // With another runs file to calibrate on (report --calibrate-on): the rule chosen on all of
  // it, and that rule on this file's runs.
  std::vector<FoldResult> calibrated_elsewhere;  // none or one
};

// The frontier (host::frontier) of the rules on one reactive risk and the forecast probability.
struct FrontierReport {
  std::string signal;  // "risk" (the worst member's) or "nominal_risk"
  std::vector<host::FrontierRow> rows;
};

struct Report {
  std::size_t runs = 0;
  host::FalseAlarm false_alarm = host::FalseAlarm::kMargin;  // what calibration and frontier count
  bool margins_known = false;  // the runs file records the grid (host::EvalTable::has_grid)
  std::vector<LevelReport> levels;  // advisory, warning, alarm
  std::vector<FrontierReport> frontiers;  // with_frontier: risk, then nominal_risk
};

// Throws InputError, naming the file as `name`, when the targets count margins and the table has
// no grid (a file of an earlier plinth-eval).
void require_margins(const host::EvalTable& table, const CalibrationTargets& targets,
                     const std::string& name);

// The records split in two halves by name (alternately, sorted), the runs of each. With
// `with_frontier`, also the best rule each of the alarm's constraints allows on every record.
// With `calibration`, also each level's rule chosen on that other file's runs (of the same
// threshold grids) and reported on these. Throws InputError when the targets count margins and
// a table has no grid, or the two files' thresholds differ.
[[nodiscard]] Report make_report(const host::EvalTable& table, const CalibrationTargets& targets,
                                 bool with_frontier = false,
                                 const host::EvalTable* calibration = nullptr);

// The report as text (stdout) and as JSON.
[[nodiscard]] std::string report_text(const Report& report, const host::CrossingGrids& grids);
[[nodiscard]] std::string report_json(const Report& report, const host::CrossingGrids& grids);

// A rule in words: "risk >= 0.8 or probability >= 0.5625".
[[nodiscard]] std::string describe_rule(const host::Rule& rule, const host::CrossingGrids& grids);

// The ROC as a PNG drawn by gnuplot (Debian gnuplot-nox): median lead against false-alarm rate
// for the nominal risk, the worst member's risk and the forecast probability alone, each as its
// threshold moves; beside it (when the file records the grid) the same against the unneeded
// alarms' rate (collapse margin >= 2). gnuplot reads only files of a private temporary folder
// with fixed names; the image is then moved to `png_path` (no text of the user's reaches
// gnuplot). Throws InputError when gnuplot is missing or fails.
void plot_roc(const host::EvalTable& table, const std::string& png_path);

}  // namespace plinth::sim

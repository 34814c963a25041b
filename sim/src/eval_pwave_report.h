// plinth-eval report's P-wave section (docs/pwave.md): the warning with and without the on-site
// P-wave stage, from one runs file of `plinth-eval run --pwave on`. The box's warning is
// first_warning_s; with the stage at threshold p it is the earlier of that and the stage's
// first crossing of p (the alarm policy ORs its conditions and raises at once: raise_hold_s 0),
// so every threshold of the grid is scored from the same runs.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "plinth/host/eval_metrics.h"

namespace plinth::sim {

// Where the stage can help: by how long the record's P wave (its AIC pick) comes before its
// strong motion (host::RecordPhases).
enum class PWaveClass { kLeadAtLeast3s = 0, kLeadBelow3s, kNoPWave };
inline constexpr std::size_t kPWaveClasses = 3;

// The warning's outcome (host::outcome_of: leads with misses as 0, unneeded warnings at a
// collapse margin >= 2) over every run and per class.
struct PWaveThresholdRow {
  double threshold = 0.0;  // -1: without the stage
  host::WarningOutcome all;
  std::array<host::WarningOutcome, kPWaveClasses> by_class;
};

struct PWaveReport {
  std::size_t runs = 0;
  std::array<int, kPWaveClasses> records_by_class{};
  int triggered_runs = 0;            // the stage triggered (before the end of the run)
  int triggered_before_strong = 0;   // ... before the record's strong motion
  PWaveThresholdRow without;         // the box without the stage
  std::vector<PWaveThresholdRow> with;  // one per grid threshold
  // The threshold chosen on this file (or on `calibrate_on`): the longest median lead over the
  // collapses of P >= 3 s records whose unneeded rate is at most 5 points above the box's.
  std::optional<PWaveThresholdRow> chosen;
  bool chosen_elsewhere = false;
};

inline constexpr double kPWaveUnneededAllowance = 0.05;

// Throws InputError when the file has no P-wave columns.
[[nodiscard]] PWaveReport make_pwave_report(const host::EvalTable& table,
                                            const host::EvalTable* calibrate_on = nullptr);
[[nodiscard]] std::string pwave_report_text(const PWaveReport& report);

}  // namespace plinth::sim

// plinth-eval report's regional section (docs/regional.md, "Evaluation"): the warning with and
// without a simulated regional alert, from one runs file of `plinth-eval run --regional on`. The
// box's warning is first_warning_s; with the alert at threshold p it is the earlier of that and
// the alert's receipt when the room's probability of collapse under it is >= p (the alarm
// policy's warning_regional: ORed with the other conditions, raised at once, raise_hold_s 0). An
// alert before the record's first sample counts at 0 s: neither the box nor the truth sees
// earlier. Every threshold of the grid is scored from the same runs.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "plinth/host/eval_metrics.h"

namespace plinth::sim {

// By hypocentral distance: inside the blind zone of the median latency (6.9 s x 3.5 km/s =
// 24 km), beyond it, far.
inline constexpr std::array<double, 2> kRegionalClassFloorsKm{25.0, 50.0};
inline constexpr std::size_t kRegionalClasses = kRegionalClassFloorsKm.size() + 1;

struct RegionalThresholdRow {
  double threshold = 0.0;  // -1: without the alert
  host::WarningOutcome all;
  std::array<host::WarningOutcome, kRegionalClasses> by_class;
};

struct RegionalClassCounts {
  int records = 0;
  int runs = 0;
  int blind = 0;           // runs whose alert came at or after its S arrival
  int before_record = 0;   // runs whose alert came before the record's first sample
};

struct RegionalReport {
  std::size_t runs = 0;
  std::array<RegionalClassCounts, kRegionalClasses> counts{};
  RegionalClassCounts total;
  RegionalThresholdRow without;
  std::vector<RegionalThresholdRow> with;  // one per kRegionalThresholds
  // The box's default (alarm_policy.h warning_regional.on), scored.
  std::optional<RegionalThresholdRow> box_default;
  // Chosen on this file or on `calibrate_on`: the longest median lead over all collapses whose
  // unneeded rate is at most kRegionalUnneededAllowance above the box's.
  std::optional<RegionalThresholdRow> chosen;
  bool chosen_elsewhere = false;
};

inline constexpr double kRegionalUnneededAllowance = 0.05;
inline constexpr std::array<double, 9> kRegionalThresholds{0.1, 0.2, 0.3, 0.4, 0.5,
                                                           0.6, 0.7, 0.8, 0.9};

// The distance class of a hypocentral distance (km).
[[nodiscard]] std::size_t regional_class(double rhyp_km);
// The warning's first time with the alert at threshold p (p < 0: the box's alone).
[[nodiscard]] double regional_warning_time(const host::EvalRun& run, double p);

// Throws InputError when the file (or the calibration file) has no regional columns.
[[nodiscard]] RegionalReport make_regional_report(const host::EvalTable& table,
                                                  const host::EvalTable* calibrate_on = nullptr);
[[nodiscard]] std::string regional_report_text(const RegionalReport& report);

}  // namespace plinth::sim

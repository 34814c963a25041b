// What the reports of a warning input (the P-wave stage: eval_pwave_report; regional alerts:
// eval_regional_report) share: how one is scored against the box without it, how its threshold
// is chosen, and their text's formatting. Host-only.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <vector>

#include "plinth/host/eval_metrics.h"

namespace plinth::sim {

// s: the median lead over the collapses, 0 when there is none.
inline double median_lead(const host::WarningOutcome& o) {
  return std::max(0.0, o.lead_quantile(0.5));
}

// The threshold a report chooses (docs/pwave.md, docs/regional.md): of the rows whose unneeded
// warnings over all runs (`row.all`) are at most `allowance` above the box's without the input,
// the one whose `lead(row)` is longest; ties: the higher `row.threshold` (fewer warnings).
// The index into `rows`, -1 when none qualifies.
template <class Row, class Lead>
[[nodiscard]] int choose_threshold(const std::vector<Row>& rows, double unneeded_without,
                                   double allowance, Lead lead) {
  constexpr double kTie = 1e-12;
  int best = -1;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& row = rows[i];
    if (row.all.unneeded_rate() > unneeded_without + allowance + kTie) continue;
    if (best < 0) {
      best = static_cast<int>(i);
      continue;
    }
    const Row& chosen = rows[static_cast<std::size_t>(best)];
    const double l = lead(row);
    const double chosen_lead = lead(chosen);
    if (l > chosen_lead + kTie ||
        (std::fabs(l - chosen_lead) <= kTie && row.threshold > chosen.threshold)) {
      best = static_cast<int>(i);
    }
  }
  return best;
}

// Sets `report.chosen` to its row at the threshold `choose` picks on `calibration` (another
// file's report over the same thresholds), or on `report` itself when there is none.
template <class Report, class Choose>
void set_chosen_threshold(Report& report, const Report* calibration, Choose choose) {
  const int i = choose(calibration != nullptr ? *calibration : report);
  if (i >= 0) report.chosen = report.with[static_cast<std::size_t>(i)];
  report.chosen_elsewhere = calibration != nullptr;
}

// printf into a std::string (a report's line is short: 512 characters at most).
__attribute__((format(printf, 1, 0))) inline std::string report_vtext(const char* format,
                                                                      va_list args) {
  char buffer[512];
  std::vsnprintf(buffer, sizeof buffer, format, args);
  return buffer;
}
__attribute__((format(printf, 1, 2))) inline std::string report_text(const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::string out = report_vtext(format, args);
  va_end(args);
  return out;
}
// The same, ended by a newline.
__attribute__((format(printf, 1, 2))) inline std::string report_line(const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::string out = report_vtext(format, args);
  va_end(args);
  return out + "\n";
}

}  // namespace plinth::sim

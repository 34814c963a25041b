#include "eval_pwave_report.h"

#include <algorithm>
#include <optional>
#include <set>

#include "eval_warning_report.h"
#include "plinth/host/input_error.h"
#include "plinth/monitor/alarm_level.h"

namespace plinth::sim {

namespace {

using host::EvalRun;
using host::EvalTable;

constexpr std::array<const char*, kPWaveClasses> kClassNames{
    "P >= 3 s before the strong motion", "P < 3 s before it (near the source)",
    "no P before it (begins in the strong motion)"};

PWaveClass class_of(const EvalRun& r) {
  if (r.p_pick_s < 0.0) return PWaveClass::kNoPWave;
  const double lead = r.strong_motion_s - r.p_pick_s;
  if (lead >= 3.0) return PWaveClass::kLeadAtLeast3s;
  return lead > 0.0 ? PWaveClass::kLeadBelow3s : PWaveClass::kNoPWave;
}

// The warning's first time with the stage at grid index `p` (-1: without the stage).
double warning_time(const EvalRun& r, int p) {
  const double box = r.first_shown_s[monitor::risk_level_index(monitor::AlarmLevel::kWarning)];
  if (p < 0) return box;
  const double stage = r.pwave_crossing_s[static_cast<std::size_t>(p)];
  if (stage < 0.0) return box;
  return box < 0.0 ? stage : std::min(box, stage);
}

PWaveThresholdRow score(const std::vector<EvalRun>& runs, int p, double threshold) {
  PWaveThresholdRow row;
  row.threshold = threshold;
  const auto first = [p](const EvalRun& r) { return warning_time(r, p); };
  row.all = host::outcome_of(runs, first);
  for (std::size_t c = 0; c < kPWaveClasses; ++c) {
    std::vector<EvalRun> in_class;
    for (const EvalRun& r : runs) {
      if (static_cast<std::size_t>(class_of(r)) == c) in_class.push_back(r);
    }
    row.by_class[c] = host::outcome_of(in_class, first);
  }
  return row;
}

// The longest median lead over P >= 3 s collapses within the unneeded allowance (ties: the
// higher threshold). Returns the grid index, -1 when none qualifies.
int choose(const PWaveReport& r) {
  return choose_threshold(
      r.with, r.without.all.unneeded_rate(), kPWaveUnneededAllowance,
      [](const PWaveThresholdRow& w) { return w.by_class[0].lead_quantile(0.5); });
}

PWaveReport score_table(const EvalTable& table) {
  if (table.grids.pwave.empty()) {
    throw host::InputError("the runs file has no P-wave columns (plinth-eval run --pwave on)");
  }
  if (!table.has_grid) {
    throw host::InputError(
        "the runs file has no PGA grid columns: the collapse margins are not "
        "known (run it again with this plinth-eval)");
  }
  PWaveReport r;
  r.runs = table.runs.size();
  std::set<std::string> seen;
  for (const EvalRun& run : table.runs) {
    if (seen.insert(run.record).second)
      ++r.records_by_class[static_cast<std::size_t>(class_of(run))];
    if (run.pwave_trigger_s >= 0.0) {
      ++r.triggered_runs;
      if (run.pwave_trigger_s < run.strong_motion_s) ++r.triggered_before_strong;
    }
  }
  r.without = score(table.runs, -1, -1.0);
  for (std::size_t p = 0; p < table.grids.pwave.size(); ++p) {
    r.with.push_back(score(table.runs, static_cast<int>(p), table.grids.pwave[p]));
  }
  return r;
}

std::string outcome_text(const host::WarningOutcome& o) {
  const host::BandCount unneeded = o.unneeded();
  return report_text(
      "%4d collapses, %3d missed, lead median %5.2f s, p10 %5.2f s; unneeded %5.1f %% "
      "(%d of %d)",
      o.collapses, o.misses, std::max(0.0, o.lead_quantile(0.5)),
      std::max(0.0, o.lead_quantile(0.1)), 100.0 * unneeded.rate(), unneeded.alarms, unneeded.runs);
}

}  // namespace

PWaveReport make_pwave_report(const EvalTable& table, const EvalTable* calibrate_on) {
  PWaveReport r = score_table(table);
  std::optional<PWaveReport> calibration;
  if (calibrate_on != nullptr) {
    if (calibrate_on->grids.pwave != table.grids.pwave) {
      throw host::InputError("the calibration file's pwave_ge_ grid differs from this file's");
    }
    calibration = score_table(*calibrate_on);
  }
  set_chosen_threshold(r, calibration ? &*calibration : nullptr, choose);
  return r;
}

std::string pwave_report_text(const PWaveReport& r) {
  std::string out = "P-wave stage (warning; docs/pwave.md)\n";
  out += report_text(
      "  records: %d with the P wave >= 3 s before the strong motion, %d < 3 s, %d "
      "without a P wave before it\n",
      r.records_by_class[0], r.records_by_class[1], r.records_by_class[2]);
  out +=
      report_text("  the stage triggered in %d of %zu runs, %d of them before the strong motion\n",
                  r.triggered_runs, r.runs, r.triggered_before_strong);
  const auto block = [&](const char* title, const PWaveThresholdRow& row) {
    out += std::string("  ") + title + "\n";
    out += "    all records:  " + outcome_text(row.all) + "\n";
    for (std::size_t c = 0; c < kPWaveClasses; ++c) {
      out += report_text("    %-46s ", kClassNames[c]) + outcome_text(row.by_class[c]) + "\n";
    }
  };
  block("without the stage (the box's warning):", r.without);
  if (r.chosen) {
    const std::string title = report_text(
        "with the stage at p >= %g (chosen %s: the longest median lead "
        "on P >= 3 s records, unneeded at most %g points more):",
        r.chosen->threshold, r.chosen_elsewhere ? "on the calibration file" : "on this file",
        100.0 * kPWaveUnneededAllowance);
    block(title.c_str(), *r.chosen);
    out += report_text(
        "  gain of the median lead: %+.2f s on P >= 3 s records, %+.2f s on all; "
        "unneeded %+.1f points\n",
        median_lead(r.chosen->by_class[0]) - median_lead(r.without.by_class[0]),
        median_lead(r.chosen->all) - median_lead(r.without.all),
        100.0 * (r.chosen->all.unneeded_rate() - r.without.all.unneeded_rate()));
  } else {
    out += "  no threshold keeps the unneeded warnings within the allowance\n";
  }
  out += "  every threshold: p, median lead on P >= 3 s / all (s), unneeded (%), missed\n";
  out += report_text("    without  %5.2f / %5.2f  %5.1f  %d\n", median_lead(r.without.by_class[0]),
                     median_lead(r.without.all), 100.0 * r.without.all.unneeded_rate(),
                     r.without.all.misses);
  for (const PWaveThresholdRow& w : r.with) {
    out +=
        report_text("    %-7g  %5.2f / %5.2f  %5.1f  %d\n", w.threshold, median_lead(w.by_class[0]),
                    median_lead(w.all), 100.0 * w.all.unneeded_rate(), w.all.misses);
  }
  return out;
}

}  // namespace plinth::sim

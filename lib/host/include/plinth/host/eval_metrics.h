// plinth-eval's measures: each run's truth (the solver on the true statue) against the box's
// timeline on the same motion, and what they add up to per alarm level.
//
// A run is
//   a collapse   when the true statue overturns or falls: the level is a hit when it was
//                shown before the collapse (lead = collapse time - first time shown), else a
//                miss (shown at or after the collapse, or never);
//   quiet        when its peak rotation stays below half the overturning angle: the level shown
//                at all is a false alarm;
//   a near miss  otherwise (it rocked past half the angle and stood): the level shown there is
//                counted apart, neither hit nor false alarm.
// The ROC (lead against false-alarm rate as a threshold moves) comes from first-crossing times
// the box records for a grid of thresholds on each of its signals (reactive risk, forecast
// probability); a rule "signal A at a or signal B at b" is first true at the earlier of the
// two crossings, so any such rule's ROC is computed from the same runs without running again.
#pragma once

#include <array>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace plinth::host {

inline constexpr double kQuietPeakRatio = 0.5;  // of the overturning angle: below it, quiet

enum class EvalLevel : std::size_t { kAdvisory = 0, kWarning = 1, kAlarm = 2 };
inline constexpr std::size_t kEvalLevels = 3;
[[nodiscard]] const char* eval_level_name(EvalLevel level);

// The threshold grids of the first-crossing times (every run of a file shares them).
struct CrossingGrids {
  std::vector<double> risk;         // reactive risk of the worst member, dimensionless
  std::vector<double> probability;  // forecast probability, dimensionless
  // The P-wave stage's probability of collapse (plinth-eval run --pwave on; empty: off).
  std::vector<double> pwave{};
};
[[nodiscard]] CrossingGrids default_crossing_grids();
// The P-wave stage's grid: fine at the small probabilities where its threshold is chosen.
[[nodiscard]] std::vector<double> default_pwave_grid();

struct EvalRun {
  std::string record;  // file name
  std::string scene;   // file name
  int statue = 0;      // index of the true statue drawn for this record and scene
  double scale_g = 0.0;  // the record's PGA, g
  // Truth.
  bool collapsed = false;
  double collapse_time_s = -1.0;  // -1: none
  double peak_ratio = 0.0;        // max |theta| / alpha over the run (1 at a collapse)
  // The box: first time each level was shown (-1: never).
  std::array<double, kEvalLevels> first_shown_s{-1.0, -1.0, -1.0};
  // First time each grid threshold was reached (-1: never), same order as the grids.
  std::vector<double> risk_crossing_s;
  std::vector<double> probability_crossing_s;
  // The nominal statue's reactive risk alone (today's box), on the risk grid.
  std::vector<double> nominal_risk_crossing_s;
  // With the P-wave stage (grids.pwave not empty): the record's reference phases (pwave_records.h,
  // s from its first sample; p_pick_s -1 when there is none), the stage's first trigger (its
  // onset, s; -1: none) and the first time its probability reached each grid value (-1: never).
  double p_pick_s = -1.0;
  double strong_motion_s = -1.0;
  double pwave_trigger_s = -1.0;
  std::vector<double> pwave_crossing_s;

  [[nodiscard]] bool quiet() const { return !collapsed && peak_ratio < kQuietPeakRatio; }
  [[nodiscard]] bool near_miss() const { return !collapsed && peak_ratio >= kQuietPeakRatio; }
};

// What a rule (or a level) did over a set of runs.
struct WarningOutcome {
  int collapses = 0;
  int hits = 0;
  int misses = 0;
  int quiet_runs = 0;
  int false_alarms = 0;
  int near_miss_runs = 0;
  int raised_on_near_misses = 0;
  std::vector<double> leads_s;  // one per collapse; 0 for a miss

  [[nodiscard]] double false_alarm_rate() const;    // false_alarms / quiet_runs (0 if none)
  [[nodiscard]] double lead_quantile(double q) const;  // of leads_s, misses as 0; -1 if empty
};

// The outcome of the rule whose first time in each run is `first_time(run)` (-1: never).
template <class FirstTime>
[[nodiscard]] WarningOutcome outcome_of(const std::vector<EvalRun>& runs, FirstTime first_time) {
  WarningOutcome o;
  for (const EvalRun& r : runs) {
    const double t = first_time(r);
    if (r.collapsed) {
      ++o.collapses;
      const bool hit = t >= 0.0 && t < r.collapse_time_s;
      (hit ? o.hits : o.misses) += 1;
      o.leads_s.push_back(hit ? r.collapse_time_s - t : 0.0);
    } else if (r.quiet()) {
      ++o.quiet_runs;
      o.false_alarms += t >= 0.0 ? 1 : 0;
    } else {
      ++o.near_miss_runs;
      o.raised_on_near_misses += t >= 0.0 ? 1 : 0;
    }
  }
  return o;
}

[[nodiscard]] WarningOutcome level_outcome(const std::vector<EvalRun>& runs, EvalLevel level);

// Which reactive risk a rule reads: the worst member's (the box's) or the nominal statue's alone
// (today's box, EvalRun::nominal_risk_crossing_s).
enum class RiskSignal { kWorstMember, kNominal };

// A rule of the alarm policy's form: shown once the risk reaches `risk` or the forecast
// probability reaches `probability` (index into the grids; -1: that signal unused).
struct Rule {
  int risk_index = -1;
  int probability_index = -1;
  RiskSignal risk_signal = RiskSignal::kWorstMember;
};
[[nodiscard]] double first_time(const EvalRun& run, const Rule& rule);

struct RocPoint {
  Rule rule;
  WarningOutcome outcome;
};
// Every rule of the grids (each signal alone, and every pair), with its outcome.
[[nodiscard]] std::vector<RocPoint> roc(const std::vector<EvalRun>& runs,
                                        const CrossingGrids& grids,
                                        RiskSignal risk_signal = RiskSignal::kWorstMember);

// Calibration targets of one level.
struct LevelTarget {
  double max_false_alarm_rate = 0.05;
  int max_misses = 0;  // tried first; relaxed upward when no rule meets both
};
// The rule that meets the target with the longest median lead (ties: the lower false-alarm
// rate). When none does, safety first: among the rules that miss at most max_misses collapses,
// the lowest false-alarm rate; when none misses that few, the fewest misses (within the rate
// if any rule is). `found` false only without runs or rules.
struct Choice {
  bool found = false;
  bool meets_target = false;
  RocPoint point;
};
[[nodiscard]] Choice choose_rule(const std::vector<RocPoint>& points, const LevelTarget& target);

// The frontier of a set of rules: for each of the alarm's constraints (docs/forecast.md), the rule
// that meets it with the fewest false alarms (then the fewest misses, the longest median lead),
// or for "false alarms <= 5 %" the fewest misses (then the fewest false alarms): what the signals
// of a runs file allow at best, whatever thresholds the box ships.
struct FrontierRow {
  const char* constraint = "";
  bool found = false;  // some rule meets the constraint
  RocPoint point;
};
[[nodiscard]] std::vector<FrontierRow> frontier(const std::vector<RocPoint>& points);

// CSV: one run per row (header first); the grids are written in the header's column names
// (risk_ge_0.3, probability_ge_0.5625, nominal_risk_ge_0.3). With the P-wave stage the row ends
// with p_pick_s, strong_motion_s, pwave_trigger_s and the pwave_ge_<p> crossings; a file
// without them reads as a run without the stage. read_eval_csv checks the header and every field and
// throws InputError naming the file and line.
void write_eval_csv_header(std::FILE* out, const CrossingGrids& grids);
void write_eval_csv_row(std::FILE* out, const EvalRun& run);
struct EvalTable {
  CrossingGrids grids;
  std::vector<EvalRun> runs;
};
[[nodiscard]] EvalTable read_eval_csv(const std::string& path);

}  // namespace plinth::host

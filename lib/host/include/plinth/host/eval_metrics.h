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
// An alarm in a run that stood is also scored by the run's collapse margin (FEMA P-695's collapse
// margin ratio on incremental dynamic analysis): its case's lowest collapsing PGA on the grid
// divided by the run's PGA. An alarm is unneeded when the margin is >= 2 (the shaking would have
// to double to topple the statue). A case that never collapses up to the grid's top bounds the
// margin from below only (top / PGA): such a run counts as unneeded when that bound is >= 2 and
// is counted apart, as "margin unknown", when it is below 2.
// The ROC (lead against false-alarm rate as a threshold moves) comes from first-crossing times
// the box records for a grid of thresholds on each of its signals (reactive risk, forecast
// probability); a rule "signal A at a or signal B at b" is first true at the earlier of the
// two crossings, so any such rule's ROC is computed from the same runs without running again.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "plinth/monitor/alarm_level.h"

namespace plinth::host {

inline constexpr double kQuietPeakRatio = 0.5;  // of the overturning angle: below it, quiet
inline constexpr double kUnneededMargin = 2.0;   // collapse margin from which an alarm is unneeded

// Which alarms a calibration or a frontier counts as false: those raised in runs with a collapse
// margin >= 2 (kMargin, unneeded alarms), or in quiet runs (kPeak, below half the angle).
enum class FalseAlarm { kMargin, kPeak };
[[nodiscard]] const char* false_alarm_name(FalseAlarm definition);  // "margin", "peak"
// "margin" or "peak" into `definition`; false otherwise.
[[nodiscard]] bool parse_false_alarm(const std::string& text, FalseAlarm& definition);

// plinth-eval run's PGA grid: `steps` points from from_g to to_g, evenly spaced (steps 0: not
// known, a runs file written before the grid was recorded).
struct PgaGrid {
  double from_g = 0.0;
  double to_g = 0.0;
  int steps = 0;

  [[nodiscard]] bool known() const { return steps > 0; }
  [[nodiscard]] double at(int i) const;  // the i-th point, g
  [[nodiscard]] double top_g() const { return at(steps - 1); }
  // The index of the grid point `pga_g` is (within the runs file's 6 digits), or -1.
  [[nodiscard]] int index_of(double pga_g) const;
  friend bool operator==(const PgaGrid&, const PgaGrid&) = default;
};

// The threshold grids of the first-crossing times (every run of a file shares them).
struct CrossingGrids {
  std::vector<double> risk;         // reactive risk of the worst member, dimensionless
  std::vector<double> probability;  // forecast probability, dimensionless
  // The P-wave stage's probability of collapse (plinth-eval run --pwave on; empty: off).
  std::vector<double> pwave{};
  // Regional alerts simulated (plinth-eval run --regional on): the regional_ columns.
  bool regional = false;
};
[[nodiscard]] CrossingGrids default_crossing_grids();
// The P-wave stage's grid: fine at the small probabilities where its threshold is chosen.
[[nodiscard]] std::vector<double> default_pwave_grid();
// The regional alert's columns (EvalRun::Regional, in its order).
inline constexpr std::array<std::string_view, 8> kRegionalColumns{
    "regional_magnitude", "regional_rhyp_km", "regional_origin_s", "regional_alert_s",
    "regional_s_arrival_s", "regional_pga_g", "regional_sigma_ln", "regional_probability"};

// The fault block, ending the row (plinth-eval run since fault injection; docs/safety.md,
// "Fault injection"): the fault injected and the box's trouble. Files of an earlier plinth-eval
// have none (EvalTable::has_faults false).
inline constexpr std::array<std::string_view, 11> kFaultColumns{
    "fault",          "fault_param",          "fault_at",
    "fault_began_s",  "first_fault_trouble_s", "fault_trouble_at_end",
    "first_statue_fault_s", "first_statue_unexplained_s", "level_at_end",
    "trouble_at_end", "runs_written"};
// level_at_end of a run that ended while its box was restarting (no level shown).
inline constexpr std::string_view kBoxDown = "down";

struct EvalRun {
  std::string record;  // file name
  std::string scene;   // file name
  int statue = 0;      // index of the true statue drawn for this record and scene
  double scale_g = 0.0;  // the record's PGA, g
  // The case is (record, scene, statue, seed): the statues are drawn from the seed.
  std::uint32_t seed = 0;
  PgaGrid grid;  // the grid its case ran up
  // The case's lowest collapsing PGA on the grid, g (-1: none up to the grid's top). Not a column
  // of the runs file: read_eval_csv sets it from the case's rows (assign_case_collapses).
  double case_collapse_g = -1.0;
  // Truth.
  bool collapsed = false;
  double collapse_time_s = -1.0;  // -1: none
  double peak_ratio = 0.0;        // max |theta| / alpha over the run (1 at a collapse)
  // >= 0: the true statue lifted off then (Phase::kLiftedOff): the model ends, so the truth is
  // unknown and the run counts in no outcome (outcome_of skips it); -1: the model held.
  double model_valid_until_s = -1.0;
  // When the true statue first left full contact (-1: never). Not a column of the runs file:
  // plinth-eval run --motion-out writes it beside the levels' times.
  double first_motion_s = -1.0;
  // The box: first time each risk level was shown (-1: never), in monitor::kRiskLevels' order.
  std::array<double, monitor::kRiskLevels.size()> first_shown_s{-1.0, -1.0, -1.0};
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
  // With regional alerts simulated (grids.regional; regional_eval.h, docs/regional.md): the
  // record's source and the run's alert (times in s from the record's first sample, negative
  // before it), the statue's probability of collapse under it in the box's regional room.
  struct Regional {
    double magnitude = 0.0;
    double rhyp_km = 0.0;
    double origin_s = 0.0;
    double alert_s = 0.0;
    double s_arrival_s = 0.0;
    double pga_g = 0.0;
    double sigma_ln = 0.0;
    double probability = 0.0;
  };
  std::optional<Regional> regional;
  // The fault block (kFaultColumns; times in s from the record's t = 0, -1: never).
  struct Faults {
    std::string fault = "none";  // the kind injected (plinth-eval run --fault), "none"
    std::string param;           // its parameter as given ("" without one)
    std::string at;              // --fault-at as given ("" without a fault)
    // When it began (negative: in the box's quiet lead-in, before the record); nullopt: never
    // (no fault, or its anchor did not come before the run ended). Written "" then.
    std::optional<double> began_s;
    double first_trouble_s = -1.0;  // the trouble naming the faulted input, first shown
    bool trouble_at_end = false;    // ... shown when the run ended (a collapse: just before it)
    double first_statue_fault_s = -1.0;        // statue_sensor_fault, first shown
    double first_statue_unexplained_s = -1.0;  // statue_unexplained, first shown
    // The level and the trouble shown when the run ended: alarm_level names, or kBoxDown.
    std::string level_at_end = "normal";
    monitor::AlarmCause trouble_at_end_cause = monitor::AlarmCause::kNone;
    // plinth-eval run --collapses-only: the file holds only the runs whose truth collapsed.
    bool collapses_only = false;
  };
  std::optional<Faults> faults;

  [[nodiscard]] bool outside_model() const { return model_valid_until_s >= 0.0; }
  [[nodiscard]] bool quiet() const { return !collapsed && peak_ratio < kQuietPeakRatio; }
  [[nodiscard]] bool near_miss() const { return !collapsed && peak_ratio >= kQuietPeakRatio; }
  // The collapse margin: case_collapse_g / scale_g; when the case never collapsed, the lower bound
  // top / scale_g (margin_is_lower_bound). 0 when the grid is not known.
  [[nodiscard]] double collapse_margin() const;
  [[nodiscard]] bool margin_is_lower_bound() const { return case_collapse_g < 0.0; }
};

// The runs that stood, by collapse margin: [1, 1.25), [1.25, 1.5), [1.5, 2), [2, 3), >= 3.
inline constexpr std::array<double, 5> kMarginBandFloors{1.0, 1.25, 1.5, 2.0, 3.0};
inline constexpr std::size_t kMarginBands = kMarginBandFloors.size();
struct BandCount {
  int runs = 0;
  int alarms = 0;  // runs in which the rule or level was raised
  int quiet = 0;   // runs whose peak stayed below half the angle: false alarms by the peak
  [[nodiscard]] double rate() const;  // alarms / runs (0 if none)
};
struct MarginBands {
  // Margin known to lie in the band (the top band also takes lower bounds >= 3).
  std::array<BandCount, kMarginBands> known;
  // Margin known only to be >= a bound in band i < 4 (the case stood up to the grid's top); the
  // last of these (bound in [2, 3)) is unneeded all the same, the others are "margin unknown".
  std::array<BandCount, kMarginBands - 1> lower_bound;
  BandCount below_one;  // stood above its case's lowest collapse (plinth-eval run --all-scales)
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
  MarginBands margins;          // the runs that stood, by collapse margin (none without the grid)

  [[nodiscard]] double false_alarm_rate() const;    // false_alarms / quiet_runs (0 if none)
  // Alarms in runs with a margin >= 2 (known, or bounded below by >= 2), and those runs.
  [[nodiscard]] BandCount unneeded() const;
  // Runs whose margin is bounded below by less than 2 only: neither needed nor unneeded.
  [[nodiscard]] BandCount margin_unknown() const;
  [[nodiscard]] double unneeded_rate() const { return unneeded().rate(); }
  // false_alarm_rate() or unneeded_rate().
  [[nodiscard]] double false_alarm_rate(FalseAlarm definition) const;
  [[nodiscard]] double lead_quantile(double q) const;  // of leads_s, misses as 0; -1 if empty
};

// Counts a run that stood, raised or not, into its margin band (nothing without the grid).
void count_margin(const EvalRun& run, bool raised, MarginBands& bands);

// The outcome of the rule whose first time in each run is `first_time(run)` (-1: never).
template <class FirstTime>
[[nodiscard]] WarningOutcome outcome_of(const std::vector<EvalRun>& runs, FirstTime first_time) {
  WarningOutcome o;
  for (const EvalRun& r : runs) {
    if (r.outside_model()) continue;  // no truth to judge the warning against
    const double t = first_time(r);
    if (r.collapsed) {
      ++o.collapses;
      const bool hit = t >= 0.0 && t < r.collapse_time_s;
      (hit ? o.hits : o.misses) += 1;
      o.leads_s.push_back(hit ? r.collapse_time_s - t : 0.0);
      continue;
    }
    if (r.quiet()) {
      ++o.quiet_runs;
      o.false_alarms += t >= 0.0 ? 1 : 0;
    } else {
      ++o.near_miss_runs;
      o.raised_on_near_misses += t >= 0.0 ? 1 : 0;
    }
    count_margin(r, t >= 0.0, o.margins);
  }
  return o;
}

// `level`: one of monitor::kRiskLevels.
[[nodiscard]] WarningOutcome level_outcome(const std::vector<EvalRun>& runs,
                                           monitor::AlarmLevel level);

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
  FalseAlarm false_alarm = FalseAlarm::kMargin;  // which rate max_false_alarm_rate bounds
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

// Issue 24's target for `alarm` with the statue sensor: unneeded alarms at most 9 %.
inline constexpr double kStatueSensorMaxUnneededRate = 0.09;

// The frontier of a set of rules: for each of the alarm's constraints (docs/forecast.md), the rule
// that meets it with the fewest false alarms (then the fewest misses, the longest median lead),
// for "false alarms <= 5 %" the fewest misses (then the fewest false alarms), and for "no miss,
// false alarms <= 9 %" (kStatueSensorMaxUnneededRate) the longest median lead (then the fewest false
// alarms): what the signals of a runs file allow at best, whatever thresholds the box ships.
struct FrontierRow {
  const char* constraint = "";
  bool found = false;  // some rule meets the constraint
  RocPoint point;
};
[[nodiscard]] std::vector<FrontierRow> frontier(const std::vector<RocPoint>& points,
                                               FalseAlarm false_alarm = FalseAlarm::kMargin);

// A case (record, scene, statue, seed) as its rows tell it: they run up its grid from the first
// point, each once, to its first collapse (or on: --all-scales) or to the top.
struct EvalCaseRows {
  std::string record;
  std::string scene;
  int statue = 0;
  std::uint32_t seed = 0;
  PgaGrid grid;
  int first_collapse = -1;  // grid index of its lowest collapsing PGA; -1: none up to the top
  std::vector<std::size_t> runs;  // indices into the runs, in grid order
};
// The cases of runs whose grid is known, in the order their first rows come. Throws InputError
// (prefixed with `where`) naming a case whose rows are not its grid's from the first point up to
// a collapse or the top: a row off the grid, twice, or missing (a file cut short).
[[nodiscard]] std::vector<EvalCaseRows> eval_cases(const std::vector<EvalRun>& runs,
                                                   const std::string& where);
// Sets every run's case_collapse_g from its case's rows (eval_cases).
void assign_case_collapses(std::vector<EvalRun>& runs, const std::string& where);

// CSV: one run per row (header first); the grids are written in the header's column names
// (risk_ge_0.3, probability_ge_0.5625, nominal_risk_ge_0.3). read_eval_csv checks the header and
// every field and throws InputError naming the file and line. The columns seed, pga_from_g,
// pga_to_g and pga_steps (the case's draw and grid, after first_alarm_s) are read when present:
// a file of an earlier plinth-eval has none, and its runs have no known grid (has_grid false).
// With the P-wave stage the row ends with p_pick_s, strong_motion_s, pwave_trigger_s and the
// pwave_ge_<p> crossings; a file without them reads as runs without the stage. With regional
// alerts come the regional_ columns (kRegionalColumns); then, with with_faults, the fault block
// (kFaultColumns). A file that holds only collapses (runs_written "collapses") is read without
// the check of its cases' rows (EvalTable::collapses_only).
void write_eval_csv_header(std::FILE* out, const CrossingGrids& grids, bool with_grid,
                           bool with_faults = false);
// with_grid: the seed and grid columns. A row has them when run.grid is known (as the header must).
void write_eval_csv_row(std::FILE* out, const EvalRun& run);
struct EvalTable {
  CrossingGrids grids;
  std::vector<EvalRun> runs;
  bool has_grid = false;  // the file records each case's grid: collapse margins are known
  bool has_faults = false;  // the fault block (kFaultColumns)
  // Only the runs whose truth collapsed (plinth-eval run --collapses-only): no margins, no
  // outcome of the runs that stood.
  bool collapses_only = false;
};
[[nodiscard]] EvalTable read_eval_csv(const std::string& path);

}  // namespace plinth::host

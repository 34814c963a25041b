// plinth-eval fault-report (docs/safety.md, "Fault injection"): per runs file of one fault class
// (plinth-eval run --fault), the collapses it silenced (neither an alarm before them nor the
// faulted input named as trouble when they came) and the lead it cost against another box on the
// same cases (alarm time with the fault minus without: the share within +0.5 s).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plinth/host/eval_metrics.h"

namespace plinth::sim {

// The allowance: the box with the fault alarms no later than the box it is measured
// against + this (issue 32: in at least 95 % of the collapses).
inline constexpr double kFaultLeadAllowanceS = 0.5;

// A collapse the fault silenced, as the runs file tells it.
struct SilencedRun {
  std::string record;
  std::string scene;
  int statue = 0;
  double scale_g = 0.0;
  double collapse_time_s = 0.0;
  std::optional<double> fault_began_s;  // nullopt: the fault never began
  std::string level_at_end;             // shown just before the collapse
  std::string trouble_at_end;
  double first_warning_s = -1.0;
};

// The alarm with the fault against the other box's, over the collapses both files hold.
struct FaultLeadLoss {
  int matched = 0;
  int within = 0;  // alarmed no later than the other + kFaultLeadAllowanceS (or neither alarmed)
  int both_alarmed = 0;
  int only_other_alarmed = 0;  // the box with the fault alarmed after the collapse or never
  int only_this_alarmed = 0;
  int neither_alarmed = 0;
  std::vector<double> lost_s;  // alarm time with the fault minus without, where both alarmed
  [[nodiscard]] double within_share() const;  // within / matched (0 if none)
  [[nodiscard]] double lost_quantile(double q) const;  // of lost_s; 0 if empty
};

struct FaultClassReport {
  std::string file;
  std::string fault = "none";
  std::string param;
  std::string at;
  bool collapses_only = false;
  int runs = 0;       // rows
  int collapses = 0;  // of the runs the model held
  int alarmed = 0;    // `alarm` shown before the collapse
  int named = 0;      // the faulted input named as trouble just before the collapse
  int fault_began = 0;  // collapses before which the fault began
  // The level shown just before each collapse (level_at_end: a level's name, or down), counted.
  std::map<std::string, int> level_at_collapse;
  std::vector<SilencedRun> silenced;
  // Runs in which the box showed the statue sensor's trouble (statue_sensor_fault or
  // statue_unexplained), and each.
  int statue_trouble_runs = 0;
  int statue_fault_runs = 0;
  int statue_unexplained_runs = 0;
  // A file of every run with its grid: `alarm` as the box showed it (misses, unneeded alarms).
  std::optional<host::WarningOutcome> alarm;
  std::optional<FaultLeadLoss> against;
};

// `against`: the box to measure the lead against (its runs must hold every collapse of `table`,
// with the same truth), or nullptr. Throws InputError naming the file when it has no fault
// columns (a runs file of an earlier plinth-eval), mixes fault classes, or does not match.
[[nodiscard]] FaultClassReport make_fault_report(const host::EvalTable& table,
                                                 const std::string& file,
                                                 const host::EvalTable* against,
                                                 const std::string& against_file);
[[nodiscard]] std::string fault_report_text(const std::vector<FaultClassReport>& reports,
                                            const std::string& against_file, int list_silenced);
[[nodiscard]] std::string fault_report_json(const std::vector<FaultClassReport>& reports,
                                            const std::string& against_file);

}  // namespace plinth::sim

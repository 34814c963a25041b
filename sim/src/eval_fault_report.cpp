#include "eval_fault_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "plinth/host/input_error.h"
#include "plinth/host/json_text.h"
#include "plinth/version/version.h"

namespace plinth::sim {
namespace {

using host::EvalRun;
using host::EvalTable;
using host::InputError;

// Times within the runs file's 6 significant digits are one time.
constexpr double kSameTimeS = 1e-9;

// `v` in 6 significant digits, as the runs file writes it.
std::string g6(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

// `v` with `digits` decimals.
std::string fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

// A run's case and scale, as the runs file writes them.
std::string run_key(const EvalRun& r) {
  return r.record + "|" + r.scene + "|" + std::to_string(r.statue) + "|" +
         std::to_string(r.seed) + "|" + g6(r.scale_g);
}

std::string run_name(const EvalRun& r) {
  return r.record + ", " + r.scene + ", statue " + std::to_string(r.statue) + ", " +
         g6(r.scale_g) + " g";
}

// The box's `alarm` before the collapse: its time, or -1.
double alarm_before_collapse(const EvalRun& r) {
  const double t = r.first_shown_s[monitor::risk_level_index(monitor::AlarmLevel::kAlarm)];
  return t >= 0.0 && t < r.collapse_time_s ? t : -1.0;
}

const EvalRun::Faults& faults_of(const EvalRun& r) { return *r.faults; }

// The runs of `table` whose truth collapsed, by key.
std::map<std::string, const EvalRun*> collapses_by_key(const EvalTable& table) {
  std::map<std::string, const EvalRun*> out;
  for (const EvalRun& r : table.runs) {
    if (r.collapsed) out.emplace(run_key(r), &r);
  }
  return out;
}

FaultLeadLoss lead_loss(const std::vector<const EvalRun*>& collapses, const EvalTable& against,
                        const std::string& file, const std::string& against_file) {
  const std::map<std::string, const EvalRun*> other = collapses_by_key(against);
  FaultLeadLoss loss;
  for (const EvalRun* r : collapses) {
    const auto it = other.find(run_key(*r));
    if (it == other.end()) {
      throw InputError(against_file + ": has no collapse at " + run_name(*r) + ", which " + file +
                       " has (not the same cases: another --seed, --statues, grid or records?)");
    }
    const EvalRun& o = *it->second;
    if (std::fabs(o.collapse_time_s - r->collapse_time_s) > 1e-6 * (1.0 + r->collapse_time_s)) {
      throw InputError(against_file + ": " + run_name(*r) + " collapses at " +
                       g6(o.collapse_time_s) + " s, in " + file + " at " +
                       g6(r->collapse_time_s) + " s (another truth: --truth-step?)");
    }
    ++loss.matched;
    const double with = alarm_before_collapse(*r);
    const double without = alarm_before_collapse(o);
    if (with >= 0.0 && without >= 0.0) {
      ++loss.both_alarmed;
      loss.lost_s.push_back(with - without);
      loss.within += with - without <= kFaultLeadAllowanceS + kSameTimeS ? 1 : 0;
    } else if (with >= 0.0) {
      ++loss.only_this_alarmed;
      ++loss.within;
    } else if (without >= 0.0) {
      ++loss.only_other_alarmed;
    } else {
      ++loss.neither_alarmed;
      ++loss.within;
    }
  }
  std::sort(loss.lost_s.begin(), loss.lost_s.end());
  return loss;
}

std::string percent(int part, int whole) {
  return whole > 0 ? fixed(100.0 * part / whole, 1) + " %" : "-";
}

std::string class_name(const FaultClassReport& r) {
  std::string name = r.fault;
  if (!r.param.empty()) name += ":" + r.param;
  if (r.fault != "none") name += " at " + r.at;
  return name;
}

std::string optional_number(const std::optional<double>& v) {
  return v ? g6(*v) : "null";
}

}  // namespace

double FaultLeadLoss::within_share() const {
  return matched > 0 ? static_cast<double>(within) / matched : 0.0;
}

double FaultLeadLoss::lost_quantile(double q) const {
  if (lost_s.empty()) return 0.0;
  const double at = q * static_cast<double>(lost_s.size() - 1);
  const auto i = static_cast<std::size_t>(at);
  if (i + 1 >= lost_s.size()) return lost_s.back();
  return lost_s[i] + (at - static_cast<double>(i)) * (lost_s[i + 1] - lost_s[i]);
}

FaultClassReport make_fault_report(const EvalTable& table, const std::string& file,
                                   const EvalTable* against, const std::string& against_file) {
  if (!table.has_faults) {
    throw InputError(file + ": no fault columns (fault ... runs_written): a runs file of a "
                     "plinth-eval before fault injection; run it again with this one (plinth " +
                     std::string(version::kVersionText) + ")");
  }
  if (table.runs.empty()) throw InputError(file + ": no runs");
  FaultClassReport report;
  report.file = file;
  const EvalRun::Faults& first = faults_of(table.runs.front());
  report.fault = first.fault;
  report.param = first.param;
  report.at = first.at;
  report.collapses_only = table.collapses_only;
  std::vector<const EvalRun*> collapses;
  for (const EvalRun& r : table.runs) {
    const EvalRun::Faults& f = faults_of(r);
    if (f.fault != first.fault || f.param != first.param || f.at != first.at) {
      throw InputError(file + ": " + run_name(r) + ": fault " + f.fault + " " + f.param + " at " +
                       f.at + ", where its first row has " + class_name(report) +
                       " (one class per file)");
    }
    ++report.runs;
    const bool statue_fault = f.first_statue_fault_s >= 0.0;
    const bool unexplained = f.first_statue_unexplained_s >= 0.0;
    report.statue_fault_runs += statue_fault ? 1 : 0;
    report.statue_unexplained_runs += unexplained ? 1 : 0;
    report.statue_trouble_runs += statue_fault || unexplained ? 1 : 0;
    if (!r.collapsed || r.outside_model()) continue;
    collapses.push_back(&r);
    ++report.collapses;
    const bool alarmed = alarm_before_collapse(r) >= 0.0;
    report.alarmed += alarmed ? 1 : 0;
    report.named += f.trouble_at_end ? 1 : 0;
    ++report.level_at_collapse[f.level_at_end];
    report.fault_began += f.began_s && *f.began_s < r.collapse_time_s ? 1 : 0;
    if (!alarmed && !f.trouble_at_end) {
      report.silenced.push_back(
          {r.record, r.scene, r.statue, r.scale_g, r.collapse_time_s, f.began_s, f.level_at_end,
           monitor::alarm_cause_name(f.trouble_at_end_cause),
           r.first_shown_s[monitor::risk_level_index(monitor::AlarmLevel::kWarning)]});
    }
  }
  if (table.has_grid && !table.collapses_only) {
    report.alarm = host::level_outcome(table.runs, monitor::AlarmLevel::kAlarm);
  }
  if (against != nullptr) report.against = lead_loss(collapses, *against, file, against_file);
  return report;
}

std::string fault_report_text(const std::vector<FaultClassReport>& reports,
                              const std::string& against_file, int list_silenced) {
  std::string out;
  out += "fault-report: silenced = a collapse with neither `alarm` before it nor the faulted "
         "input named as trouble just before it\n";
  if (!against_file.empty()) {
    out += "lead against " + against_file + ": alarm time with the fault minus without, on the "
           "same collapses; within = no later than it + " +
           fixed(kFaultLeadAllowanceS, 1) + " s (or neither alarmed)\n";
  }
  for (const FaultClassReport& r : reports) {
    out += '\n';  // (appended alone: GCC 12 warns of "\n" + std::string as an overlap)
    out += class_name(r) + " (" + r.file + (r.collapses_only ? ", collapses only" : "") +
           "): " + std::to_string(r.runs) + " runs, " + std::to_string(r.collapses) +
           " collapses, the fault begun before " + std::to_string(r.fault_began) + "\n";
    out += "  alarm before the collapse: " + std::to_string(r.alarmed) + "; faulted input named "
           "at the collapse: " + std::to_string(r.named) + "; silenced: " +
           std::to_string(r.silenced.size()) + "\n";
    out += "  shown at the collapse:";
    for (const char* level : {"alarm", "warning", "advisory", "normal", "fault", "down"}) {
      const auto it = r.level_at_collapse.find(level);
      if (it == r.level_at_collapse.end()) continue;
      out += " " + it->first + " " + std::to_string(it->second);
    }
    out += '\n';
    if (r.against) {
      const FaultLeadLoss& l = *r.against;
      out += "  against " + against_file + ": " + std::to_string(l.matched) +
             " collapses; within +" + fixed(kFaultLeadAllowanceS, 1) + " s: " +
             std::to_string(l.within) + " (" + percent(l.within, l.matched) + "); both alarmed " +
             std::to_string(l.both_alarmed);
      if (!l.lost_s.empty()) {
        out += ", lost median " + fixed(l.lost_quantile(0.5), 2) + " s, 95th pct " +
               fixed(l.lost_quantile(0.95), 2) + " s, worst " +
               fixed(l.lost_s.back(), 2) + " s";
      }
      out += "; only it alarmed " + std::to_string(l.only_other_alarmed) + ", only this " +
             std::to_string(l.only_this_alarmed) + ", neither " +
             std::to_string(l.neither_alarmed) + "\n";
    }
    out += "  statue sensor trouble in " + std::to_string(r.statue_trouble_runs) + " of " +
           std::to_string(r.runs) + " runs (" + percent(r.statue_trouble_runs, r.runs) +
           "): statue_sensor_fault " + std::to_string(r.statue_fault_runs) +
           ", statue_unexplained " + std::to_string(r.statue_unexplained_runs) + "\n";
    if (r.alarm) {
      const host::BandCount u = r.alarm->unneeded();
      out += "  alarm: missed " + std::to_string(r.alarm->misses) + " of " +
             std::to_string(r.alarm->collapses) + "; unneeded (margin >= 2) " +
             percent(u.alarms, u.runs) + " (" + std::to_string(u.alarms) + " / " +
             std::to_string(u.runs) + "); lead median " +
             fixed(r.alarm->lead_quantile(0.5), 2) + " s\n";
    }
    const int shown = std::min<int>(list_silenced, static_cast<int>(r.silenced.size()));
    for (int i = 0; i < shown; ++i) {
      const SilencedRun& s = r.silenced[static_cast<std::size_t>(i)];
      out += "  silenced: " + s.record + ", " + s.scene + ", statue " + std::to_string(s.statue) +
             ", " + g6(s.scale_g) + " g: collapse at " +
             fixed(s.collapse_time_s, 3) + " s, the fault from " +
             (s.fault_began_s ? fixed(*s.fault_began_s, 3) + " s" : "never") +
             ", shown then " + s.level_at_end + " (trouble " + s.trouble_at_end + ")" +
             (s.first_warning_s >= 0.0 ? ", warning from " + fixed(s.first_warning_s, 3) +
                                             " s"
                                       : ", no warning") +
             "\n";
    }
    if (shown < static_cast<int>(r.silenced.size())) {
      out += "  ... " + std::to_string(r.silenced.size() - static_cast<std::size_t>(shown)) +
             " more silenced (--json lists them all)\n";
    }
  }
  return out;
}

std::string fault_report_json(const std::vector<FaultClassReport>& reports,
                              const std::string& against_file) {
  using host::json_quoted;
  std::string out = "{\"against\": " + (against_file.empty() ? "null" : json_quoted(against_file)) +
                    ", \"allowance_s\": " + g6(kFaultLeadAllowanceS) +
                    ", \"classes\": [";
  for (std::size_t i = 0; i < reports.size(); ++i) {
    const FaultClassReport& r = reports[i];
    out += i == 0 ? "\n" : ",\n";
    out += "{\"file\": " + json_quoted(r.file) + ", \"fault\": " + json_quoted(r.fault) +
           ", \"param\": " + json_quoted(r.param) + ", \"at\": " + json_quoted(r.at) +
           ", \"collapses_only\": " + (r.collapses_only ? "true" : "false") +
           ", \"runs\": " + std::to_string(r.runs) +
           ", \"collapses\": " + std::to_string(r.collapses) +
           ", \"fault_began\": " + std::to_string(r.fault_began) +
           ", \"alarmed\": " + std::to_string(r.alarmed) +
           ", \"named\": " + std::to_string(r.named) + ", \"level_at_collapse\": {";
    bool first_level = true;
    for (const auto& [level, count] : r.level_at_collapse) {
      out += (first_level ? "" : ", ") + json_quoted(level) + ": " + std::to_string(count);
      first_level = false;
    }
    out += '}';
    out += ", \"statue_trouble_runs\": " + std::to_string(r.statue_trouble_runs) +
           ", \"statue_fault_runs\": " + std::to_string(r.statue_fault_runs) +
           ", \"statue_unexplained_runs\": " + std::to_string(r.statue_unexplained_runs);
    if (r.alarm) {
      const host::BandCount u = r.alarm->unneeded();
      out += ", \"alarm\": {\"collapses\": " + std::to_string(r.alarm->collapses) +
             ", \"misses\": " + std::to_string(r.alarm->misses) +
             ", \"unneeded\": " + std::to_string(u.alarms) +
             ", \"unneeded_runs\": " + std::to_string(u.runs) + "}";
    }
    if (r.against) {
      const FaultLeadLoss& l = *r.against;
      out += ", \"against\": {\"matched\": " + std::to_string(l.matched) +
             ", \"within\": " + std::to_string(l.within) +
             ", \"within_share\": " + g6(l.within_share()) +
             ", \"both_alarmed\": " + std::to_string(l.both_alarmed) +
             ", \"only_other_alarmed\": " + std::to_string(l.only_other_alarmed) +
             ", \"only_this_alarmed\": " + std::to_string(l.only_this_alarmed) +
             ", \"neither_alarmed\": " + std::to_string(l.neither_alarmed) +
             ", \"lost_median_s\": " + g6(l.lost_quantile(0.5)) +
             ", \"lost_p95_s\": " + g6(l.lost_quantile(0.95)) +
             ", \"lost_max_s\": " + (l.lost_s.empty() ? "null" : g6(l.lost_s.back())) +
             "}";
    }
    out += ", \"silenced\": [";
    for (std::size_t j = 0; j < r.silenced.size(); ++j) {
      const SilencedRun& s = r.silenced[j];
      out += (j == 0 ? "" : ", ");
      out += "{\"record\": " + json_quoted(s.record) + ", \"scene\": " + json_quoted(s.scene) +
             ", \"statue\": " + std::to_string(s.statue) +
             ", \"scale_g\": " + g6(s.scale_g) +
             ", \"collapse_time_s\": " + g6(s.collapse_time_s) +
             ", \"fault_began_s\": " + optional_number(s.fault_began_s) +
             ", \"level_at_end\": " + json_quoted(s.level_at_end) +
             ", \"trouble_at_end\": " + json_quoted(s.trouble_at_end) +
             ", \"first_warning_s\": " + g6(s.first_warning_s) + "}";
    }
    out += "]}";
  }
  out += "\n]}\n";
  return out;
}

}  // namespace plinth::sim

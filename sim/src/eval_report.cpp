#include "eval_report.h"

#include <stdlib.h>  // mkdtemp

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "gnuplot.h"
#include "plinth/host/input_error.h"
#include "plinth/host/json_text.h"

namespace plinth::eval {
namespace {

using host::Choice;
using host::CrossingGrids;
using host::EvalLevel;
using host::EvalRun;
using host::EvalTable;
using host::InputError;
using host::Rule;
using host::WarningOutcome;

// The alarm policy's default risk thresholds (alarm_policy.h): today's reactive box.
constexpr double kDefaultRiskOn[host::kEvalLevels] = {0.1, 0.5, 0.8};
constexpr const char* kLevelNames[host::kEvalLevels] = {"advisory", "warning", "alarm"};

std::string number(double v, int digits = 3) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

// The grid index of `value` (the closest), -1 when the grid is empty.
int grid_index(const std::vector<double>& grid, double value) {
  int best = -1;
  for (int i = 0; i < static_cast<int>(grid.size()); ++i) {
    const double d = std::abs(grid[static_cast<std::size_t>(i)] - value);
    if (best < 0 || d < std::abs(grid[static_cast<std::size_t>(best)] - value)) best = i;
  }
  return best;
}

WarningOutcome nominal_risk_outcome(const std::vector<EvalRun>& runs, int index) {
  const Rule rule{index, -1, host::RiskSignal::kNominal};
  return host::outcome_of(runs, [&rule](const EvalRun& r) { return host::first_time(r, rule); });
}

std::vector<EvalRun> runs_of(const std::vector<EvalRun>& runs,
                             const std::vector<std::string>& records) {
  const std::set<std::string> wanted(records.begin(), records.end());
  std::vector<EvalRun> out;
  for (const EvalRun& r : runs) {
    if (wanted.count(r.record) > 0) out.push_back(r);
  }
  return out;
}

const host::LevelTarget& target_of(const CalibrationTargets& t, std::size_t level) {
  return level == 0 ? t.advisory : level == 1 ? t.warning : t.alarm;
}

std::string outcome_text(const WarningOutcome& o) {
  return std::to_string(o.hits) + "/" + std::to_string(o.collapses) + " hit, " +
         std::to_string(o.misses) + " missed, false alarms " + std::to_string(o.false_alarms) +
         "/" + std::to_string(o.quiet_runs) + " (" + number(100.0 * o.false_alarm_rate(), 1) +
         " %), near misses raised " + std::to_string(o.raised_on_near_misses) + "/" +
         std::to_string(o.near_miss_runs) + ", lead median " + number(o.lead_quantile(0.5), 2) +
         " s, 10th pct " + number(o.lead_quantile(0.1), 2) + " s";
}

std::string outcome_json(const WarningOutcome& o) {
  return "{\"collapses\": " + std::to_string(o.collapses) + ", \"hits\": " +
         std::to_string(o.hits) + ", \"misses\": " + std::to_string(o.misses) +
         ", \"quiet_runs\": " + std::to_string(o.quiet_runs) + ", \"false_alarms\": " +
         std::to_string(o.false_alarms) + ", \"false_alarm_rate\": " +
         number(o.false_alarm_rate(), 4) + ", \"near_miss_runs\": " +
         std::to_string(o.near_miss_runs) + ", \"raised_on_near_misses\": " +
         std::to_string(o.raised_on_near_misses) + ", \"lead_median_s\": " +
         number(o.lead_quantile(0.5), 3) + ", \"lead_p10_s\": " + number(o.lead_quantile(0.1), 3) +
         "}";
}

std::string names_json(const std::vector<std::string>& names) {
  std::string out = "[";
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i ? ", " : "") + host::json_quoted(names[i]);
  return out + "]";
}

}  // namespace

std::string describe_rule(const Rule& rule, const CrossingGrids& grids) {
  std::string out;
  if (rule.risk_index >= 0) {
    out += rule.risk_signal == host::RiskSignal::kNominal ? "nominal_risk >= " : "risk >= ";
    out += number(grids.risk[static_cast<std::size_t>(rule.risk_index)], 2);
  }
  if (rule.probability_index >= 0) {
    if (!out.empty()) out += " or ";
    out += "probability >= " +
           number(grids.probability[static_cast<std::size_t>(rule.probability_index)], 4);
  }
  return out.empty() ? "never" : out;
}

Report make_report(const EvalTable& table, const CalibrationTargets& targets, bool with_frontier) {
  Report report;
  report.runs = table.runs.size();
  for (const EvalRun& r : table.runs) report.outside_model += r.outside_model() ? 1U : 0U;
  std::set<std::string> names;
  for (const EvalRun& r : table.runs) names.insert(r.record);
  std::vector<std::string> halves[2];
  std::size_t k = 0;
  for (const std::string& name : names) halves[k++ % 2].push_back(name);
  const std::vector<host::RocPoint> all_points = host::roc(table.runs, table.grids);
  for (std::size_t level = 0; level < host::kEvalLevels; ++level) {
    LevelReport l;
    l.level = kLevelNames[level];
    l.shown = host::level_outcome(table.runs, static_cast<EvalLevel>(level));
    l.reactive = nominal_risk_outcome(table.runs, grid_index(table.grids.risk, kDefaultRiskOn[level]));
    const host::LevelTarget& target = target_of(targets, level);
    for (int fold = 0; fold < 2; ++fold) {
      FoldResult f;
      f.calibration_records = halves[fold];
      f.report_records = halves[1 - fold];
      const std::vector<EvalRun> calibration = runs_of(table.runs, f.calibration_records);
      const std::vector<EvalRun> held_out = runs_of(table.runs, f.report_records);
      f.chosen = host::choose_rule(host::roc(calibration, table.grids), target);
      if (f.chosen.found) {
        const Rule rule = f.chosen.point.rule;
        f.held_out = host::outcome_of(held_out,
                                      [&rule](const EvalRun& r) { return host::first_time(r, rule); });
      }
      l.folds.push_back(f);
    }
    l.all_records = host::choose_rule(all_points, target);
    report.levels.push_back(l);
  }
  if (with_frontier) {
    report.frontiers.push_back({"risk", host::frontier(all_points)});
    report.frontiers.push_back(
        {"nominal_risk",
         host::frontier(host::roc(table.runs, table.grids, host::RiskSignal::kNominal))});
  }
  return report;
}

std::string report_text(const Report& report, const CrossingGrids& grids) {
  std::string out = "plinth-eval: " + std::to_string(report.runs) + " runs";
  if (report.outside_model > 0) {
    out += ", of which " + std::to_string(report.outside_model) +
           " left the model (the true statue lifted off: no truth, counted in no outcome)";
  }
  out += "\n";
  for (const LevelReport& l : report.levels) {
    out += l.level + "\n";
    out += "  shown by the box:          " + outcome_text(l.shown) + "\n";
    out += "  today's reactive risk:     " + outcome_text(l.reactive) + "\n";
    for (std::size_t f = 0; f < l.folds.size(); ++f) {
      const FoldResult& fold = l.folds[f];
      out += "  fold " + std::to_string(f + 1) + ": chosen " +
             describe_rule(fold.chosen.point.rule, grids) +
             (fold.chosen.meets_target ? "" : " (target not met on its half)") + "\n";
      out += "    on its half:             " + outcome_text(fold.chosen.point.outcome) + "\n";
      out += "    on the other half:       " + outcome_text(fold.held_out) + "\n";
    }
    out += "  chosen on all records:     " + describe_rule(l.all_records.point.rule, grids) +
           (l.all_records.meets_target ? "" : " (target not met)") + "\n";
    out += "                             " + outcome_text(l.all_records.point.outcome) + "\n";
  }
  for (const FrontierReport& f : report.frontiers) {
    out += "frontier: the fewest false alarms of the rules on " + f.signal +
           " and probability, every record\n";
    for (const host::FrontierRow& row : f.rows) {
      out += "  " + std::string(row.constraint) + ": ";
      out += row.found ? describe_rule(row.point.rule, grids) + "\n    " +
                             outcome_text(row.point.outcome) + "\n"
                       : "none\n";
    }
  }
  return out;
}

std::string report_json(const Report& report, const CrossingGrids& grids) {
  std::string out = "{\"runs\": " + std::to_string(report.runs) +
                    ", \"outside_model\": " + std::to_string(report.outside_model) + ", \"levels\": [";
  for (std::size_t i = 0; i < report.levels.size(); ++i) {
    const LevelReport& l = report.levels[i];
    out += i ? ", " : "";
    out += "{\"level\": " + host::json_quoted(l.level) + ", \"shown\": " + outcome_json(l.shown) +
           ", \"reactive\": " + outcome_json(l.reactive) + ", \"folds\": [";
    for (std::size_t f = 0; f < l.folds.size(); ++f) {
      const FoldResult& fold = l.folds[f];
      out += f ? ", " : "";
      out += "{\"calibration_records\": " + names_json(fold.calibration_records) +
             ", \"report_records\": " + names_json(fold.report_records) +
             ", \"rule\": " + host::json_quoted(describe_rule(fold.chosen.point.rule, grids)) +
             ", \"meets_target\": " + (fold.chosen.meets_target ? "true" : "false") +
             ", \"calibration\": " + outcome_json(fold.chosen.point.outcome) +
             ", \"held_out\": " + outcome_json(fold.held_out) + "}";
    }
    out += "], \"all_records\": {\"rule\": " +
           host::json_quoted(describe_rule(l.all_records.point.rule, grids)) +
           ", \"meets_target\": " + (l.all_records.meets_target ? "true" : "false") +
           ", \"outcome\": " + outcome_json(l.all_records.point.outcome) + "}}";
  }
  out += "]";
  if (!report.frontiers.empty()) {
    out += ", \"frontier\": {";
    for (std::size_t i = 0; i < report.frontiers.size(); ++i) {
      const FrontierReport& f = report.frontiers[i];
      out += (i ? ", " : "") + host::json_quoted(f.signal) + ": [";
      for (std::size_t k = 0; k < f.rows.size(); ++k) {
        const host::FrontierRow& row = f.rows[k];
        out += (k ? ", " : "");
        out += "{\"constraint\": " + host::json_quoted(row.constraint) + ", \"rule\": " +
               (row.found ? host::json_quoted(describe_rule(row.point.rule, grids)) : "null") +
               ", \"outcome\": " + (row.found ? outcome_json(row.point.outcome) : "null") + "}";
      }
      out += "]";
    }
    out += "}";
  }
  return out + "}\n";
}

namespace {

// One series of the ROC: false-alarm rate (%) and median lead (s) per threshold.
void write_series(const std::string& path, const std::vector<WarningOutcome>& outcomes) {
  std::ofstream out(path);
  for (const WarningOutcome& o : outcomes) {
    out << 100.0 * o.false_alarm_rate() << ' ' << o.lead_quantile(0.5) << ' ' << o.misses << '\n';
  }
  if (!out) throw InputError(path + ": cannot write the plot's data");
}

}  // namespace

void plot_roc(const EvalTable& table, const std::string& png_path) {
  char folder_template[] = "/tmp/plinth-eval-plot-XXXXXX";
  if (::mkdtemp(folder_template) == nullptr) throw InputError("--plot: cannot make a temporary folder");
  const std::filesystem::path folder(folder_template);
  const auto series = [&](const char* name, std::size_t n, auto outcome) {
    std::vector<WarningOutcome> outcomes;
    for (std::size_t i = 0; i < n; ++i) outcomes.push_back(outcome(static_cast<int>(i)));
    write_series((folder / name).string(), outcomes);
  };
  const std::size_t nr = table.grids.risk.size();
  series("nominal.dat", nr, [&](int i) { return nominal_risk_outcome(table.runs, i); });
  series("worst.dat", nr, [&](int i) {
    return host::outcome_of(table.runs, [&](const EvalRun& r) { return host::first_time(r, Rule{i, -1}); });
  });
  series("probability.dat", table.grids.probability.size(), [&](int i) {
    return host::outcome_of(table.runs, [&](const EvalRun& r) { return host::first_time(r, Rule{-1, i}); });
  });
  const std::string dir = folder.string();
  {
    std::ofstream gp(folder / "roc.gp");
    gp << "set terminal pngcairo size 900,600 font ',11'\n"
       << "set output '" << dir << "/roc.png'\n"
       << "set title 'plinth-eval: lead against false alarms as the threshold moves'\n"
       << "set xlabel 'false alarms, % of the runs that stay below half the overturning angle'\n"
       << "set ylabel 'median lead before the collapse, s (misses count 0)'\n"
       << "set grid\nset key bottom right\n"
       << "plot '" << dir << "/nominal.dat' using 1:2 with linespoints title 'nominal statue, risk', "
       << "'" << dir << "/worst.dat' using 1:2 with linespoints title 'worst member, risk', "
       << "'" << dir << "/probability.dat' using 1:2 with linespoints title 'forecast probability'\n";
    if (!gp) throw InputError("--plot: cannot write the gnuplot script");
  }
  cli::run_gnuplot((folder / "roc.gp").string(), {});
  const std::string temporary = png_path + ".tmp";
  std::error_code ec;
  std::filesystem::copy_file(folder / "roc.png", temporary,
                             std::filesystem::copy_options::overwrite_existing, ec);
  if (!ec) std::filesystem::rename(temporary, png_path, ec);
  std::filesystem::remove_all(folder);
  if (ec) throw InputError(png_path + ": cannot write the plot: " + ec.message());
}

}  // namespace plinth::eval

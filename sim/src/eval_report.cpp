#include "eval_report.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "gnuplot.h"
#include "plinth/host/input_error.h"
#include "plinth/host/json_text.h"

namespace plinth::sim {
namespace {

using host::Choice;
using host::CrossingGrids;
using host::EvalRun;
using host::EvalTable;
using host::InputError;
using host::Rule;
using host::WarningOutcome;

// The alarm policy's default risk thresholds (alarm_policy.h): today's reactive box.
// Per risk level (monitor::kRiskLevels).
constexpr double kDefaultRiskOn[monitor::kRiskLevels.size()] = {0.1, 0.5, 0.8};

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

// The records' names, sorted, each once.
std::vector<std::string> record_names(const std::vector<EvalRun>& runs) {
  std::set<std::string> names;
  for (const EvalRun& r : runs) names.insert(r.record);
  return {names.begin(), names.end()};
}

const host::LevelTarget& target_of(const CalibrationTargets& t, std::size_t level) {
  return level == 0 ? t.advisory : level == 1 ? t.warning : t.alarm;
}

std::string count_text(const host::BandCount& c) {
  return std::to_string(c.alarms) + "/" + std::to_string(c.runs) +
         (c.runs > 0 ? " (" + number(100.0 * c.rate(), 1) + " %)" : "");
}

// "1-1.25", ..., ">= 3"
std::string band_name(std::size_t band) {
  const auto floor = [](std::size_t i) {
    char buffer[16];
    std::snprintf(buffer, sizeof buffer, "%g", host::kMarginBandFloors[i]);
    return std::string(buffer);
  };
  return band + 1 < host::kMarginBands ? floor(band) + "-" + floor(band + 1) : ">= " + floor(band);
}

std::string outcome_text(const WarningOutcome& o, bool margins) {
  std::string out = std::to_string(o.hits) + "/" + std::to_string(o.collapses) + " hit, " +
                    std::to_string(o.misses) + " missed, false alarms (peak < 0.5) " +
                    std::to_string(o.false_alarms) + "/" + std::to_string(o.quiet_runs) + " (" +
                    number(100.0 * o.false_alarm_rate(), 1) + " %), ";
  if (margins) {
    const host::BandCount unknown = o.margin_unknown();
    out += "unneeded (margin >= 2) " + count_text(o.unneeded()) + ", margin unknown " +
           std::to_string(unknown.alarms) + "/" + std::to_string(unknown.runs) + ", ";
  }
  return out + "near misses raised " + std::to_string(o.raised_on_near_misses) + "/" +
         std::to_string(o.near_miss_runs) + ", lead median " + number(o.lead_quantile(0.5), 2) +
         " s, 10th pct " + number(o.lead_quantile(0.1), 2) + " s";
}

// The alarm rate by margin band (and how many of the band's runs the peak calls quiet), and the
// runs bounded below only.
std::string bands_text(const WarningOutcome& o) {
  const host::MarginBands& m = o.margins;
  std::string out = "    by collapse margin (runs that stood):";
  for (std::size_t b = 0; b < host::kMarginBands; ++b) {
    out += (b ? "; " : " ") + band_name(b) + ": " + count_text(m.known[b]);
  }
  out += "\n    of those, quiet by the peak:";
  for (std::size_t b = 0; b < host::kMarginBands; ++b) {
    out += (b ? "; " : " ") + band_name(b) + ": " + std::to_string(m.known[b].quiet);
  }
  out += "\n    margin bounded below only (the case stood up to its grid's top; >= 3 counted "
         "above):";
  for (std::size_t b = 0; b < m.lower_bound.size(); ++b) {
    out += (b ? "; >= " : " >= ") + band_name(b) + ": " + count_text(m.lower_bound[b]);
  }
  if (m.below_one.runs > 0) {
    out += "\n    stood above the case's lowest collapse (margin < 1): " + count_text(m.below_one);
  }
  return out + "\n";
}

std::string count_json(const host::BandCount& c) {
  return "{\"runs\": " + std::to_string(c.runs) + ", \"alarms\": " + std::to_string(c.alarms) +
         ", \"rate\": " + (c.runs > 0 ? number(c.rate(), 4) : "null") +
         ", \"quiet\": " + std::to_string(c.quiet) + "}";
}

std::string outcome_json(const WarningOutcome& o, bool margins) {
  const auto known = [margins](const std::string& value) { return margins ? value : "null"; };
  return "{\"collapses\": " + std::to_string(o.collapses) + ", \"hits\": " +
         std::to_string(o.hits) + ", \"misses\": " + std::to_string(o.misses) +
         ", \"quiet_runs\": " + std::to_string(o.quiet_runs) + ", \"false_alarms\": " +
         std::to_string(o.false_alarms) + ", \"false_alarm_rate\": " +
         number(o.false_alarm_rate(), 4) + ", \"unneeded_runs\": " +
         known(std::to_string(o.unneeded().runs)) + ", \"unneeded_alarms\": " +
         known(std::to_string(o.unneeded().alarms)) + ", \"unneeded_rate\": " +
         known(number(o.unneeded_rate(), 4)) + ", \"margin_unknown_runs\": " +
         known(std::to_string(o.margin_unknown().runs)) + ", \"margin_unknown_alarms\": " +
         known(std::to_string(o.margin_unknown().alarms)) + ", \"near_miss_runs\": " +
         std::to_string(o.near_miss_runs) + ", \"raised_on_near_misses\": " +
         std::to_string(o.raised_on_near_misses) + ", \"lead_median_s\": " +
         number(o.lead_quantile(0.5), 3) + ", \"lead_p10_s\": " + number(o.lead_quantile(0.1), 3) +
         "}";
}

// {"bands": [{"from": 1, "to": 1.25, "runs": .., "alarms": .., "rate": ..}, ..., {"from": 3,
// "to": null, ...}], "lower_bound_only": [the same by the bound's band], "below_one": {...}}
std::string bands_json(const WarningOutcome& o) {
  const auto list = [](const auto& counts) {
    std::string out = "[";
    for (std::size_t b = 0; b < counts.size(); ++b) {
      const std::string to =
          b + 1 < host::kMarginBands ? number(host::kMarginBandFloors[b + 1], 2) : "null";
      std::string count = count_json(counts[b]);
      out += (b ? ", " : "") + std::string("{\"from\": ") + number(host::kMarginBandFloors[b], 2) +
             ", \"to\": " + to + ", " + count.substr(1);
    }
    return out + "]";
  };
  return "{\"bands\": " + list(o.margins.known) + ", \"lower_bound_only\": " +
         list(o.margins.lower_bound) + ", \"below_one\": " + count_json(o.margins.below_one) + "}";
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

void require_margins(const EvalTable& table, const CalibrationTargets& targets,
                     const std::string& name) {
  if (targets.false_alarm == host::FalseAlarm::kMargin && !table.has_grid) {
    throw InputError(name +
                     ": no seed and pga grid columns (written by a plinth-eval before the "
                     "collapse margin): the margin needs each case's grid; run plinth-eval run "
                     "again, or report with --false-alarm peak");
  }
}

Report make_report(const EvalTable& table, const CalibrationTargets& targets, bool with_frontier,
                   const EvalTable* calibration) {
  require_margins(table, targets, "the runs file");
  if (calibration != nullptr) {
    require_margins(*calibration, targets, "--calibrate-on's file");
    if (calibration->grids.risk != table.grids.risk ||
        calibration->grids.probability != table.grids.probability) {
      throw InputError("--calibrate-on: its threshold columns differ from the report's file's "
                       "(another plinth-eval version)");
    }
  }
  Report report;
  report.runs = table.runs.size();
  report.false_alarm = targets.false_alarm;
  report.margins_known = table.has_grid;
  std::vector<std::string> halves[2];
  std::size_t k = 0;
  for (const std::string& name : record_names(table.runs)) halves[k++ % 2].push_back(name);
  const std::vector<host::RocPoint> all_points = host::roc(table.runs, table.grids);
  for (std::size_t level = 0; level < monitor::kRiskLevels.size(); ++level) {
    LevelReport l;
    l.level = monitor::alarm_level_name(monitor::kRiskLevels[level]);
    l.shown = host::level_outcome(table.runs, monitor::kRiskLevels[level]);
    l.reactive = nominal_risk_outcome(table.runs, grid_index(table.grids.risk, kDefaultRiskOn[level]));
    host::LevelTarget target = target_of(targets, level);
    target.false_alarm = targets.false_alarm;
    for (int fold = 0; fold < 2; ++fold) {
      FoldResult f;
      f.calibration_records = halves[fold];
      f.report_records = halves[1 - fold];
      const std::vector<EvalRun> on_half = runs_of(table.runs, f.calibration_records);
      const std::vector<EvalRun> held_out = runs_of(table.runs, f.report_records);
      f.chosen = host::choose_rule(host::roc(on_half, table.grids), target);
      if (f.chosen.found) {
        const Rule rule = f.chosen.point.rule;
        f.held_out = host::outcome_of(held_out,
                                      [&rule](const EvalRun& r) { return host::first_time(r, rule); });
      }
      l.folds.push_back(f);
    }
    l.all_records = host::choose_rule(all_points, target);
    if (calibration != nullptr) {
      FoldResult f;
      f.calibration_records = record_names(calibration->runs);
      f.report_records = record_names(table.runs);
      f.chosen = host::choose_rule(host::roc(calibration->runs, calibration->grids), target);
      if (f.chosen.found) {
        const Rule rule = f.chosen.point.rule;
        f.held_out = host::outcome_of(table.runs,
                                      [&rule](const EvalRun& r) { return host::first_time(r, rule); });
      }
      l.calibrated_elsewhere.push_back(f);
    }
    report.levels.push_back(l);
  }
  if (with_frontier) {
    report.frontiers.push_back({"risk", host::frontier(all_points, targets.false_alarm)});
    report.frontiers.push_back(
        {"nominal_risk",
         host::frontier(host::roc(table.runs, table.grids, host::RiskSignal::kNominal),
                        targets.false_alarm)});
  }
  return report;
}

std::string report_text(const Report& report, const CrossingGrids& grids) {
  const bool m = report.margins_known;
  std::string out = "plinth-eval: " + std::to_string(report.runs) + " runs; false alarms for the "
                    "calibration and the frontier: " +
                    (report.false_alarm == host::FalseAlarm::kMargin
                         ? "unneeded alarms (--false-alarm margin: raised in runs whose collapse "
                           "margin is >= 2)\n"
                         : "alarms in quiet runs (--false-alarm peak: peak below half the "
                           "overturning angle)\n");
  if (!m) {
    out += "collapse margins: not in this file (no seed and pga grid columns: a plinth-eval "
           "before the margin)\n";
  }
  for (const LevelReport& l : report.levels) {
    out += l.level + "\n";
    out += "  shown by the box:          " + outcome_text(l.shown, m) + "\n";
    if (m) out += bands_text(l.shown);
    out += "  today's reactive risk:     " + outcome_text(l.reactive, m) + "\n";
    for (std::size_t f = 0; f < l.folds.size(); ++f) {
      const FoldResult& fold = l.folds[f];
      out += "  fold " + std::to_string(f + 1) + ": chosen " +
             describe_rule(fold.chosen.point.rule, grids) +
             (fold.chosen.meets_target ? "" : " (target not met on its half)") + "\n";
      out += "    on its half:             " + outcome_text(fold.chosen.point.outcome, m) + "\n";
      out += "    on the other half:       " + outcome_text(fold.held_out, m) + "\n";
    }
    out += "  chosen on all records:     " + describe_rule(l.all_records.point.rule, grids) +
           (l.all_records.meets_target ? "" : " (target not met)") + "\n";
    out += "                             " + outcome_text(l.all_records.point.outcome, m) + "\n";
    for (const FoldResult& f : l.calibrated_elsewhere) {
      out += "  calibrated on --calibrate-on's " + std::to_string(f.calibration_records.size()) +
             " records: chosen " + describe_rule(f.chosen.point.rule, grids) +
             (f.chosen.meets_target ? "" : " (target not met there)") + "\n";
      out += "    there:                   " + outcome_text(f.chosen.point.outcome, m) + "\n";
      out += "    here:                    " + outcome_text(f.held_out, m) + "\n";
      if (m) out += bands_text(f.held_out);
    }
  }
  for (const FrontierReport& f : report.frontiers) {
    out += "frontier: the fewest false alarms of the rules on " + f.signal +
           " and probability, every record\n";
    for (const host::FrontierRow& row : f.rows) {
      out += "  " + std::string(row.constraint) + ": ";
      out += row.found ? describe_rule(row.point.rule, grids) + "\n    " +
                             outcome_text(row.point.outcome, m) + "\n"
                       : "none\n";
    }
  }
  return out;
}

std::string report_json(const Report& report, const CrossingGrids& grids) {
  const bool m = report.margins_known;
  std::string out = "{\"runs\": " + std::to_string(report.runs) + ", \"false_alarm\": " +
                    host::json_quoted(host::false_alarm_name(report.false_alarm)) +
                    ", \"margins_known\": " + (m ? "true" : "false") + ", \"levels\": [";
  for (std::size_t i = 0; i < report.levels.size(); ++i) {
    const LevelReport& l = report.levels[i];
    out += i ? ", " : "";
    out += "{\"level\": " + host::json_quoted(l.level) + ", \"shown\": " +
           outcome_json(l.shown, m) +
           ", \"shown_by_margin\": " + (m ? bands_json(l.shown) : "null") +
           ", \"reactive\": " + outcome_json(l.reactive, m) + ", \"folds\": [";
    const auto fold_json = [&](const FoldResult& fold) {
      return "{\"calibration_records\": " + names_json(fold.calibration_records) +
             ", \"report_records\": " + names_json(fold.report_records) +
             ", \"rule\": " + host::json_quoted(describe_rule(fold.chosen.point.rule, grids)) +
             ", \"meets_target\": " + (fold.chosen.meets_target ? "true" : "false") +
             ", \"calibration\": " + outcome_json(fold.chosen.point.outcome, m) +
             ", \"held_out\": " + outcome_json(fold.held_out, m) + "}";
    };
    for (std::size_t f = 0; f < l.folds.size(); ++f) out += (f ? ", " : "") + fold_json(l.folds[f]);
    out += "], \"all_records\": {\"rule\": " +
           host::json_quoted(describe_rule(l.all_records.point.rule, grids)) +
           ", \"meets_target\": " + (l.all_records.meets_target ? "true" : "false") +
           ", \"outcome\": " + outcome_json(l.all_records.point.outcome, m) +
           "}, \"calibrated_elsewhere\": ";
    if (l.calibrated_elsewhere.empty()) {
      out += "null}";
    } else {
      const FoldResult& f = l.calibrated_elsewhere.front();
      out += fold_json(f).substr(0, fold_json(f).size() - 1) + ", \"held_out_by_margin\": " +
             (m ? bands_json(f.held_out) : "null") + "}}";
    }
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
               ", \"outcome\": " + (row.found ? outcome_json(row.point.outcome, m) : "null") +
               "}";
      }
      out += "]";
    }
    out += "}";
  }
  return out + "}\n";
}

namespace {

// One series of the ROC: false-alarm rate (%), median lead (s), misses, unneeded-alarm rate (%)
// per threshold.
void write_series(const std::string& path, const std::vector<WarningOutcome>& outcomes) {
  std::ofstream out(path);
  for (const WarningOutcome& o : outcomes) {
    out << 100.0 * o.false_alarm_rate() << ' ' << o.lead_quantile(0.5) << ' ' << o.misses << ' '
        << 100.0 * o.unneeded_rate() << '\n';
  }
  if (!out) throw InputError(path + ": cannot write the plot's data");
}

}  // namespace

void plot_roc(const EvalTable& table, const std::string& png_path) {
  const PlotFolder folder;
  const auto series = [&](const char* name, std::size_t n, auto outcome) {
    std::vector<WarningOutcome> outcomes;
    for (std::size_t i = 0; i < n; ++i) outcomes.push_back(outcome(static_cast<int>(i)));
    write_series(folder.path(name), outcomes);
  };
  const std::size_t nr = table.grids.risk.size();
  series("nominal.dat", nr, [&](int i) { return nominal_risk_outcome(table.runs, i); });
  series("worst.dat", nr, [&](int i) {
    return host::outcome_of(table.runs, [&](const EvalRun& r) { return host::first_time(r, Rule{i, -1}); });
  });
  series("probability.dat", table.grids.probability.size(), [&](int i) {
    return host::outcome_of(table.runs, [&](const EvalRun& r) { return host::first_time(r, Rule{-1, i}); });
  });
  const std::string dir = folder.path("");
  {
    std::ofstream gp(folder.path("roc.gp"));
    // One panel per false-alarm count: x column 1 (peak) and, with the grid, 4 (margin).
    const auto panel = [&](int x_column, const char* title, const char* xlabel) {
      gp << "set title '" << title << "'\n"
         << "set xlabel '" << xlabel << "'\n"
         << "plot '" << dir << "nominal.dat' using " << x_column
         << ":2 with linespoints title 'nominal statue, risk', "
         << "'" << dir << "worst.dat' using " << x_column
         << ":2 with linespoints title 'worst member, risk', "
         << "'" << dir << "probability.dat' using " << x_column
         << ":2 with linespoints title 'forecast probability'\n";
    };
    gp << "set terminal pngcairo size " << (table.has_grid ? "1500,600" : "900,600")
       << " font ',11'\n"
       << "set output '" << dir << "roc.png'\n"
       << "set ylabel 'median lead before the collapse, s (misses count 0)'\n"
       << "set grid\nset key bottom right\n";
    if (table.has_grid) gp << "set multiplot layout 1,2\n";
    panel(1, "plinth-eval: lead against false alarms as the threshold moves",
          "false alarms, % of the runs that stay below half the overturning angle");
    if (table.has_grid) {
      panel(4, "the same against unneeded alarms",
            "unneeded alarms, % of the runs whose collapse margin is >= 2");
      gp << "unset multiplot\n";
    }
    if (!gp) throw InputError("--plot: cannot write the gnuplot script");
  }
  folder.draw("roc.gp", "roc.png", png_path);
}

}  // namespace plinth::sim

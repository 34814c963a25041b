#include "plinth/host/eval_metrics.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string_view>
#include <system_error>

#include "plinth/host/input_error.h"

namespace plinth::host {

namespace {

constexpr std::array<const char*, kEvalLevels> kLevelNames{"advisory", "warning", "alarm"};

// The header's fixed columns, before the crossing grids.
constexpr std::array<std::string_view, 10> kFixedColumns{
    "record",          "scene",      "statue",           "scale_g",         "collapsed",
    "collapse_time_s", "peak_ratio", "first_advisory_s", "first_warning_s", "first_alarm_s"};

std::string format(double v) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

// A text field: quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

// Splits one CSV line (RFC 4180 quoting); false on an unterminated quote.
bool split_csv(const std::string& line, std::vector<std::string>& fields) {
  fields.clear();
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.push_back(field);
      field.clear();
    } else {
      field += c;
    }
  }
  fields.push_back(field);
  return !quoted;
}

double parse_number(const std::string& text, const std::string& where, std::string_view column) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, v);
  if (r.ec != std::errc{} || r.ptr != end || !std::isfinite(v)) {
    throw InputError(where + ": " + std::string(column) + ": expected a finite number, got \"" +
                     text + "\"");
  }
  return v;
}

// A first time: -1 (never) or a time >= 0.
double parse_time(const std::string& text, const std::string& where, std::string_view column) {
  const double v = parse_number(text, where, column);
  if (v != -1.0 && v < 0.0) {
    throw InputError(where + ": " + std::string(column) + ": expected a time >= 0 or -1, got " +
                     text);
  }
  return v;
}

// The grid value in a column name "<prefix><value>".
bool grid_value(std::string_view column, std::string_view prefix, double& value) {
  if (!column.starts_with(prefix)) return false;
  column.remove_prefix(prefix.size());
  const auto r = std::from_chars(column.data(), column.data() + column.size(), value);
  return r.ec == std::errc{} && r.ptr == column.data() + column.size();
}

}  // namespace

const char* eval_level_name(EvalLevel level) {
  const auto i = static_cast<std::size_t>(level);
  return i < kEvalLevels ? kLevelNames[i] : "invalid";
}

CrossingGrids default_crossing_grids() {
  CrossingGrids g;
  for (int i = 1; i <= 20; ++i) g.risk.push_back(0.05 * i);
  // Member fractions of the designs (5, 9 or 17 members) fall between these.
  for (int i = 1; i <= 16; ++i) g.probability.push_back(i / 16.0);
  return g;
}

std::vector<double> default_pwave_grid() {
  return {0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5,
          0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 0.99};
}

double WarningOutcome::false_alarm_rate() const {
  return quiet_runs > 0 ? static_cast<double>(false_alarms) / quiet_runs : 0.0;
}

double WarningOutcome::lead_quantile(double q) const {
  if (leads_s.empty()) return -1.0;
  std::vector<double> sorted = leads_s;
  std::sort(sorted.begin(), sorted.end());
  // Linear interpolation between order statistics (the usual "type 7" quantile).
  const double position = q * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  const double w = position - static_cast<double>(below);
  return sorted[below] + w * (sorted[above] - sorted[below]);
}

WarningOutcome level_outcome(const std::vector<EvalRun>& runs, EvalLevel level) {
  return outcome_of(runs, [level](const EvalRun& r) {
    return r.first_shown_s[static_cast<std::size_t>(level)];
  });
}

double first_time(const EvalRun& run, const Rule& rule) {
  double t = -1.0;
  const auto earlier = [&t](double candidate) {
    if (candidate >= 0.0 && (t < 0.0 || candidate < t)) t = candidate;
  };
  const std::vector<double>& risk = rule.risk_signal == RiskSignal::kNominal
                                        ? run.nominal_risk_crossing_s
                                        : run.risk_crossing_s;
  if (rule.risk_index >= 0 && static_cast<std::size_t>(rule.risk_index) < risk.size()) {
    earlier(risk[static_cast<std::size_t>(rule.risk_index)]);
  }
  if (rule.probability_index >= 0 &&
      static_cast<std::size_t>(rule.probability_index) < run.probability_crossing_s.size()) {
    earlier(run.probability_crossing_s[static_cast<std::size_t>(rule.probability_index)]);
  }
  return t;
}

std::vector<RocPoint> roc(const std::vector<EvalRun>& runs, const CrossingGrids& grids,
                          RiskSignal risk_signal) {
  std::vector<RocPoint> points;
  const int nr = static_cast<int>(grids.risk.size());
  const int np = static_cast<int>(grids.probability.size());
  for (int r = -1; r < nr; ++r) {
    for (int p = -1; p < np; ++p) {
      if (r < 0 && p < 0) continue;
      const Rule rule{r, p, risk_signal};
      points.push_back({rule, outcome_of(runs, [&](const EvalRun& run) {
                          return first_time(run, rule);
                        })});
    }
  }
  return points;
}

Choice choose_rule(const std::vector<RocPoint>& points, const LevelTarget& target) {
  // Safety first: 0 meets both; 1 misses no more than allowed, too many false alarms; 2 within
  // the rate, more misses; 3 neither.
  const auto rank = [&](const WarningOutcome& o) {
    const bool misses_ok = o.misses <= target.max_misses;
    const bool rate_ok = o.false_alarm_rate() <= target.max_false_alarm_rate;
    return misses_ok ? (rate_ok ? 0 : 1) : (rate_ok ? 2 : 3);
  };
  const auto lead = [](const WarningOutcome& o) { return o.lead_quantile(0.5); };
  Choice best;
  for (const RocPoint& p : points) {
    const int ra = rank(p.outcome);
    if (!best.found) {
      best = {true, ra == 0, p};
      continue;
    }
    const WarningOutcome& a = p.outcome;
    const WarningOutcome& b = best.point.outcome;
    const int rb = rank(b);
    bool better = false;
    if (ra != rb) {
      better = ra < rb;
    } else if (ra == 0) {
      better = lead(a) > lead(b) ||
               (lead(a) == lead(b) && a.false_alarm_rate() < b.false_alarm_rate());
    } else if (ra == 1) {
      better = a.false_alarm_rate() < b.false_alarm_rate() ||
               (a.false_alarm_rate() == b.false_alarm_rate() && lead(a) > lead(b));
    } else if (ra == 2) {
      better = a.misses < b.misses || (a.misses == b.misses && lead(a) > lead(b));
    } else {
      better = a.misses < b.misses ||
               (a.misses == b.misses && a.false_alarm_rate() < b.false_alarm_rate());
    }
    if (better) best = {true, ra == 0, p};
  }
  return best;
}

std::vector<FrontierRow> frontier(const std::vector<RocPoint>& points) {
  using Allowed = bool (*)(const WarningOutcome&);
  struct Constraint {
    const char* name;
    Allowed allowed;
    bool fewest_misses_first;
  };
  static constexpr Constraint kConstraints[] = {
      {"no miss", [](const WarningOutcome& o) { return o.misses == 0; }, false},
      {"no miss, median lead >= 1.5 s",
       [](const WarningOutcome& o) { return o.misses == 0 && o.lead_quantile(0.5) >= 1.5; },
       false},
      {"no miss, 10th pct lead >= 0.5 s",
       [](const WarningOutcome& o) { return o.misses == 0 && o.lead_quantile(0.1) >= 0.5; },
       false},
      {"no miss, median lead >= 3 s",
       [](const WarningOutcome& o) { return o.misses == 0 && o.lead_quantile(0.5) >= 3.0; },
       false},
      {"false alarms <= 5 %", [](const WarningOutcome& o) { return o.false_alarm_rate() <= 0.05; },
       true},
      {"fewest false alarms", [](const WarningOutcome&) { return true; }, false},
  };
  // Lexicographic: (false alarms, misses, -median lead), or (misses, false alarms, -median).
  const auto better = [](const WarningOutcome& a, const WarningOutcome& b, bool misses_first) {
    const double fa = a.false_alarm_rate();
    const double fb = b.false_alarm_rate();
    if (misses_first && a.misses != b.misses) return a.misses < b.misses;
    if (fa != fb) return fa < fb;
    if (a.misses != b.misses) return a.misses < b.misses;
    return a.lead_quantile(0.5) > b.lead_quantile(0.5);
  };
  std::vector<FrontierRow> rows;
  for (const Constraint& c : kConstraints) {
    FrontierRow row;
    row.constraint = c.name;
    for (const RocPoint& p : points) {
      if (!c.allowed(p.outcome)) continue;
      if (!row.found || better(p.outcome, row.point.outcome, c.fewest_misses_first)) {
        row.found = true;
        row.point = p;
      }
    }
    rows.push_back(row);
  }
  return rows;
}

void write_eval_csv_header(std::FILE* out, const CrossingGrids& grids) {
  std::string line;
  for (std::string_view c : kFixedColumns) {
    if (!line.empty()) line += ',';
    line += c;
  }
  for (double v : grids.risk) {
    line += ",risk_ge_";
    line += format(v);
  }
  for (double v : grids.probability) {
    line += ",probability_ge_";
    line += format(v);
  }
  for (double v : grids.risk) {
    line += ",nominal_risk_ge_";
    line += format(v);
  }
  if (!grids.pwave.empty()) line += ",p_pick_s,strong_motion_s,pwave_trigger_s";
  for (double v : grids.pwave) {
    line += ",pwave_ge_";
    line += format(v);
  }
  std::fprintf(out, "%s\n", line.c_str());
}

void write_eval_csv_row(std::FILE* out, const EvalRun& r) {
  std::string line = csv_field(r.record);
  const auto add = [&line](const std::string& field) {
    line += ',';
    line += field;
  };
  add(csv_field(r.scene));
  add(std::to_string(r.statue));
  add(format(r.scale_g));
  add(r.collapsed ? "1" : "0");
  add(format(r.collapse_time_s));
  add(format(r.peak_ratio));
  for (double t : r.first_shown_s) add(format(t));
  for (double t : r.risk_crossing_s) add(format(t));
  for (double t : r.probability_crossing_s) add(format(t));
  for (double t : r.nominal_risk_crossing_s) add(format(t));
  if (!r.pwave_crossing_s.empty()) {
    add(format(r.p_pick_s));
    add(format(r.strong_motion_s));
    add(format(r.pwave_trigger_s));
  }
  for (double t : r.pwave_crossing_s) add(format(t));
  std::fprintf(out, "%s\n", line.c_str());
}

EvalTable read_eval_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  EvalTable table;
  std::string line;
  std::vector<std::string> f;
  if (!std::getline(in, line) || !split_csv(line, f) || f.size() < kFixedColumns.size()) {
    throw InputError(path + ":1: not a plinth-eval runs file (header missing)");
  }
  for (std::size_t i = 0; i < kFixedColumns.size(); ++i) {
    if (f[i] != kFixedColumns[i]) {
      throw InputError(path + ":1: column " + std::to_string(i + 1) + ": expected \"" +
                       std::string(kFixedColumns[i]) + "\", got \"" + f[i] + "\"");
    }
  }
  std::vector<double> nominal_grid;
  bool pwave_block = false;  // p_pick_s, strong_motion_s, pwave_trigger_s, then pwave_ge_
  for (std::size_t i = kFixedColumns.size(); i < f.size(); ++i) {
    double v = 0.0;
    if (f[i] == "p_pick_s" && !pwave_block && i + 2 < f.size() && f[i + 1] == "strong_motion_s" &&
        f[i + 2] == "pwave_trigger_s") {
      pwave_block = true;
      i += 2;
    } else if (pwave_block && grid_value(f[i], "pwave_ge_", v)) {
      table.grids.pwave.push_back(v);
    } else if (pwave_block) {
      throw InputError(path + ":1: column " + std::to_string(i + 1) +
                       ": after the P-wave columns only pwave_ge_ columns may come, got \"" +
                       f[i] + "\"");
    } else if (grid_value(f[i], "risk_ge_", v) && table.grids.probability.empty()) {
      table.grids.risk.push_back(v);
    } else if (grid_value(f[i], "probability_ge_", v) && nominal_grid.empty()) {
      table.grids.probability.push_back(v);
    } else if (grid_value(f[i], "nominal_risk_ge_", v)) {
      nominal_grid.push_back(v);
    } else {
      throw InputError(path + ":1: column " + std::to_string(i + 1) + ": unknown column \"" +
                       f[i] + "\"");
    }
  }
  if (nominal_grid != table.grids.risk) {
    throw InputError(path + ":1: the nominal_risk_ge_ columns must repeat the risk_ge_ grid");
  }
  if (pwave_block && table.grids.pwave.empty()) {
    throw InputError(path + ":1: the P-wave columns need their pwave_ge_ columns");
  }
  const std::size_t columns = f.size();
  for (std::size_t n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::string where = path + ":" + std::to_string(n);
    if (!split_csv(line, f)) throw InputError(where + ": unterminated quoted field");
    if (f.size() != columns) {
      throw InputError(where + ": expected " + std::to_string(columns) + " fields, got " +
                       std::to_string(f.size()));
    }
    EvalRun r;
    r.record = f[0];
    r.scene = f[1];
    const double statue = parse_number(f[2], where, "statue");
    if (statue < 0.0 || statue != std::floor(statue) || statue > 1e6) {
      throw InputError(where + ": statue: expected a whole number >= 0, got " + f[2]);
    }
    r.statue = static_cast<int>(statue);
    r.scale_g = parse_number(f[3], where, "scale_g");
    if (f[4] != "0" && f[4] != "1") {
      throw InputError(where + ": collapsed: expected 0 or 1, got \"" + f[4] + "\"");
    }
    r.collapsed = f[4] == "1";
    r.collapse_time_s = parse_time(f[5], where, "collapse_time_s");
    if (r.collapsed != (r.collapse_time_s >= 0.0)) {
      throw InputError(where + ": collapse_time_s: must be >= 0 exactly when collapsed is 1");
    }
    r.peak_ratio = parse_number(f[6], where, "peak_ratio");
    if (r.peak_ratio < 0.0) throw InputError(where + ": peak_ratio: must be >= 0");
    for (std::size_t i = 0; i < kEvalLevels; ++i) {
      r.first_shown_s[i] = parse_time(f[7 + i], where, kFixedColumns[7 + i]);
    }
    std::size_t c = kFixedColumns.size();
    for (std::size_t i = 0; i < table.grids.risk.size(); ++i, ++c) {
      r.risk_crossing_s.push_back(parse_time(f[c], where, "risk crossing"));
    }
    for (std::size_t i = 0; i < table.grids.probability.size(); ++i, ++c) {
      r.probability_crossing_s.push_back(parse_time(f[c], where, "probability crossing"));
    }
    for (std::size_t i = 0; i < table.grids.risk.size(); ++i, ++c) {
      r.nominal_risk_crossing_s.push_back(parse_time(f[c], where, "nominal risk crossing"));
    }
    if (pwave_block) {
      r.p_pick_s = parse_time(f[c++], where, "p_pick_s");
      r.strong_motion_s = parse_time(f[c++], where, "strong_motion_s");
      r.pwave_trigger_s = parse_time(f[c++], where, "pwave_trigger_s");
      for (std::size_t i = 0; i < table.grids.pwave.size(); ++i, ++c) {
        r.pwave_crossing_s.push_back(parse_time(f[c], where, "P-wave crossing"));
      }
    }
    table.runs.push_back(std::move(r));
  }
  return table;
}

}  // namespace plinth::host

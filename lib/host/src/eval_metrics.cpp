#include "plinth/host/eval_metrics.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <span>
#include <map>
#include <string_view>
#include <system_error>
#include <tuple>

#include "plinth/host/csv_line.h"
#include "plinth/host/input_error.h"

namespace plinth::host {

namespace {

// The column after them when a run may have left the model (EvalRun::model_valid_until_s; a
// runs file without it has none).
constexpr std::string_view kModelValidColumn = "model_valid_until_s";

// The header's fixed columns, before the crossing grids.
constexpr std::array<std::string_view, 10> kFixedColumns{
    "record",          "scene",      "statue",           "scale_g",         "collapsed",
    "collapse_time_s", "peak_ratio", "first_advisory_s", "first_warning_s", "first_alarm_s"};
// Then the case's draw and grid (since the collapse margin; absent from earlier files).
constexpr std::array<std::string_view, 4> kGridColumns{"seed", "pga_from_g", "pga_to_g",
                                                       "pga_steps"};
constexpr int kMaxGridSteps = 1000;
// A margin within this fraction below a band's floor is on the floor (the grid's divisions).
constexpr double kMarginRounding = 1e-9;
// Grid points and scale_g agree within the runs file's 6 significant digits.
constexpr double kGridMatch = 1e-5;

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

std::string grid_text(double v) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
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

// The regional columns from f[c] on (kRegionalColumns' order), each checked.
EvalRun::Regional parse_regional(const std::vector<std::string>& f, std::size_t c,
                                 const std::string& where) {
  std::array<double, kRegionalColumns.size()> v{};
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = parse_number(f[c + i], where, kRegionalColumns[i]);
  EvalRun::Regional g{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]};
  const auto refuse = [&](std::size_t i, const char* expected) {
    throw InputError(where + ": " + std::string(kRegionalColumns[i]) + ": expected " + expected +
                     ", got " + f[c + i]);
  };
  if (!(g.magnitude > 0.0 && g.magnitude <= 10.0)) refuse(0, "a magnitude in (0, 10]");
  if (!(g.rhyp_km > 0.0)) refuse(1, "a distance above 0 km");
  if (!(g.s_arrival_s >= g.origin_s)) refuse(4, "an S arrival at or after the origin");
  if (!(g.alert_s >= g.origin_s)) refuse(3, "an alert at or after the origin");
  if (!(g.pga_g > 0.0)) refuse(5, "a PGA above 0 g");
  if (!(g.sigma_ln >= 0.0)) refuse(6, "a sigma_ln >= 0");
  if (!(g.probability >= 0.0 && g.probability <= 1.0)) refuse(7, "a probability in [0, 1]");
  return g;
}

// The grid value in a column name "<prefix><value>".
bool grid_value(std::string_view column, std::string_view prefix, double& value) {
  if (!column.starts_with(prefix)) return false;
  column.remove_prefix(prefix.size());
  const auto r = std::from_chars(column.data(), column.data() + column.size(), value);
  return r.ec == std::errc{} && r.ptr == column.data() + column.size();
}

// The fault block from f[c] on (kFaultColumns' order), each checked.
EvalRun::Faults parse_faults(const std::vector<std::string>& f, std::size_t c,
                             const std::string& where) {
  const auto column = [&](std::size_t i) { return std::string(kFaultColumns[i]); };
  EvalRun::Faults x;
  x.fault = f[c];
  x.param = f[c + 1];
  x.at = f[c + 2];
  if (x.fault.empty()) throw InputError(where + ": fault: expected a kind or none, got nothing");
  if (!f[c + 3].empty()) x.began_s = parse_number(f[c + 3], where, kFaultColumns[3]);
  if (x.fault == "none" && (!x.param.empty() || !x.at.empty() || x.began_s)) {
    throw InputError(where + ": fault none: its parameter, onset and began_s must be empty");
  }
  x.first_trouble_s = parse_time(f[c + 4], where, kFaultColumns[4]);
  if (f[c + 5] != "0" && f[c + 5] != "1") {
    throw InputError(where + ": " + column(5) + ": expected 0 or 1, got \"" + f[c + 5] + "\"");
  }
  x.trouble_at_end = f[c + 5] == "1";
  x.first_statue_fault_s = parse_time(f[c + 6], where, kFaultColumns[6]);
  x.first_statue_unexplained_s = parse_time(f[c + 7], where, kFaultColumns[7]);
  monitor::AlarmLevel level{};
  if (f[c + 8] != kBoxDown && !monitor::kAlarmLevelNames.parse(f[c + 8], level)) {
    throw InputError(where + ": " + column(8) + ": expected a level or " +
                     std::string(kBoxDown) + ", got \"" + f[c + 8] + "\"");
  }
  x.level_at_end = f[c + 8];
  if (!monitor::kAlarmCauseNames.parse(f[c + 9], x.trouble_at_end_cause)) {
    throw InputError(where + ": " + column(9) + ": expected a cause, got \"" + f[c + 9] + "\"");
  }
  if (f[c + 10] != "all" && f[c + 10] != "collapses") {
    throw InputError(where + ": " + column(10) + ": expected all or collapses, got \"" +
                     f[c + 10] + "\"");
  }
  x.collapses_only = f[c + 10] == "collapses";
  return x;
}

}  // namespace

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

const char* false_alarm_name(FalseAlarm definition) {
  return definition == FalseAlarm::kPeak ? "peak" : "margin";
}

bool parse_false_alarm(const std::string& text, FalseAlarm& definition) {
  if (text == "margin" || text == "peak") {
    definition = text == "peak" ? FalseAlarm::kPeak : FalseAlarm::kMargin;
    return true;
  }
  return false;
}

double PgaGrid::at(int i) const {
  return steps == 1 ? from_g : from_g + (to_g - from_g) * i / (steps - 1);
}

int PgaGrid::index_of(double pga_g) const {
  if (!known()) return -1;
  const double span = to_g - from_g;
  const long i =
      steps == 1 || !(span > 0.0) ? 0 : std::lround((pga_g - from_g) / span * (steps - 1));
  if (i < 0 || i >= steps) return -1;
  const double point = at(static_cast<int>(i));
  return std::abs(point - pga_g) <= kGridMatch * std::max(std::abs(point), std::abs(pga_g))
             ? static_cast<int>(i)
             : -1;
}

double EvalRun::collapse_margin() const {
  if (!grid.known() || !(scale_g > 0.0)) return 0.0;
  return (margin_is_lower_bound() ? grid.top_g() : case_collapse_g) / scale_g;
}

double BandCount::rate() const { return runs > 0 ? static_cast<double>(alarms) / runs : 0.0; }

void count_margin(const EvalRun& run, bool raised, MarginBands& bands) {
  if (!run.grid.known() || run.collapsed) return;
  const double margin = run.collapse_margin();
  std::size_t band = kMarginBands;  // none: below 1
  for (std::size_t i = kMarginBands; i-- > 0 && band == kMarginBands;) {
    if (margin >= kMarginBandFloors[i] * (1.0 - kMarginRounding)) band = i;
  }
  const bool top = band == kMarginBands - 1;
  BandCount& count = band == kMarginBands                  ? bands.below_one
                     : run.margin_is_lower_bound() && !top ? bands.lower_bound[band]
                                                           : bands.known[band];
  ++count.runs;
  count.alarms += raised ? 1 : 0;
  count.quiet += run.quiet() ? 1 : 0;
}

BandCount WarningOutcome::unneeded() const {
  BandCount c;
  const auto add = [&c](const BandCount& b) {
    c.runs += b.runs;
    c.alarms += b.alarms;
    c.quiet += b.quiet;
  };
  for (std::size_t i = 0; i < kMarginBands; ++i) {
    if (kMarginBandFloors[i] >= kUnneededMargin) add(margins.known[i]);
    if (i < margins.lower_bound.size() && kMarginBandFloors[i] >= kUnneededMargin) {
      add(margins.lower_bound[i]);
    }
  }
  return c;
}

BandCount WarningOutcome::margin_unknown() const {
  BandCount c;
  for (std::size_t i = 0; i < margins.lower_bound.size(); ++i) {
    if (kMarginBandFloors[i] < kUnneededMargin) {
      c.runs += margins.lower_bound[i].runs;
      c.alarms += margins.lower_bound[i].alarms;
      c.quiet += margins.lower_bound[i].quiet;
    }
  }
  return c;
}

double WarningOutcome::false_alarm_rate() const {
  return quiet_runs > 0 ? static_cast<double>(false_alarms) / quiet_runs : 0.0;
}

double WarningOutcome::false_alarm_rate(FalseAlarm definition) const {
  return definition == FalseAlarm::kPeak ? false_alarm_rate() : unneeded_rate();
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

WarningOutcome level_outcome(const std::vector<EvalRun>& runs, monitor::AlarmLevel level) {
  return outcome_of(runs, [level](const EvalRun& r) {
    return r.first_shown_s[monitor::risk_level_index(level)];
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
  const auto rate = [&target](const WarningOutcome& o) {
    return o.false_alarm_rate(target.false_alarm);
  };
  const auto rank = [&](const WarningOutcome& o) {
    const bool misses_ok = o.misses <= target.max_misses;
    const bool rate_ok = rate(o) <= target.max_false_alarm_rate;
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
      better = lead(a) > lead(b) || (lead(a) == lead(b) && rate(a) < rate(b));
    } else if (ra == 1) {
      better = rate(a) < rate(b) || (rate(a) == rate(b) && lead(a) > lead(b));
    } else if (ra == 2) {
      better = a.misses < b.misses || (a.misses == b.misses && lead(a) > lead(b));
    } else {
      better = a.misses < b.misses || (a.misses == b.misses && rate(a) < rate(b));
    }
    if (better) best = {true, ra == 0, p};
  }
  return best;
}

std::vector<FrontierRow> frontier(const std::vector<RocPoint>& points, FalseAlarm false_alarm) {
  using Allowed = bool (*)(const WarningOutcome&, FalseAlarm);
  // Which rule of those a constraint allows is the best (lexicographic, see `better`).
  enum class Order { kFewestFalseAlarms, kFewestMisses, kLongestLead };
  struct Constraint {
    const char* name;
    Allowed allowed;
    Order order;
  };
  static constexpr Constraint kConstraints[] = {
      {"no miss", [](const WarningOutcome& o, FalseAlarm) { return o.misses == 0; },
       Order::kFewestFalseAlarms},
      {"no miss, median lead >= 1.5 s",
       [](const WarningOutcome& o, FalseAlarm) {
         return o.misses == 0 && o.lead_quantile(0.5) >= 1.5;
       },
       Order::kFewestFalseAlarms},
      {"no miss, 10th pct lead >= 0.5 s",
       [](const WarningOutcome& o, FalseAlarm) {
         return o.misses == 0 && o.lead_quantile(0.1) >= 0.5;
       },
       Order::kFewestFalseAlarms},
      {"no miss, median lead >= 3 s",
       [](const WarningOutcome& o, FalseAlarm) {
         return o.misses == 0 && o.lead_quantile(0.5) >= 3.0;
       },
       Order::kFewestFalseAlarms},
      {"false alarms <= 5 %",
       [](const WarningOutcome& o, FalseAlarm f) { return o.false_alarm_rate(f) <= 0.05; },
       Order::kFewestMisses},
      {"fewest false alarms", [](const WarningOutcome&, FalseAlarm) { return true; },
       Order::kFewestFalseAlarms},
      // Issue 24's target at `alarm` read the other way: the longest lead it allows.
      {"no miss, false alarms <= 9 %: longest lead",
       [](const WarningOutcome& o, FalseAlarm f) {
         return o.misses == 0 && o.false_alarm_rate(f) <= kStatueSensorMaxUnneededRate;
       },
       Order::kLongestLead},
  };
  // Lexicographic: (false alarms, misses, -median lead), (misses, false alarms, -median lead) or
  // (-median lead, false alarms, misses).
  const auto better = [false_alarm](const WarningOutcome& a, const WarningOutcome& b, Order order) {
    const double fa = a.false_alarm_rate(false_alarm);
    const double fb = b.false_alarm_rate(false_alarm);
    const double la = a.lead_quantile(0.5);
    const double lb = b.lead_quantile(0.5);
    if (order == Order::kLongestLead && la != lb) return la > lb;
    if (order == Order::kFewestMisses && a.misses != b.misses) return a.misses < b.misses;
    if (fa != fb) return fa < fb;
    if (a.misses != b.misses) return a.misses < b.misses;
    return la > lb;
  };
  std::vector<FrontierRow> rows;
  for (const Constraint& c : kConstraints) {
    FrontierRow row;
    row.constraint = c.name;
    for (const RocPoint& p : points) {
      if (!c.allowed(p.outcome, false_alarm)) continue;
      if (!row.found || better(p.outcome, row.point.outcome, c.order)) {
        row.found = true;
        row.point = p;
      }
    }
    rows.push_back(row);
  }
  return rows;
}

namespace {

std::string case_name(const EvalRun& r) {
  return r.record + ", " + r.scene + ", statue " + std::to_string(r.statue) + ", seed " +
         std::to_string(r.seed);
}

std::string grid_name(const PgaGrid& g) {
  return grid_text(g.from_g) + " to " + grid_text(g.to_g) + " g in " + std::to_string(g.steps) +
         " steps";
}

}  // namespace

std::vector<EvalCaseRows> eval_cases(const std::vector<EvalRun>& runs, const std::string& where) {
  using Key = std::tuple<std::string, std::string, int, std::uint32_t>;
  std::map<Key, std::size_t> index;
  std::vector<EvalCaseRows> cases;
  std::vector<std::vector<int>> points;  // each case's grid indices, as its rows come
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const EvalRun& r = runs[i];
    if (!r.grid.known()) continue;
    const Key key{r.record, r.scene, r.statue, r.seed};
    auto [it, added] = index.emplace(key, cases.size());
    if (added) {
      cases.push_back({r.record, r.scene, r.statue, r.seed, r.grid, -1, {}});
      points.emplace_back();
    }
    EvalCaseRows& c = cases[it->second];
    if (!(r.grid == c.grid)) {
      throw InputError(where + ": case " + case_name(r) + ": rows of two grids (" +
                       grid_name(c.grid) + ", " + grid_name(r.grid) + ")");
    }
    const int point = c.grid.index_of(r.scale_g);
    if (point < 0) {
      throw InputError(where + ": case " + case_name(r) + ": scale_g " + grid_text(r.scale_g) +
                       " g is not a point of its grid (" + grid_name(c.grid) + ")");
    }
    c.runs.push_back(i);
    points[it->second].push_back(point);
  }
  for (std::size_t k = 0; k < cases.size(); ++k) {
    EvalCaseRows& c = cases[k];
    std::vector<std::size_t> order(c.runs.size());
    for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return points[k][a] < points[k][b]; });
    std::vector<std::size_t> sorted;
    for (std::size_t j = 0; j < order.size(); ++j) {
      const int point = points[k][order[j]];
      const EvalRun& r = runs[c.runs[order[j]]];
      if (point != static_cast<int>(j)) {
        throw InputError(where + ": case " + case_name(r) + ": " +
                         (point < static_cast<int>(j)
                              ? "two rows at " + grid_text(c.grid.at(point)) + " g"
                              : "no row at " + grid_text(c.grid.at(static_cast<int>(j))) +
                                    " g, below its rows at higher PGA") +
                         " (its rows run up the grid from " + grid_text(c.grid.from_g) + " g)");
      }
      if (c.first_collapse < 0 && r.collapsed) c.first_collapse = point;
      sorted.push_back(c.runs[order[j]]);
    }
    c.runs = std::move(sorted);
    if (c.first_collapse < 0 && static_cast<int>(c.runs.size()) < c.grid.steps) {
      throw InputError(where + ": case " + case_name(runs[c.runs.front()]) + ": its rows stop at " +
                       grid_text(c.grid.at(static_cast<int>(c.runs.size()) - 1)) +
                       " g without a collapse, below its grid's top " + grid_text(c.grid.top_g()) +
                       " g (a file cut short, or part of a shard?)");
    }
  }
  return cases;
}

void assign_case_collapses(std::vector<EvalRun>& runs, const std::string& where) {
  for (const EvalCaseRows& c : eval_cases(runs, where)) {
    const double collapse_g = c.first_collapse >= 0 ? c.grid.at(c.first_collapse) : -1.0;
    for (std::size_t i : c.runs) runs[i].case_collapse_g = collapse_g;
  }
}

void write_eval_csv_header(std::FILE* out, const CrossingGrids& grids, bool with_grid,
                           bool with_faults) {
  std::string line;
  for (std::string_view c : kFixedColumns) {
    if (!line.empty()) line += ',';
    line += c;
  }
  line += ',';
  line += kModelValidColumn;
  for (std::string_view c : with_grid ? std::span<const std::string_view>(kGridColumns)
                                      : std::span<const std::string_view>()) {
    line += ',';
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
  for (std::string_view c : grids.regional ? std::span<const std::string_view>(kRegionalColumns)
                                           : std::span<const std::string_view>()) {
    line += ',';
    line += c;
  }
  for (std::string_view c : with_faults ? std::span<const std::string_view>(kFaultColumns)
                                        : std::span<const std::string_view>()) {
    line += ',';
    line += c;
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
  add(format(r.model_valid_until_s));
  if (r.grid.known()) {
    add(std::to_string(r.seed));
    add(grid_text(r.grid.from_g));
    add(grid_text(r.grid.to_g));
    add(std::to_string(r.grid.steps));
  }
  for (double t : r.risk_crossing_s) add(format(t));
  for (double t : r.probability_crossing_s) add(format(t));
  for (double t : r.nominal_risk_crossing_s) add(format(t));
  if (!r.pwave_crossing_s.empty()) {
    add(format(r.p_pick_s));
    add(format(r.strong_motion_s));
    add(format(r.pwave_trigger_s));
  }
  for (double t : r.pwave_crossing_s) add(format(t));
  if (r.regional) {
    const EvalRun::Regional& g = *r.regional;
    for (double v : {g.magnitude, g.rhyp_km, g.origin_s, g.alert_s, g.s_arrival_s, g.pga_g,
                     g.sigma_ln, g.probability}) {
      add(format(v));
    }
  }
  if (r.faults) {
    const EvalRun::Faults& f = *r.faults;
    add(csv_field(f.fault));
    add(csv_field(f.param));
    add(csv_field(f.at));
    add(f.began_s ? format(*f.began_s) : "");
    add(format(f.first_trouble_s));
    add(f.trouble_at_end ? "1" : "0");
    add(format(f.first_statue_fault_s));
    add(format(f.first_statue_unexplained_s));
    add(csv_field(f.level_at_end));
    add(monitor::alarm_cause_name(f.trouble_at_end_cause));
    add(f.collapses_only ? "collapses" : "all");
  }
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
  const bool has_model_valid =
      f.size() > kFixedColumns.size() && f[kFixedColumns.size()] == kModelValidColumn;
  const std::size_t first_extra = kFixedColumns.size() + (has_model_valid ? 1 : 0);
  table.has_grid = f.size() >= first_extra + kGridColumns.size() &&
                   std::equal(kGridColumns.begin(), kGridColumns.end(),
                              f.begin() + static_cast<std::ptrdiff_t>(first_extra));
  const std::size_t first_grid = first_extra + (table.has_grid ? kGridColumns.size() : 0);
  bool pwave_block = false;  // p_pick_s, strong_motion_s, pwave_trigger_s, then pwave_ge_
  // The fault block, when present, ends the header; the regional columns, when present, come
  // before it.
  std::size_t header_end = f.size();
  const auto ends_with = [&](std::span<const std::string_view> block) {
    return header_end >= first_grid + block.size() &&
           std::equal(block.begin(), block.end(),
                      f.begin() + static_cast<std::ptrdiff_t>(header_end - block.size()));
  };
  if (ends_with(kFaultColumns)) {
    table.has_faults = true;
    header_end -= kFaultColumns.size();
  }
  if (ends_with(kRegionalColumns)) {
    table.grids.regional = true;
    header_end -= kRegionalColumns.size();
  }
  for (std::size_t i = first_grid; i < header_end; ++i) {
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
    for (std::size_t i = 0; i < monitor::kRiskLevels.size(); ++i) {
      r.first_shown_s[i] = parse_time(f[7 + i], where, kFixedColumns[7 + i]);
    }
    std::size_t c = kFixedColumns.size();
    if (has_model_valid) {
      r.model_valid_until_s = parse_time(f[c++], where, kModelValidColumn);
      if (r.outside_model() && r.collapsed) {
        throw InputError(where + ": model_valid_until_s: a run that left the model has no collapse");
      }
    }
    if (table.has_grid) {
      const double seed = parse_number(f[c], where, "seed");
      if (seed < 0.0 || seed != std::floor(seed) || seed > 4294967295.0) {
        throw InputError(where + ": seed: expected a whole number from 0 to 4294967295, got " +
                         f[c]);
      }
      r.seed = static_cast<std::uint32_t>(seed);
      r.grid.from_g = parse_number(f[c + 1], where, "pga_from_g");
      r.grid.to_g = parse_number(f[c + 2], where, "pga_to_g");
      const double steps = parse_number(f[c + 3], where, "pga_steps");
      if (!(r.grid.from_g > 0.0) || !(r.grid.to_g >= r.grid.from_g)) {
        throw InputError(where + ": pga_from_g, pga_to_g: expected 0 < from <= to, got " +
                         f[c + 1] + ", " + f[c + 2]);
      }
      if (steps < 1.0 || steps != std::floor(steps) || steps > kMaxGridSteps ||
          (steps > 1.0 && !(r.grid.to_g > r.grid.from_g))) {
        throw InputError(where + ": pga_steps: expected a whole number from 1 to " +
                         std::to_string(kMaxGridSteps) + " (1 when from = to), got " + f[c + 3]);
      }
      r.grid.steps = static_cast<int>(steps);
      c += kGridColumns.size();
    }
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
    if (table.grids.regional) r.regional = parse_regional(f, c, where);
    c += table.grids.regional ? kRegionalColumns.size() : 0;
    if (table.has_faults) {
      r.faults = parse_faults(f, c, where);
      if (table.runs.empty()) table.collapses_only = r.faults->collapses_only;
      if (r.faults->collapses_only != table.collapses_only) {
        throw InputError(where + ": runs_written: \"" + f[c + kFaultColumns.size() - 1] +
                         "\" where the rows above say \"" +
                         (table.collapses_only ? "collapses" : "all") + "\"");
      }
      if (table.collapses_only && !r.collapsed) {
        throw InputError(where + ": runs_written \"collapses\", but this run did not collapse");
      }
    }
    table.runs.push_back(std::move(r));
  }
  // A file of collapses alone has, by design, no rows of the runs that stood.
  if (table.has_grid && !table.collapses_only) assign_case_collapses(table.runs, path);
  return table;
}

}  // namespace plinth::host

#include "eval_regional_report.h"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <set>
#include <string>

#include "eval_warning_report.h"
#include "plinth/host/input_error.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/alarm_policy.h"

namespace plinth::sim {

namespace {

using host::EvalRun;
using host::EvalTable;

constexpr std::array<const char*, kRegionalClasses> kClassNames{"Rhyp < 25 km (near the source)",
                                                                "Rhyp 25-50 km", "Rhyp >= 50 km"};

RegionalThresholdRow score(const std::vector<EvalRun>& runs, double p) {
  RegionalThresholdRow row;
  row.threshold = p;
  const auto first = [p](const EvalRun& r) { return regional_warning_time(r, p); };
  row.all = host::outcome_of(runs, first);
  std::array<std::vector<EvalRun>, kRegionalClasses> in_class;
  for (const EvalRun& r : runs) in_class[regional_class(r.regional->rhyp_km)].push_back(r);
  for (std::size_t c = 0; c < kRegionalClasses; ++c) {
    row.by_class[c] = host::outcome_of(in_class[c], first);
  }
  return row;
}

// The longest median lead over all collapses within the unneeded allowance (ties: the higher
// threshold). The index into `with`, -1 when none qualifies.
int choose(const RegionalReport& r) {
  return choose_threshold(r.with, r.without.all.unneeded_rate(), kRegionalUnneededAllowance,
                          [](const RegionalThresholdRow& w) { return median_lead(w.all); });
}

RegionalReport score_table(const EvalTable& table, const char* which) {
  if (!table.grids.regional) {
    throw host::InputError(std::string(which) +
                           " has no regional columns (plinth-eval run --regional on)");
  }
  if (!table.has_grid) {
    throw host::InputError(std::string(which) +
                           " has no PGA grid columns: the collapse margins "
                           "are not known (run it again with this plinth-eval)");
  }
  RegionalReport r;
  r.runs = table.runs.size();
  std::set<std::string> seen;
  for (const EvalRun& run : table.runs) {
    const EvalRun::Regional& g = *run.regional;
    RegionalClassCounts& c = r.counts[regional_class(g.rhyp_km)];
    for (RegionalClassCounts* k : {&c, &r.total}) {
      if (seen.count(run.record) == 0) ++k->records;
      ++k->runs;
      k->blind += g.alert_s >= g.s_arrival_s ? 1 : 0;
      k->before_record += g.alert_s < 0.0 ? 1 : 0;
    }
    seen.insert(run.record);
  }
  r.without = score(table.runs, -1.0);
  for (const double p : kRegionalThresholds) r.with.push_back(score(table.runs, p));
  const monitor::AlarmPolicySettings policy;
  if (const auto* box = monitor::built_part<monitor::RiskThresholds>(policy.warning_regional)) {
    r.box_default = score(table.runs, static_cast<double>(box->on));
  }
  return r;
}

}  // namespace

std::size_t regional_class(double rhyp_km) {
  std::size_t c = 0;
  while (c < kRegionalClassFloorsKm.size() && rhyp_km >= kRegionalClassFloorsKm[c]) ++c;
  return c;
}

double regional_warning_time(const EvalRun& r, double p) {
  const double box = r.first_shown_s[monitor::risk_level_index(monitor::AlarmLevel::kWarning)];
  if (p < 0.0 || !r.regional || !(r.regional->probability >= p)) return box;
  const double alert = std::max(0.0, r.regional->alert_s);
  return box < 0.0 ? alert : std::min(box, alert);
}

RegionalReport make_regional_report(const EvalTable& table, const EvalTable* calibrate_on) {
  RegionalReport r = score_table(table, "the runs file");
  std::optional<RegionalReport> calibration;
  if (calibrate_on != nullptr) {
    calibration = score_table(*calibrate_on, "the calibration file (--regional-calibrate-on)");
  }
  set_chosen_threshold(r, calibration ? &*calibration : nullptr, choose);
  return r;
}

std::string regional_report_text(const RegionalReport& r) {
  std::string out = "Regional alerts (warning; simulated, docs/regional.md)\n";
  out += report_line(
      "  %zu runs of %d records; alerts in the blind zone (at or after the S arrival): "
      "%d (%.1f %%); before the record's first sample (counted at 0 s): %d",
      r.runs, r.total.records, r.total.blind,
      r.total.runs ? 100.0 * r.total.blind / r.total.runs : 0.0, r.total.before_record);
  const auto table = [&](const char* title, const RegionalThresholdRow& with) {
    out += std::string("  ") + title + "\n";
    out +=
        "    class                          records  collapses  median lead without / with "
        "(gain)   p10 without / with   unneeded without / with   missed   blind zone\n";
    const auto row = [&](const char* name, int records, const host::WarningOutcome& a,
                         const host::WarningOutcome& b, const RegionalClassCounts& k) {
      out += report_line(
          "    %-31s %7d  %9d  %5.2f / %5.2f s (%+5.2f)     %5.2f / %5.2f s      %5.1f / "
          "%5.1f %%        %d / %d    %5.1f %%",
          name, records, a.collapses, median_lead(a), median_lead(b),
          median_lead(b) - median_lead(a), std::max(0.0, a.lead_quantile(0.1)),
          std::max(0.0, b.lead_quantile(0.1)), 100.0 * a.unneeded_rate(), 100.0 * b.unneeded_rate(),
          a.misses, b.misses, k.runs ? 100.0 * k.blind / k.runs : 0.0);
    };
    for (std::size_t c = 0; c < kRegionalClasses; ++c) {
      row(kClassNames[c], r.counts[c].records, r.without.by_class[c], with.by_class[c],
          r.counts[c]);
    }
    row("all", r.total.records, r.without.all, with.all, r.total);
  };
  if (r.chosen) {
    const std::string title = report_line(
        "with the alert at p >= %g (chosen %s: the longest median lead, unneeded at most %g "
        "points more):",
        r.chosen->threshold, r.chosen_elsewhere ? "on the calibration file" : "on this file",
        100.0 * kRegionalUnneededAllowance);
    table(title.substr(0, title.size() - 1).c_str(), *r.chosen);
  } else {
    out +=
        report_line("  no threshold keeps the unneeded warnings within %g points of the box's (%s)",
                    100.0 * kRegionalUnneededAllowance,
                    r.chosen_elsewhere ? "on the calibration file" : "on this file");
  }
  if (r.box_default) {
    const std::string title = report_line(
        "with the alert at the box's default, p >= %g (alarm_policy.warning_regional.on):",
        r.box_default->threshold);
    table(title.substr(0, title.size() - 1).c_str(), *r.box_default);
  }
  out += "  every threshold: p, median lead (s) all";
  for (const char* name : kClassNames) out += std::string(" / ") + name;
  out += ", unneeded (%), missed\n";
  const auto threshold_line = [&](const std::string& key, const RegionalThresholdRow& w) {
    std::string s = "    " + key;
    s.resize(13, ' ');
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%5.2f", median_lead(w.all));
    s += buffer;
    for (const host::WarningOutcome& o : w.by_class) {
      std::snprintf(buffer, sizeof buffer, " / %5.2f", median_lead(o));
      s += buffer;
    }
    std::snprintf(buffer, sizeof buffer, "  %5.1f  %d\n", 100.0 * w.all.unneeded_rate(),
                  w.all.misses);
    return s + buffer;
  };
  out += threshold_line("without", r.without);
  for (const RegionalThresholdRow& w : r.with) {
    char key[16];
    std::snprintf(key, sizeof key, "%g", w.threshold);
    out += threshold_line(key, w);
  }
  return out;
}

}  // namespace plinth::sim

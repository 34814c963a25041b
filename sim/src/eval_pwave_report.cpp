#include "eval_pwave_report.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

#include "plinth/host/input_error.h"

namespace plinth::eval {

namespace {

using host::EvalRun;
using host::EvalTable;

// A warning in a run that stood is unneeded from this collapse margin on (the margin branch's
// host::kUnneededMargin, FEMA P-695's collapse margin ratio on the PGA grid).
constexpr double kUnneededMargin = 2.0;

constexpr std::array<const char*, kPWaveClasses> kClassNames{
    "P >= 3 s before the strong motion", "P < 3 s before it (near the source)",
    "no P before it (begins in the strong motion)"};

PWaveClass class_of(const EvalRun& r) {
  if (r.p_pick_s < 0.0) return PWaveClass::kNoPWave;
  const double lead = r.strong_motion_s - r.p_pick_s;
  if (lead >= 3.0) return PWaveClass::kLeadAtLeast3s;
  return lead > 0.0 ? PWaveClass::kLeadBelow3s : PWaveClass::kNoPWave;
}

// Each run's collapse margin: its case's lowest collapsing PGA over its own PGA; for a case that
// never collapsed, the case's highest PGA over its own (a lower bound: the grid's top).
std::vector<double> collapse_margins(const std::vector<EvalRun>& runs) {
  std::map<std::tuple<std::string, std::string, int>, std::pair<double, double>> cases;
  for (const EvalRun& r : runs) {
    auto& [lowest_collapse, highest] =
        cases.try_emplace({r.record, r.scene, r.statue}, -1.0, 0.0).first->second;
    highest = std::max(highest, r.scale_g);
    if (r.collapsed && (lowest_collapse < 0.0 || r.scale_g < lowest_collapse)) {
      lowest_collapse = r.scale_g;
    }
  }
  std::vector<double> margins;
  for (const EvalRun& r : runs) {
    const auto& [lowest_collapse, highest] = cases.at({r.record, r.scene, r.statue});
    margins.push_back((lowest_collapse > 0.0 ? lowest_collapse : highest) / r.scale_g);
  }
  return margins;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(pos));
  const double f = pos - static_cast<double>(i);
  return i + 1 < v.size() ? v[i] * (1.0 - f) + v[i + 1] * f : v[i];
}

// The warning's first time with the stage at grid index `p` (-1: without the stage).
double warning_time(const EvalRun& r, int p) {
  const double box = r.first_shown_s[static_cast<std::size_t>(host::EvalLevel::kWarning)];
  if (p < 0) return box;
  const double stage = r.pwave_crossing_s[static_cast<std::size_t>(p)];
  if (stage < 0.0) return box;
  return box < 0.0 ? stage : std::min(box, stage);
}

PWaveThresholdRow score(const std::vector<EvalRun>& runs, const std::vector<double>& margins,
                        int p, double threshold) {
  PWaveThresholdRow row;
  row.threshold = threshold;
  std::vector<double> leads_all;
  std::array<std::vector<double>, kPWaveClasses> leads;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const EvalRun& r = runs[i];
    const double t = warning_time(r, p);
    const auto c = static_cast<std::size_t>(class_of(r));
    PWaveOutcome* outcomes[] = {&row.all, &row.by_class[c]};
    if (r.collapsed) {
      const bool hit = t >= 0.0 && t < r.collapse_time_s;
      const double lead = hit ? r.collapse_time_s - t : 0.0;
      leads_all.push_back(lead);
      leads[c].push_back(lead);
      for (PWaveOutcome* o : outcomes) {
        ++o->collapses;
        o->missed += hit ? 0 : 1;
      }
    } else if (margins[i] >= kUnneededMargin) {
      for (PWaveOutcome* o : outcomes) {
        ++o->unneeded_runs;
        o->unneeded_warnings += t >= 0.0 ? 1 : 0;
      }
    }
  }
  row.all.median_lead_s = quantile(leads_all, 0.5);
  row.all.p10_lead_s = quantile(leads_all, 0.1);
  for (std::size_t c = 0; c < kPWaveClasses; ++c) {
    row.by_class[c].median_lead_s = quantile(leads[c], 0.5);
    row.by_class[c].p10_lead_s = quantile(leads[c], 0.1);
  }
  return row;
}

// The longest median lead over P >= 3 s collapses within the unneeded allowance; ties: the
// higher threshold (fewer warnings). Returns the grid index, -1 when none qualifies.
int choose(const PWaveReport& r) {
  int best = -1;
  for (std::size_t i = 0; i < r.with.size(); ++i) {
    const PWaveThresholdRow& w = r.with[i];
    if (w.all.unneeded_rate() > r.without.all.unneeded_rate() + kPWaveUnneededAllowance + 1e-12) {
      continue;
    }
    const double lead = w.by_class[0].median_lead_s;
    if (best < 0 || lead > r.with[static_cast<std::size_t>(best)].by_class[0].median_lead_s + 1e-12 ||
        (std::fabs(lead - r.with[static_cast<std::size_t>(best)].by_class[0].median_lead_s) <=
             1e-12 &&
         w.threshold > r.with[static_cast<std::size_t>(best)].threshold)) {
      best = static_cast<int>(i);
    }
  }
  return best;
}

PWaveReport score_table(const EvalTable& table) {
  if (table.grids.pwave.empty()) {
    throw host::InputError("the runs file has no P-wave columns (plinth-eval run --pwave on)");
  }
  PWaveReport r;
  r.runs = table.runs.size();
  const std::vector<double> margins = collapse_margins(table.runs);
  std::set<std::string> seen;
  for (const EvalRun& run : table.runs) {
    if (seen.insert(run.record).second) ++r.records_by_class[static_cast<std::size_t>(class_of(run))];
    if (run.pwave_trigger_s >= 0.0) {
      ++r.triggered_runs;
      if (run.pwave_trigger_s < run.strong_motion_s) ++r.triggered_before_strong;
    }
  }
  r.without = score(table.runs, margins, -1, -1.0);
  for (std::size_t p = 0; p < table.grids.pwave.size(); ++p) {
    r.with.push_back(score(table.runs, margins, static_cast<int>(p), table.grids.pwave[p]));
  }
  return r;
}

__attribute__((format(printf, 1, 2))) std::string text(const char* format, ...) {
  char buffer[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof buffer, format, args);
  va_end(args);
  return buffer;
}

std::string outcome_text(const PWaveOutcome& o) {
  return text("%4d collapses, %3d missed, lead median %5.2f s, p10 %5.2f s; unneeded %5.1f %% "
              "(%d of %d)",
              o.collapses, o.missed, o.median_lead_s, o.p10_lead_s, 100.0 * o.unneeded_rate(),
              o.unneeded_warnings, o.unneeded_runs);
}

}  // namespace

PWaveReport make_pwave_report(const EvalTable& table, const EvalTable* calibrate_on) {
  PWaveReport r = score_table(table);
  if (calibrate_on != nullptr) {
    if (calibrate_on->grids.pwave != table.grids.pwave) {
      throw host::InputError("the calibration file's pwave_ge_ grid differs from this file's");
    }
    const int i = choose(score_table(*calibrate_on));
    if (i >= 0) r.chosen = r.with[static_cast<std::size_t>(i)];
    r.chosen_elsewhere = true;
  } else {
    const int i = choose(r);
    if (i >= 0) r.chosen = r.with[static_cast<std::size_t>(i)];
  }
  return r;
}

std::string pwave_report_text(const PWaveReport& r) {
  std::string out = "P-wave stage (warning; docs/pwave.md)\n";
  out += text("  records: %d with the P wave >= 3 s before the strong motion, %d < 3 s, %d "
              "without a P wave before it\n",
              r.records_by_class[0], r.records_by_class[1], r.records_by_class[2]);
  out += text("  the stage triggered in %d of %zu runs, %d of them before the strong motion\n",
              r.triggered_runs, r.runs, r.triggered_before_strong);
  const auto block = [&](const char* title, const PWaveThresholdRow& row) {
    out += std::string("  ") + title + "\n";
    out += "    all records:  " + outcome_text(row.all) + "\n";
    for (std::size_t c = 0; c < kPWaveClasses; ++c) {
      out += text("    %-46s ", kClassNames[c]) + outcome_text(row.by_class[c]) + "\n";
    }
  };
  block("without the stage (the box's warning):", r.without);
  if (r.chosen) {
    const std::string title = text("with the stage at p >= %g (chosen %s: the longest median lead "
                                   "on P >= 3 s records, unneeded at most %g points more):",
                                   r.chosen->threshold,
                                   r.chosen_elsewhere ? "on the calibration file" : "on this file",
                                   100.0 * kPWaveUnneededAllowance);
    block(title.c_str(), *r.chosen);
    out += text("  gain of the median lead: %+.2f s on P >= 3 s records, %+.2f s on all; "
                "unneeded %+.1f points\n",
                r.chosen->by_class[0].median_lead_s - r.without.by_class[0].median_lead_s,
                r.chosen->all.median_lead_s - r.without.all.median_lead_s,
                100.0 * (r.chosen->all.unneeded_rate() - r.without.all.unneeded_rate()));
  } else {
    out += "  no threshold keeps the unneeded warnings within the allowance\n";
  }
  out += "  every threshold: p, median lead on P >= 3 s / all (s), unneeded (%), missed\n";
  out += text("    without  %5.2f / %5.2f  %5.1f  %d\n", r.without.by_class[0].median_lead_s,
              r.without.all.median_lead_s, 100.0 * r.without.all.unneeded_rate(),
              r.without.all.missed);
  for (const PWaveThresholdRow& w : r.with) {
    out += text("    %-7g  %5.2f / %5.2f  %5.1f  %d\n", w.threshold, w.by_class[0].median_lead_s,
                w.all.median_lead_s, 100.0 * w.all.unneeded_rate(), w.all.missed);
  }
  return out;
}

}  // namespace plinth::eval

// plinth-eval's measures (eval_metrics.h): classification of runs, leads, ROC rules,
// calibration choice, and the runs file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "plinth/host/eval_metrics.h"
#include "plinth/host/input_error.h"

namespace plinth::host {
namespace {

EvalRun collapse_at(double t, double alarm_at) {
  EvalRun r;
  r.collapsed = true;
  r.collapse_time_s = t;
  r.peak_ratio = 1.0;
  r.first_shown_s = {-1.0, -1.0, alarm_at};
  return r;
}

EvalRun standing(double peak, double alarm_at) {
  EvalRun r;
  r.peak_ratio = peak;
  r.first_shown_s = {-1.0, -1.0, alarm_at};
  return r;
}

TEST(EvalMetrics, ClassifiesHitsMissesFalseAlarmsAndNearMisses) {
  const std::vector<EvalRun> runs{
      collapse_at(10.0, 8.0),   // hit, lead 2
      collapse_at(10.0, 10.0),  // at the collapse: a miss
      collapse_at(10.0, -1.0),  // never: a miss
      collapse_at(5.0, 4.5),    // hit, lead 0.5
      standing(0.1, 3.0),       // quiet, raised: false alarm
      standing(0.49, -1.0),     // quiet, not raised
      standing(0.5, 2.0),       // past half the angle: a near miss, raised
      standing(0.9, -1.0),      // near miss, not raised
  };
  const WarningOutcome o = level_outcome(runs, monitor::AlarmLevel::kAlarm);
  EXPECT_EQ(o.collapses, 4);
  EXPECT_EQ(o.hits, 2);
  EXPECT_EQ(o.misses, 2);
  EXPECT_EQ(o.quiet_runs, 2);
  EXPECT_EQ(o.false_alarms, 1);
  EXPECT_DOUBLE_EQ(o.false_alarm_rate(), 0.5);
  EXPECT_EQ(o.near_miss_runs, 2);
  EXPECT_EQ(o.raised_on_near_misses, 1);
  // Leads, misses as 0: {0, 0, 0.5, 2}.
  EXPECT_DOUBLE_EQ(o.lead_quantile(0.5), 0.25);
  EXPECT_DOUBLE_EQ(o.lead_quantile(0.0), 0.0);
  EXPECT_DOUBLE_EQ(o.lead_quantile(1.0), 2.0);
  EXPECT_DOUBLE_EQ(level_outcome(runs, monitor::AlarmLevel::kWarning).lead_quantile(0.5), 0.0);
  EXPECT_EQ(WarningOutcome{}.lead_quantile(0.5), -1.0);
  EXPECT_EQ(WarningOutcome{}.false_alarm_rate(), 0.0);
}

TEST(EvalMetrics, ARuleIsFirstTrueAtTheEarlierCrossing) {
  EvalRun r;
  r.risk_crossing_s = {1.0, 3.0, -1.0};
  r.probability_crossing_s = {2.0, -1.0};
  EXPECT_EQ(first_time(r, {0, -1}), 1.0);
  EXPECT_EQ(first_time(r, {1, 0}), 2.0);
  EXPECT_EQ(first_time(r, {2, 1}), -1.0);
  EXPECT_EQ(first_time(r, {2, 0}), 2.0);
  EXPECT_EQ(first_time(r, {-1, -1}), -1.0);
  EXPECT_EQ(first_time(r, {7, 9}), -1.0);  // outside the grids: unused
}

// Two collapses and two quiet runs; three risk thresholds, two probability ones.
std::vector<EvalRun> roc_runs() {
  std::vector<EvalRun> runs(4);
  runs[0].collapsed = true;
  runs[0].collapse_time_s = 10.0;
  runs[0].risk_crossing_s = {5.0, 8.0, 9.5};
  runs[0].probability_crossing_s = {4.0, 7.0};
  runs[1].collapsed = true;
  runs[1].collapse_time_s = 10.0;
  runs[1].risk_crossing_s = {6.0, 9.0, -1.0};
  runs[1].probability_crossing_s = {3.0, -1.0};
  runs[2].risk_crossing_s = {2.0, -1.0, -1.0};  // quiet
  runs[2].probability_crossing_s = {-1.0, -1.0};
  runs[3].risk_crossing_s = {1.0, 1.5, -1.0};  // quiet
  runs[3].probability_crossing_s = {2.0, -1.0};
  return runs;
}

TEST(EvalMetrics, RocCoversEverySignalAloneAndEveryPair) {
  const CrossingGrids grids{{0.2, 0.5, 0.8}, {0.5, 1.0}};
  const std::vector<RocPoint> points = roc(roc_runs(), grids);
  EXPECT_EQ(points.size(), 3U + 2U + 3U * 2U);
  for (const RocPoint& p : points) {
    if (p.rule.risk_index == 2 && p.rule.probability_index == -1) {
      EXPECT_EQ(p.outcome.misses, 1);
      EXPECT_EQ(p.outcome.false_alarms, 0);
    }
    if (p.rule.risk_index == -1 && p.rule.probability_index == 0) {
      EXPECT_EQ(p.outcome.misses, 0);
      EXPECT_EQ(p.outcome.false_alarms, 1);
      EXPECT_DOUBLE_EQ(p.outcome.lead_quantile(0.5), 6.5);
    }
  }
}

TEST(EvalMetrics, ChoosesTheLongestLeadWithinTheTarget) {
  const CrossingGrids grids{{0.2, 0.5, 0.8}, {0.5, 1.0}};
  const std::vector<RocPoint> points = roc(roc_runs(), grids);
  // Within 0 false alarms and 0 misses: nothing; the rules without a false alarm all miss one.
  // Safety first: of the rules that miss none, the fewest false alarms (one in two), then the
  // longest lead: "probability 0.5" (leads 6 and 7).
  Choice c = choose_rule(points, {0.0, 0, FalseAlarm::kPeak});
  ASSERT_TRUE(c.found);
  EXPECT_FALSE(c.meets_target);
  EXPECT_EQ(c.point.outcome.misses, 0);
  EXPECT_EQ(c.point.outcome.false_alarms, 1);
  EXPECT_DOUBLE_EQ(c.point.outcome.lead_quantile(0.5), 6.5);
  // Allowing a miss but no false alarm: the fewest misses within the rate, then the lead.
  c = choose_rule(points, {0.0, 1, FalseAlarm::kPeak});
  ASSERT_TRUE(c.meets_target);
  EXPECT_EQ(c.point.outcome.false_alarms, 0);
  EXPECT_EQ(c.point.outcome.misses, 1);
  // Allowing one false alarm in two: "probability 0.5" (leads 6 and 7) beats the others.
  c = choose_rule(points, {0.5, 0, FalseAlarm::kPeak});
  ASSERT_TRUE(c.meets_target);
  EXPECT_EQ(c.point.rule.probability_index, 0);
  EXPECT_DOUBLE_EQ(c.point.outcome.lead_quantile(0.5), 6.5);
  EXPECT_FALSE(choose_rule({}, {}).found);
}

// The frontier on the same runs: every rule that misses nothing raises one false alarm in two, and
// "probability 0.5" leads longest (6 and 7 s); the rules without a false alarm all miss one,
// "probability 1.0" the longest lead of those (3 s and a miss: median 1.5).
TEST(EvalMetrics, FrontierIsTheFewestFalseAlarmsEachConstraintAllows) {
  const CrossingGrids grids{{0.2, 0.5, 0.8}, {0.5, 1.0}};
  const std::vector<FrontierRow> rows = frontier(roc(roc_runs(), grids), FalseAlarm::kPeak);
  ASSERT_EQ(rows.size(), 7U);
  for (std::size_t i = 0; i < 4; ++i) {  // the "no miss" constraints: all met by one rule
    SCOPED_TRACE(rows[i].constraint);
    ASSERT_TRUE(rows[i].found);
    EXPECT_EQ(rows[i].point.rule.risk_index, -1);
    EXPECT_EQ(rows[i].point.rule.probability_index, 0);
    EXPECT_DOUBLE_EQ(rows[i].point.outcome.false_alarm_rate(), 0.5);
  }
  for (std::size_t i = 4; i < 6; ++i) {  // within 5 %, and the fewest false alarms
    SCOPED_TRACE(rows[i].constraint);
    ASSERT_TRUE(rows[i].found);
    EXPECT_EQ(rows[i].point.outcome.false_alarms, 0);
    EXPECT_EQ(rows[i].point.outcome.misses, 1);
    EXPECT_DOUBLE_EQ(rows[i].point.outcome.lead_quantile(0.5), 1.5);
  }
  // The risk alone at 0.2 and 0.5: nothing within 5 %, nothing with a 3 s median but 0.2's.
  const std::vector<FrontierRow> risk_only =
      frontier(roc(roc_runs(), {{0.2, 0.5}, {}}), FalseAlarm::kPeak);
  EXPECT_FALSE(risk_only[4].found);
  ASSERT_TRUE(risk_only[3].found);
  EXPECT_EQ(risk_only[3].point.rule.risk_index, 0);
  EXPECT_TRUE(frontier({})[0].constraint[0] != '\0');
  EXPECT_FALSE(frontier({})[0].found);
  EXPECT_FALSE(rows[6].found);  // every rule that misses nothing: 50 % false alarms
}

// Issue 24's row: of the rules that miss nothing within 9 % false alarms, the longest lead. Two
// collapses at 10 s, the risk reached at 8 s, the probability at 5 s; 20 quiet runs, the
// probability reached in `probability_false` of them, the risk in none.
TEST(EvalMetrics, FrontierGivesTheLongestLeadWithinNinePercent) {
  const auto runs = [](int probability_false) {
    std::vector<EvalRun> r(22);
    for (int i = 0; i < 2; ++i) {
      r[static_cast<std::size_t>(i)].collapsed = true;
      r[static_cast<std::size_t>(i)].collapse_time_s = 10.0;
      r[static_cast<std::size_t>(i)].risk_crossing_s = {8.0};
      r[static_cast<std::size_t>(i)].probability_crossing_s = {5.0};
    }
    for (std::size_t i = 2; i < r.size(); ++i) {
      r[i].peak_ratio = 0.1;
      r[i].risk_crossing_s = {-1.0};
      r[i].probability_crossing_s = {i < 2U + static_cast<std::size_t>(probability_false) ? 3.0
                                                                                         : -1.0};
    }
    return r;
  };
  const CrossingGrids grids{{0.5}, {0.5}};
  // 1 in 20 (5 %): the probability's 5 s lead, though the risk alone raises none.
  std::vector<FrontierRow> rows = frontier(roc(runs(1), grids), FalseAlarm::kPeak);
  ASSERT_EQ(rows.size(), 7U);
  ASSERT_TRUE(rows[6].found);
  EXPECT_EQ(rows[6].point.outcome.misses, 0);
  EXPECT_DOUBLE_EQ(rows[6].point.outcome.lead_quantile(0.5), 5.0);
  EXPECT_DOUBLE_EQ(rows[6].point.outcome.false_alarm_rate(), 0.05);
  EXPECT_EQ(rows[6].point.rule.risk_index, -1);  // the probability alone: no extra alarm
  EXPECT_DOUBLE_EQ(rows[0].point.outcome.lead_quantile(0.5), 2.0);  // "no miss": the risk
  // 2 in 20 (10 %): over the 9 %, so the risk's 2 s.
  rows = frontier(roc(runs(2), grids), FalseAlarm::kPeak);
  ASSERT_TRUE(rows[6].found);
  EXPECT_DOUBLE_EQ(rows[6].point.outcome.lead_quantile(0.5), 2.0);
  EXPECT_DOUBLE_EQ(rows[6].point.outcome.false_alarm_rate(), 0.0);
}

TEST(EvalMetrics, TheNominalSignalReadsTheNominalStatuesCrossings) {
  std::vector<EvalRun> runs = roc_runs();
  for (EvalRun& r : runs) r.nominal_risk_crossing_s = {-1.0, -1.0, -1.0};  // never reached
  runs[0].nominal_risk_crossing_s[0] = 9.0;
  EXPECT_EQ(first_time(runs[0], {0, -1, RiskSignal::kNominal}), 9.0);
  EXPECT_EQ(first_time(runs[0], {0, -1}), 5.0);
  const std::vector<RocPoint> nominal = roc(runs, {{0.2, 0.5, 0.8}, {}}, RiskSignal::kNominal);
  ASSERT_EQ(nominal.size(), 3U);
  EXPECT_EQ(nominal[0].rule.risk_signal, RiskSignal::kNominal);
  EXPECT_EQ(nominal[0].outcome.misses, 1);        // run 1 never crosses
  EXPECT_EQ(nominal[0].outcome.false_alarms, 0);
}

// One case on a grid of 0.5, 1, 1.5, 2, 2.5 g: rows from 0.5 g up to `first_collapse` (a grid
// index) or, with -1, to the top; alarms raised in the rows whose index is in `raised`.
std::vector<EvalRun> case_rows(const std::string& record, int first_collapse,
                               const std::vector<int>& raised) {
  const PgaGrid grid{0.5, 2.5, 5};
  std::vector<EvalRun> rows;
  for (int i = 0; i < grid.steps; ++i) {
    const bool alarm = std::find(raised.begin(), raised.end(), i) != raised.end();
    EvalRun r = i == first_collapse ? collapse_at(5.0, alarm ? 4.0 : -1.0)
                                    : standing(0.1, alarm ? 3.0 : -1.0);
    r.record = record;
    r.scene = "s.toml";
    r.seed = 7;
    r.grid = grid;
    r.scale_g = grid.at(i);
    rows.push_back(r);
    if (i == first_collapse) break;
  }
  return rows;
}

TEST(EvalMetrics, TheCollapseMarginIsTheCasesLowestCollapseOverTheRunsPga) {
  // Collapses at 2 g: its runs at 0.5, 1 and 1.5 g have margins 4, 2 and 1.33.
  std::vector<EvalRun> runs = case_rows("a.AT2", 3, {0, 1, 2});
  // Never collapses up to 2.5 g: margins at least 5, 2.5, 1.67, 1.25 and 1.
  for (const EvalRun& r : case_rows("b.AT2", -1, {1, 2, 4})) runs.push_back(r);
  assign_case_collapses(runs, "test");
  EXPECT_DOUBLE_EQ(runs[0].case_collapse_g, 2.0);
  EXPECT_DOUBLE_EQ(runs[0].collapse_margin(), 4.0);
  EXPECT_FALSE(runs[0].margin_is_lower_bound());
  EXPECT_DOUBLE_EQ(runs[2].collapse_margin(), 2.0 / 1.5);
  EXPECT_EQ(runs[4].case_collapse_g, -1.0);
  EXPECT_TRUE(runs[4].margin_is_lower_bound());
  EXPECT_DOUBLE_EQ(runs[4].collapse_margin(), 5.0);
  const WarningOutcome o = level_outcome(runs, monitor::AlarmLevel::kAlarm);
  const MarginBands& m = o.margins;
  // Known: 1.33 (raised) in 1.25-1.5, 2 (raised) in 2-3, 4 (raised) and >= 5 (not) in >= 3.
  EXPECT_EQ(m.known[0].runs, 0);
  EXPECT_EQ(m.known[1].runs, 1);
  EXPECT_EQ(m.known[1].alarms, 1);
  EXPECT_EQ(m.known[2].runs, 0);
  EXPECT_EQ(m.known[3].runs, 1);
  EXPECT_EQ(m.known[3].alarms, 1);
  EXPECT_EQ(m.known[4].runs, 2);
  EXPECT_EQ(m.known[4].alarms, 1);
  EXPECT_EQ(m.known[4].quiet, 2);  // both stood with a peak of 0.1
  // Bounded below only: >= 1 (raised), >= 1.25 (not), >= 1.67 (raised), >= 2.5 (raised).
  EXPECT_EQ(m.lower_bound[0].runs, 1);
  EXPECT_EQ(m.lower_bound[0].alarms, 1);
  EXPECT_EQ(m.lower_bound[1].runs, 1);
  EXPECT_EQ(m.lower_bound[1].alarms, 0);
  EXPECT_EQ(m.lower_bound[2].alarms, 1);
  EXPECT_EQ(m.lower_bound[3].runs, 1);
  EXPECT_EQ(m.lower_bound[3].alarms, 1);
  // Unneeded: margin 2, 4, >= 5, >= 2.5: 3 raised of 4. Unknown: >= 1, 1.25, 1.67: 2 of 3.
  EXPECT_EQ(o.unneeded().runs, 4);
  EXPECT_EQ(o.unneeded().alarms, 3);
  EXPECT_DOUBLE_EQ(o.false_alarm_rate(FalseAlarm::kMargin), 0.75);
  EXPECT_EQ(o.margin_unknown().runs, 3);
  EXPECT_EQ(o.margin_unknown().alarms, 2);
  // The peak counts every standing run here (peak 0.1): 6 raised of 8.
  EXPECT_DOUBLE_EQ(o.false_alarm_rate(FalseAlarm::kPeak), 6.0 / 8.0);
  EXPECT_EQ(o.collapses, 1);
  // Without the grid (a file of an earlier plinth-eval) no run has a margin.
  for (EvalRun& r : runs) r.grid = {};
  EXPECT_EQ(level_outcome(runs, monitor::AlarmLevel::kAlarm).unneeded().runs, 0);
}

TEST(EvalMetrics, TheCalibrationCountsTheFalseAlarmsItIsTold) {
  // A collapse at 2 g warned by both rules; rule 0 (risk) also raises in the run at 1.5 g
  // (quiet, margin 1.33: needed by the margin), rule 1 (probability) in the run at 0.5 g (a
  // near miss past half the angle, margin 4: unneeded).
  std::vector<EvalRun> runs = case_rows("a.AT2", 3, {});
  for (EvalRun& r : runs) {
    r.risk_crossing_s = {-1.0};
    r.probability_crossing_s = {-1.0};
  }
  runs[3].risk_crossing_s = {2.0};
  runs[3].probability_crossing_s = {2.0};
  runs[2].risk_crossing_s = {1.0};
  runs[0].probability_crossing_s = {1.0};
  runs[0].peak_ratio = 0.6;
  assign_case_collapses(runs, "test");
  const WarningOutcome never = outcome_of(runs, [](const EvalRun&) { return -1.0; });
  EXPECT_EQ(never.margins.known[4].quiet, 0);  // the run at 0.5 g rocked past half the angle
  EXPECT_EQ(never.margins.known[1].quiet, 1);
  const std::vector<RocPoint> points = roc(runs, {{0.5}, {0.5}});
  const Choice by_margin = choose_rule(points, {0.0, 0, FalseAlarm::kMargin});
  const Choice by_peak = choose_rule(points, {0.0, 0, FalseAlarm::kPeak});
  ASSERT_TRUE(by_margin.meets_target);
  ASSERT_TRUE(by_peak.meets_target);
  EXPECT_EQ(by_margin.point.rule.risk_index, 0);
  EXPECT_EQ(by_margin.point.rule.probability_index, -1);
  EXPECT_EQ(by_peak.point.rule.risk_index, -1);
  EXPECT_EQ(by_peak.point.rule.probability_index, 0);
  const FrontierRow margin_row = frontier(points, FalseAlarm::kMargin)[0];
  EXPECT_EQ(margin_row.point.rule.risk_index, 0);
  EXPECT_EQ(frontier(points, FalseAlarm::kPeak)[0].point.rule.probability_index, 0);
  FalseAlarm parsed = FalseAlarm::kMargin;
  EXPECT_TRUE(parse_false_alarm("peak", parsed));
  EXPECT_EQ(parsed, FalseAlarm::kPeak);
  EXPECT_FALSE(parse_false_alarm("quiet", parsed));
  EXPECT_STREQ(false_alarm_name(FalseAlarm::kMargin), "margin");
}

std::string case_error(std::vector<EvalRun> runs) {
  try {
    assign_case_collapses(runs, "f.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(EvalMetrics, ACasesRowsMustRunUpItsGrid) {
  std::vector<EvalRun> runs = case_rows("a.AT2", -1, {});
  EXPECT_EQ(case_error({runs[0], runs[1], runs[2], runs[3]}),
            "f.csv: case a.AT2, s.toml, statue 0, seed 7: its rows stop at 2 g without a collapse, "
            "below its grid's top 2.5 g (a file cut short, or part of a shard?)");
  EXPECT_EQ(case_error({runs[0], runs[2], runs[3], runs[4]}),
            "f.csv: case a.AT2, s.toml, statue 0, seed 7: no row at 1 g, below its rows at higher "
            "PGA (its rows run up the grid from 0.5 g)");
  EXPECT_EQ(case_error({runs[0], runs[1], runs[1], runs[2], runs[3], runs[4]}),
            "f.csv: case a.AT2, s.toml, statue 0, seed 7: two rows at 1 g (its rows run up the grid "
            "from 0.5 g)");
  std::vector<EvalRun> off = runs;
  off[2].scale_g = 1.6;
  EXPECT_EQ(case_error(off), "f.csv: case a.AT2, s.toml, statue 0, seed 7: scale_g 1.6 g is not a "
                             "point of its grid (0.5 to 2.5 g in 5 steps)");
  std::vector<EvalRun> mixed = runs;
  mixed[3].grid.to_g = 3.0;
  EXPECT_EQ(case_error(mixed), "f.csv: case a.AT2, s.toml, statue 0, seed 7: rows of two grids (0.5 "
                               "to 2.5 g in 5 steps, 0.5 to 3 g in 5 steps)");
  // Another seed is another case; rows in any order; past the first collapse (--all-scales) fine.
  std::vector<EvalRun> two = runs;
  for (EvalRun r : runs) {
    r.seed = 8;
    two.insert(two.begin(), r);
  }
  EXPECT_EQ(eval_cases(two, "f.csv").size(), 2U);
  std::vector<EvalRun> all_scales = case_rows("a.AT2", -1, {});
  all_scales[2].collapsed = true;
  all_scales[2].collapse_time_s = 5.0;
  std::reverse(all_scales.begin(), all_scales.end());
  assign_case_collapses(all_scales, "f.csv");
  EXPECT_DOUBLE_EQ(all_scales[0].case_collapse_g, 1.5);  // the 2.5 g row, standing again
  EXPECT_DOUBLE_EQ(all_scales[0].collapse_margin(), 0.6);
  EXPECT_EQ(level_outcome(all_scales, monitor::AlarmLevel::kAlarm).margins.below_one.runs, 2);
}

// The process id keeps two runs of the suite at once (ctest -j, the release and sanitize builds)
// off each other's files.
std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("plinth_eval_" + std::to_string(getpid()) + "_" + name))
      .string();
}

TEST(EvalMetrics, RunsFileRoundTrips) {
  const CrossingGrids grids{{0.2, 0.5}, {0.25}};
  EvalRun a = collapse_at(12.5, 11.25);
  a.record = "odd, \"name\".AT2";
  a.scene = "s.toml";
  a.statue = 3;
  a.scale_g = 0.4;
  a.risk_crossing_s = {10.0, -1.0};
  a.probability_crossing_s = {9.5};
  a.nominal_risk_crossing_s = {11.0, -1.0};
  EvalRun b = standing(0.125, -1.0);
  b.record = "r.AT2";
  b.scene = "t.toml";
  b.risk_crossing_s = {-1.0, -1.0};
  b.probability_crossing_s = {-1.0};
  b.nominal_risk_crossing_s = {-1.0, -1.0};
  b.model_valid_until_s = 7.25;
  const std::string path = temp_path("roundtrip.csv");
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  write_eval_csv_header(f, grids, false);
  write_eval_csv_row(f, a);
  write_eval_csv_row(f, b);
  std::fclose(f);
  const EvalTable t = read_eval_csv(path);
  EXPECT_EQ(t.grids.risk, grids.risk);
  EXPECT_EQ(t.grids.probability, grids.probability);
  ASSERT_EQ(t.runs.size(), 2U);
  EXPECT_EQ(t.runs[0].record, a.record);
  EXPECT_EQ(t.runs[0].statue, 3);
  EXPECT_DOUBLE_EQ(t.runs[0].collapse_time_s, 12.5);
  EXPECT_EQ(t.runs[0].first_shown_s, a.first_shown_s);
  EXPECT_EQ(t.runs[0].risk_crossing_s, a.risk_crossing_s);
  EXPECT_EQ(t.runs[1].probability_crossing_s, b.probability_crossing_s);
  EXPECT_EQ(t.runs[0].nominal_risk_crossing_s, a.nominal_risk_crossing_s);
  EXPECT_FALSE(t.runs[1].collapsed);
  EXPECT_FALSE(t.runs[0].outside_model());
  EXPECT_EQ(t.runs[1].model_valid_until_s, 7.25);
  EXPECT_FALSE(t.has_grid);  // runs without a grid: the header has no grid columns
  std::filesystem::remove(path);
}

TEST(EvalMetrics, RunsFileKeepsTheCaseAndItsGridAndReadsEarlierFiles) {
  const CrossingGrids grids{{0.5}, {0.25}};
  std::vector<EvalRun> runs = case_rows("r.AT2", 2, {0, 2});
  for (EvalRun& r : runs) {
    r.seed = 4000000000U;
    r.risk_crossing_s = {-1.0};
    r.probability_crossing_s = {-1.0};
    r.nominal_risk_crossing_s = {-1.0};
  }
  const std::string path = temp_path("grid.csv");
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  write_eval_csv_header(f, grids, true);
  for (const EvalRun& r : runs) write_eval_csv_row(f, r);
  std::fclose(f);
  const EvalTable t = read_eval_csv(path);
  ASSERT_TRUE(t.has_grid);
  ASSERT_EQ(t.runs.size(), 3U);
  EXPECT_EQ(t.runs[0].seed, 4000000000U);
  EXPECT_EQ(t.runs[0].grid, runs[0].grid);
  EXPECT_DOUBLE_EQ(t.runs[0].case_collapse_g, 1.5);  // set from the rows as they are read
  EXPECT_DOUBLE_EQ(t.runs[1].collapse_margin(), 1.5);
  // The same file without the four columns, as a plinth-eval before the margin wrote it.
  std::ifstream in(path);
  std::string text;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::size_t> commas;
    for (std::size_t i = 0; i < line.size(); ++i) {
      if (line[i] == ',') commas.push_back(i);
    }
    text += line.substr(0, commas[10]) + line.substr(commas[14]) + "\n";  // after model_valid_until_s
  }
  in.close();
  std::ofstream(path) << text;
  const EvalTable old = read_eval_csv(path);
  EXPECT_FALSE(old.has_grid);
  ASSERT_EQ(old.runs.size(), 3U);
  EXPECT_FALSE(old.runs[0].grid.known());
  EXPECT_EQ(old.runs[1].risk_crossing_s, runs[1].risk_crossing_s);
  std::filesystem::remove(path);
}


// The fault block (plinth-eval run --fault) ends the row, after the regional columns; it is read
// back field for field, and a file of collapses alone skips the check of its cases' rows.
TEST(EvalMetrics, RunsFileKeepsTheFaultBlock) {
  CrossingGrids grids{{0.5}, {0.25}};
  grids.regional = true;
  std::vector<EvalRun> runs = case_rows("r.AT2", 2, {0, 2});
  for (EvalRun& r : runs) {
    r.risk_crossing_s = {-1.0};
    r.probability_crossing_s = {-1.0};
    r.nominal_risk_crossing_s = {-1.0};
    r.regional = EvalRun::Regional{6.5, 30.0, -12.0, -5.0, 1.0, 0.3, 0.7, 0.25};
    EvalRun::Faults& f = r.faults.emplace();
    f.fault = "statue_stuck";
    f.at = "motion+0.5";
    f.began_s = -2.045;
    f.first_trouble_s = 3.25;
    f.trouble_at_end = true;
    f.first_statue_unexplained_s = 4.5;
    f.level_at_end = "fault";
    f.trouble_at_end_cause = monitor::AlarmCause::kStatueSensorFault;
  }
  runs[0].faults->began_s.reset();  // never began
  runs[1].faults->level_at_end = std::string(kBoxDown);
  const std::string path = temp_path("faults.csv");
  const auto write = [&](const std::vector<EvalRun>& rows) {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    write_eval_csv_header(f, grids, true, true);
    for (const EvalRun& r : rows) write_eval_csv_row(f, r);
    std::fclose(f);
  };
  write(runs);
  const EvalTable t = read_eval_csv(path);
  ASSERT_TRUE(t.has_faults);
  EXPECT_TRUE(t.grids.regional);
  EXPECT_FALSE(t.collapses_only);
  ASSERT_EQ(t.runs.size(), 3U);
  const EvalRun::Faults& f = *t.runs[2].faults;
  EXPECT_EQ(f.fault, "statue_stuck");
  EXPECT_EQ(f.param, "");
  EXPECT_EQ(f.at, "motion+0.5");
  ASSERT_TRUE(f.began_s.has_value());
  EXPECT_DOUBLE_EQ(*f.began_s, -2.045);
  EXPECT_FALSE(t.runs[0].faults->began_s.has_value());
  EXPECT_DOUBLE_EQ(f.first_trouble_s, 3.25);
  EXPECT_TRUE(f.trouble_at_end);
  EXPECT_DOUBLE_EQ(f.first_statue_fault_s, -1.0);
  EXPECT_DOUBLE_EQ(f.first_statue_unexplained_s, 4.5);
  EXPECT_EQ(f.level_at_end, "fault");
  EXPECT_EQ(t.runs[1].faults->level_at_end, kBoxDown);
  EXPECT_EQ(f.trouble_at_end_cause, monitor::AlarmCause::kStatueSensorFault);
  EXPECT_DOUBLE_EQ(t.runs[2].regional->probability, 0.25);
  // Collapses alone: the case's rows stop at its collapse without the ones below it.
  std::vector<EvalRun> collapses{runs[2]};
  collapses[0].faults->collapses_only = true;
  write(collapses);
  const EvalTable c = read_eval_csv(path);
  EXPECT_TRUE(c.collapses_only);
  ASSERT_EQ(c.runs.size(), 1U);
  // A row that did not collapse in such a file, and one that says otherwise, are refused.
  collapses = {runs[0], runs[2]};
  collapses[0].faults->collapses_only = true;
  write(collapses);
  try {
    (void)read_eval_csv(path);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":2: runs_written \"collapses\", but this run did not"),
              std::string::npos)
        << e.what();
  }
  collapses = {runs[2], runs[2]};
  collapses[0].faults->collapses_only = true;
  write(collapses);
  try {
    (void)read_eval_csv(path);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":3: runs_written: \"all\" where the rows above say"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove(path);
}


std::string error_reading(const std::string& text) {
  const std::string path = temp_path("bad.csv");
  std::ofstream(path) << text;
  try {
    (void)read_eval_csv(path);
  } catch (const InputError& e) {
    std::filesystem::remove(path);
    return e.what();
  }
  std::filesystem::remove(path);
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(EvalMetrics, RunsFileErrorsNameTheLineAndColumn) {
  const std::string header =
      "record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,first_advisory_s,"
      "first_warning_s,first_alarm_s,risk_ge_0.5,nominal_risk_ge_0.5\n";
  EXPECT_NE(error_reading("").find(":1: not a plinth-eval runs file"), std::string::npos);
  EXPECT_NE(error_reading("a,b\n").find(":1: not a plinth-eval runs file"), std::string::npos);
  EXPECT_NE(error_reading(header + "r,s,0,0.3,1,nan,1,-1,-1,-1,-1,-1\n")
                .find(":2: collapse_time_s: expected a finite number, got \"nan\""),
            std::string::npos);
  EXPECT_NE(error_reading(header + "r,s,0,0.3,1,-1,1,-1,-1,-1,-1,-1\n")
                .find(":2: collapse_time_s: must be >= 0 exactly when collapsed is 1"),
            std::string::npos);
  EXPECT_NE(error_reading(header + "r,s,0,0.3,2,-1,1,-1,-1,-1,-1,-1\n")
                .find(":2: collapsed: expected 0 or 1"),
            std::string::npos);
  EXPECT_NE(error_reading(header + "r,s,0,0.3,0,-1,1,-1,-1\n").find(":2: expected 12 fields"),
            std::string::npos);
  EXPECT_NE(error_reading(header + "r,s,0,0.3,0,-1,1,-1,-1,-1,-3,-1\n")
                .find(":2: risk crossing: expected a time >= 0 or -1"),
            std::string::npos);
  EXPECT_NE(error_reading(header + "\"r,s,0\n").find(":2: unterminated quoted field"),
            std::string::npos);
  EXPECT_NE(error_reading("record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,"
                          "first_advisory_s,first_warning_s,first_alarm_s,risk_ge_0.5\n")
                .find(":1: the nominal_risk_ge_ columns must repeat the risk_ge_ grid"),
            std::string::npos);
  const std::string grid_header =
      "record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,first_advisory_s,"
      "first_warning_s,first_alarm_s,seed,pga_from_g,pga_to_g,pga_steps,risk_ge_0.5,"
      "nominal_risk_ge_0.5\n";
  EXPECT_NE(error_reading(grid_header + "r,s,0,0.3,0,-1,0.1,-1,-1,-1,-2,0.3,0.3,1,-1,-1\n")
                .find(":2: seed: expected a whole number from 0 to 4294967295, got -2"),
            std::string::npos);
  EXPECT_NE(error_reading(grid_header + "r,s,0,0.3,0,-1,0.1,-1,-1,-1,7,0.3,0.2,1,-1,-1\n")
                .find(":2: pga_from_g, pga_to_g: expected 0 < from <= to, got 0.3, 0.2"),
            std::string::npos);
  EXPECT_NE(error_reading(grid_header + "r,s,0,0.3,0,-1,0.1,-1,-1,-1,7,0.3,0.3,2,-1,-1\n")
                .find(":2: pga_steps: expected a whole number from 1 to 1000 (1 when from = to), "
                      "got 2"),
            std::string::npos);
  EXPECT_NE(error_reading(grid_header + "r,s,0,0.3,0,-1,0.1,-1,-1,-1,7,0.3,0.6,2,-1,-1\n")
                .find("bad.csv: case r, s, statue 0, seed 7: its rows stop at 0.3 g without a "
                      "collapse"),
            std::string::npos);
  EXPECT_NE(error_reading("record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,"
                          "first_advisory_s,first_warning_s,first_alarm_s,colour\n")
                .find(":1: column 11: unknown column \"colour\""),
            std::string::npos);
  // The fault block's fields.
  const std::string fault_header =
      "record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,first_advisory_s,"
      "first_warning_s,first_alarm_s,fault,fault_param,fault_at,fault_began_s,"
      "first_fault_trouble_s,fault_trouble_at_end,first_statue_fault_s,"
      "first_statue_unexplained_s,level_at_end,trouble_at_end,runs_written\n";
  const auto refused = [&](const std::string& fields, const std::string& message) {
    EXPECT_NE(error_reading(fault_header + "r,s,0,0.3,0,-1,0.1,-1,-1,-1," + fields + "\n")
                  .find(":2: " + message),
              std::string::npos)
        << message;
  };
  refused("none,,,1,-1,0,-1,-1,normal,none,all",
          "fault none: its parameter, onset and began_s must be empty");
  refused("reset,,3,3,-1,2,-1,-1,normal,none,all",
          "fault_trouble_at_end: expected 0 or 1, got \"2\"");
  refused("reset,,3,3,-1,0,-1,-1,asleep,none,all",
          "level_at_end: expected a level or down, got \"asleep\"");
  refused("reset,,3,3,-1,0,-1,-1,down,sleepy,all",
          "trouble_at_end: expected a cause, got \"sleepy\"");
  refused("reset,,3,3,-1,0,-1,-1,down,none,some",
          "runs_written: expected all or collapses, got \"some\"");
  refused("reset,,3,x,-1,0,-1,-1,down,none,all",
          "fault_began_s: expected a finite number, got \"x\"");
}

// A run whose true statue lifted off has no truth: it counts in no outcome. A runs file
// written before the column (none left the model) still reads.
TEST(EvalMetrics, RunsOutsideTheModelCountNowhere) {
  EvalRun lifted = standing(0.3, 2.0);
  lifted.model_valid_until_s = 4.0;
  const std::vector<EvalRun> runs{collapse_at(10.0, 8.0), standing(0.1, -1.0), lifted};
  const WarningOutcome o = level_outcome(runs, monitor::AlarmLevel::kAlarm);
  EXPECT_EQ(o.collapses, 1);
  EXPECT_EQ(o.quiet_runs, 1);
  EXPECT_EQ(o.false_alarms, 0);
  EXPECT_EQ(o.near_miss_runs, 0);
  const std::string path = temp_path("old.csv");
  std::ofstream(path) << "record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,"
                         "first_advisory_s,first_warning_s,first_alarm_s,risk_ge_0.5,"
                         "nominal_risk_ge_0.5\nr,s,0,0.3,0,-1,0.2,-1,-1,-1,-1,-1\n";
  const EvalTable t = read_eval_csv(path);
  ASSERT_EQ(t.runs.size(), 1U);
  EXPECT_FALSE(t.runs[0].outside_model());
  std::filesystem::remove(path);
  EXPECT_NE(error_reading("record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,"
                          "first_advisory_s,first_warning_s,first_alarm_s,model_valid_until_s,"
                          "risk_ge_0.5,nominal_risk_ge_0.5\nr,s,0,0.3,1,3,1,-1,-1,-1,2,-1,-1\n")
                .find(":2: model_valid_until_s: a run that left the model has no collapse"),
            std::string::npos);
}

// The runs file's P-wave block: after the other grids, read back, refused when malformed.
EvalRun run_with(double p_pick, double trigger, std::vector<double> crossings) {
  EvalRun r;
  r.record = "RSN1_X-UP.AT2";
  r.scene = "s.toml";
  r.scale_g = 0.6;
  r.peak_ratio = 0.2;
  r.risk_crossing_s = {-1.0};
  r.probability_crossing_s = {-1.0};
  r.nominal_risk_crossing_s = {-1.0};
  r.p_pick_s = p_pick;
  r.strong_motion_s = 7.25;
  r.pwave_trigger_s = trigger;
  r.pwave_crossing_s = std::move(crossings);
  return r;
}

TEST(EvalPWaveColumns, RoundTripAfterTheOtherGrids) {
  CrossingGrids grids{{0.5}, {0.5}};
  grids.pwave = {0.1, 0.5};
  const std::string path = temp_path("pwave_roundtrip.csv");
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  write_eval_csv_header(f, grids, false);
  write_eval_csv_row(f, run_with(1.5, 2.25, {3.0, -1.0}));
  write_eval_csv_row(f, run_with(-1.0, -1.0, {-1.0, -1.0}));
  std::fclose(f);
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  EXPECT_NE(header.find(",nominal_risk_ge_0.5,p_pick_s,strong_motion_s,pwave_trigger_s,"
                        "pwave_ge_0.1,pwave_ge_0.5"),
            std::string::npos)
      << header;
  const EvalTable t = read_eval_csv(path);
  EXPECT_EQ(t.grids.pwave, grids.pwave);
  ASSERT_EQ(t.runs.size(), 2U);
  EXPECT_DOUBLE_EQ(t.runs[0].p_pick_s, 1.5);
  EXPECT_DOUBLE_EQ(t.runs[0].strong_motion_s, 7.25);
  EXPECT_DOUBLE_EQ(t.runs[0].pwave_trigger_s, 2.25);
  EXPECT_EQ(t.runs[0].pwave_crossing_s, (std::vector<double>{3.0, -1.0}));
  EXPECT_DOUBLE_EQ(t.runs[1].p_pick_s, -1.0);
  std::filesystem::remove(path);
}

TEST(EvalPWaveColumns, AMalformedBlockIsRefusedNamingWhy) {
  const std::string fixed =
      "record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,first_advisory_s,"
      "first_warning_s,first_alarm_s,risk_ge_0.5,nominal_risk_ge_0.5";
  EXPECT_NE(error_reading(fixed + ",p_pick_s,strong_motion_s,pwave_trigger_s\n")
                .find(":1: the P-wave columns need their pwave_ge_ columns"),
            std::string::npos);
  EXPECT_NE(error_reading(fixed + ",p_pick_s,strong_motion_s,pwave_trigger_s,pwave_ge_0.5,"
                                "risk_ge_0.7\n")
                .find(":1: column 17: after the P-wave columns only pwave_ge_ columns may come"),
            std::string::npos);
  EXPECT_NE(error_reading(fixed + ",p_pick_s,pwave_ge_0.5\n").find("unknown column \"p_pick_s\""),
            std::string::npos);
  EXPECT_NE(error_reading(fixed + ",p_pick_s,strong_motion_s,pwave_trigger_s,pwave_ge_0.5\n" +
                        "r,s,0,0.3,0,-1,0.1,-1,-1,-1,-1,-1,1,2,-3,-1\n")
                .find(":2: pwave_trigger_s: expected a time >= 0 or -1, got -3"),
            std::string::npos);
}

// The runs file's regional block: last, read back (times before the record's start kept),
// refused when a value is out of its range.
TEST(EvalRegionalColumns, RoundTripAfterThePWaveBlock) {
  CrossingGrids grids{{0.5}, {0.5}};
  grids.pwave = {0.5};
  grids.regional = true;
  const std::string path = temp_path("regional_roundtrip.csv");
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  write_eval_csv_header(f, grids, false);
  EvalRun r = run_with(1.5, 2.25, {3.0});
  r.regional = EvalRun::Regional{6.69, 42.88, -4.0, -0.5, 8.25, 0.75, 0.693147, 0.4125};
  write_eval_csv_row(f, r);
  std::fclose(f);
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  EXPECT_NE(header.find(",pwave_ge_0.5,regional_magnitude,regional_rhyp_km,regional_origin_s,"
                        "regional_alert_s,regional_s_arrival_s,regional_pga_g,regional_sigma_ln,"
                        "regional_probability"),
            std::string::npos)
      << header;
  const EvalTable t = read_eval_csv(path);
  EXPECT_TRUE(t.grids.regional);
  EXPECT_EQ(t.grids.pwave, grids.pwave);
  ASSERT_EQ(t.runs.size(), 1U);
  ASSERT_TRUE(t.runs[0].regional.has_value());
  const EvalRun::Regional& g = *t.runs[0].regional;
  EXPECT_DOUBLE_EQ(g.magnitude, 6.69);
  EXPECT_DOUBLE_EQ(g.origin_s, -4.0);
  EXPECT_DOUBLE_EQ(g.alert_s, -0.5);
  EXPECT_DOUBLE_EQ(g.probability, 0.4125);
  EXPECT_EQ(t.runs[0].pwave_crossing_s, (std::vector<double>{3.0}));
  std::filesystem::remove(path);
}

TEST(EvalRegionalColumns, OutOfRangeValuesAreRefusedNamingTheColumn) {
  const std::string header =
      "record,scene,statue,scale_g,collapsed,collapse_time_s,peak_ratio,first_advisory_s,"
      "first_warning_s,first_alarm_s,risk_ge_0.5,nominal_risk_ge_0.5,regional_magnitude,"
      "regional_rhyp_km,regional_origin_s,regional_alert_s,regional_s_arrival_s,regional_pga_g,"
      "regional_sigma_ln,regional_probability\n";
  const std::string fixed = "r,s,0,0.3,0,-1,0.1,-1,-1,-1,-1,-1,";
  const std::string good = temp_path("regional_good.csv");
  std::ofstream(good) << header + fixed + "6.7,40,-2,5,9,0.3,0.7,0.5\n";
  EXPECT_NO_THROW((void)read_eval_csv(good));
  std::filesystem::remove(good);
  EXPECT_NE(error_reading(header + fixed + "6.7,40,-2,5,9,0.3,0.7,1.5\n")
                .find(":2: regional_probability: expected a probability in [0, 1], got 1.5"),
            std::string::npos);
  EXPECT_NE(error_reading(header + fixed + "6.7,40,-2,-3,9,0.3,0.7,0.5\n")
                .find(":2: regional_alert_s: expected an alert at or after the origin"),
            std::string::npos);
  EXPECT_NE(error_reading(header + fixed + "6.7,40,-2,5,-9,0.3,0.7,0.5\n")
                .find(":2: regional_s_arrival_s: expected an S arrival at or after the origin"),
            std::string::npos);
  EXPECT_NE(error_reading(header + fixed + "6.7,0,-2,5,9,0.3,0.7,0.5\n").find("regional_rhyp_km"),
            std::string::npos);
  EXPECT_NE(error_reading(header + fixed + "6.7,40,-2,5,9,nan,0.7,0.5\n").find("regional_pga_g"),
            std::string::npos);
}

}  // namespace
}  // namespace plinth::host

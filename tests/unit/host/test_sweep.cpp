// plinth-sweep's library: first-occurrence thresholds (sweep_search.h), parameters
// (sweep_parameter.h), jobs, shards and cancellation (job_runner.h), the plans plinth-sweep runs
// and their rows (sweep_plan.h), two-parameter maps, the ground's columns.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "plinth/host/input_error.h"
#include "plinth/host/job_runner.h"
#include "plinth/host/record_io.h"
#include "plinth/host/scene_toml.h"
#include "plinth/host/sweep_plan.h"
#include "test_support.h"
#include "test_sweep_support.h"

namespace plinth::host {
namespace {

using ::testing::HasSubstr;

using testing::brienza;
using testing::input_error_text;

// The paper's isolated block with friction, base stops and a support it can leave.
SceneParams isolated_with_friction(double mu_s = 0.3) {
  SceneParams p = plinth::testing::paper_isolated();
  p.has_friction = true;
  p.friction.static_coefficient = mu_s;
  p.friction.kinetic_coefficient = 0.8 * mu_s;
  p.has_base_stops = true;
  p.base_stops.max_displacement = 0.2;
  p.base_stops.restitution = 0.7;
  p.has_support = true;
  p.support.clearance = 0.1;
  return p;
}

SweepSettings coarse() {
  SweepSettings s;
  s.scan_points = 12;
  s.pga_max_g = 2.5;
  s.tolerance_g = 0.01;
  s.dt = 1e-3;
  return s;
}

TEST(Sweep, Names) {
  const char* expected[] = {"sliding",       "rocking",        "slide_rocking", "out_of_base",
                            "base_stop_hit", "slide_stop_hit", "fell",          "overturned",
                            "lift_off"};
  ASSERT_EQ(kSweepEventNames.size(), kSweepEventCount);
  for (std::size_t i = 0; i < kSweepEventCount; ++i) {
    EXPECT_STREQ(sweep_event_name(static_cast<SweepEvent>(i)), expected[i]);
    EXPECT_EQ(static_cast<std::size_t>(kSweepEventNames.values()[i]), i);  // the CSV order
    EXPECT_EQ(parse_sweep_event(expected[i]), static_cast<SweepEvent>(i));
  }
  for (const char* name : {"mu_s", "epsilon", "lambda", "T", "xi", "u_max", "mass_ratio"}) {
    EXPECT_STREQ(sweep_parameter_name(parse_sweep_parameter(name)), name);
  }
  EXPECT_EQ(kSweepParameterNames.size(), 7u);
}

// The thresholds as a row's fields: ",<threshold in g>" per event.
std::string fields(const Thresholds& thresholds) {
  std::string text;
  for (const std::optional<double>& t : thresholds) {
    text += ',';
    text += format_result(t);
  }
  return text;
}

// Each reported threshold: the event occurs there and not one tolerance below.
Thresholds expect_thresholds_hold(const Scene& scene, std::size_t& found, std::size_t& runs,
                                  const Record& record = brienza()) {
  const SweepSettings settings = coarse();
  const auto thresholds = first_occurrence_thresholds(scene, record, settings, &runs);
  for (std::size_t e = 0; e < kSweepEventCount; ++e) {
    const auto event = static_cast<SweepEvent>(e);
    SCOPED_TRACE(sweep_event_name(event));
    if (!thresholds[e]) continue;
    ++found;
    const double thr = *thresholds[e];
    EXPECT_GT(thr, 0.0);
    EXPECT_LE(thr, settings.pga_max_g);
    EXPECT_TRUE(simulate_occurrences(scene, record, thr * scene.g, settings)[event]);
    if (thr - settings.tolerance_g > 0.0) {
      EXPECT_FALSE(simulate_occurrences(scene, record, (thr - settings.tolerance_g) * scene.g,
                                        settings)[event]);
    }
  }
  return thresholds;
}

TEST(Sweep, ThresholdsAgreeWithDirectSimulation) {
  const Scene scene = plinth::testing::make(isolated_with_friction());
  std::size_t found = 0;
  std::size_t runs = 0;
  const auto thresholds = expect_thresholds_hold(scene, found, runs);
  // Sliding, rocking and base stop impacts at least happen below 2.5 g on this scene.
  EXPECT_GE(found, 3u);
  EXPECT_GT(runs, static_cast<std::size_t>(coarse().scan_points));
  EXPECT_TRUE(thresholds[static_cast<std::size_t>(SweepEvent::kSliding)].has_value());
  EXPECT_TRUE(thresholds[static_cast<std::size_t>(SweepEvent::kBaseStopHit)].has_value());
  EXPECT_FALSE(thresholds[static_cast<std::size_t>(SweepEvent::kSlideStopHit)].has_value());
}

// Fig. 14(c)'s scene (lambda = 2, mu_s = 0.3, base stops, a support it can leave): sliding,
// slide-rocking, leaving the support and falling off, none of them monotonic in the PGA.
TEST(Sweep, ThresholdsHoldWhereBehaviourIsNotMonotonic) {
  const Scene scene = load_scene_file(std::string(PLINTH_SOURCE_DIR) +
                                      "/sim/scenes/fig14c-slide-rocking-base-stops.toml");
  std::size_t found = 0;
  std::size_t runs = 0;
  (void)expect_thresholds_hold(scene, found, runs);
  EXPECT_GE(found, 5u);
}

// Where the model ends is a threshold like the others: the paper's block on its base with
// stops under Irpinia 1980, Bagnoli 000 lifts off (a stop hit while it rocks spins it until
// h' theta'^2 beats g, Eq 12) from about 2 g; the runs there end in lift_off, not a collapse.
TEST(Sweep, LiftOffIsAThresholdWhereTheModelEnds) {
  SceneParams p = plinth::testing::paper_isolated();
  p.has_base_stops = true;
  p.base_stops = {0.2, 0.7};
  const Scene scene = plinth::testing::make(p);
  const Record bagnoli =
      read_at2(plinth::testing::kSource + "/sim/data/records/irpinia1980_bagnoli_000.AT2",
               kStandardGravity);
  std::size_t found = 0;
  std::size_t runs = 0;
  const Thresholds thresholds = expect_thresholds_hold(scene, found, runs, bagnoli);
  const std::optional<double> lift_off = thresholds[static_cast<std::size_t>(SweepEvent::kLiftOff)];
  ASSERT_TRUE(lift_off.has_value());
  EXPECT_GT(*lift_off, 1.5);
  EXPECT_LT(*lift_off, 2.5);
  const Occurrences at = simulate_occurrences(scene, bagnoli, *lift_off * scene.g, coarse());
  EXPECT_TRUE(at[SweepEvent::kLiftOff]);
  EXPECT_FALSE(at[SweepEvent::kOverturned]);  // the run ended before anything else
}

// On the ground without friction, rocking starts as soon as the scaled record reaches
// g b1 / h (towards corner 1) or -g b2 / h (corner 2): Eq 16 at one sample.
TEST(Sweep, RockingOnsetOnTheGroundMatchesEq16) {
  const Record& record = brienza();
  // epsilon = -0.3: the record's largest positive sample governs (its peak is negative), so the
  // threshold is neither b1/h nor b2/h in g; epsilon = 0.3: the peak reaches b2/h first.
  for (const double epsilon : {-0.3, 0.3}) {
    SCOPED_TRACE(epsilon);
    const Scene scene = plinth::testing::make(plinth::testing::paper_block(epsilon));
    double scale = std::numeric_limits<double>::infinity();  // smallest record scale at which some sample reaches Eq 16
    for (const double a : record.horizontal) {
      if (a > 0.0) scale = std::min(scale, scene.g * scene.b1 / scene.h / a);
      if (a < 0.0) scale = std::min(scale, scene.g * scene.b2 / scene.h / -a);
    }
    const double expected_g = scale * record.peak_horizontal() / scene.g;
    ASSERT_LT(expected_g, 1.0);
    ASSERT_GT(expected_g, 0.0);
    if (epsilon < 0.0) {
      ASSERT_GT(expected_g, scene.b1 / scene.h + 0.01);
      ASSERT_LT(expected_g, scene.b2 / scene.h - 0.01);
    }

    SweepSettings settings;
    settings.pga_max_g = 1.0;
    settings.scan_points = 10;
    settings.tolerance_g = 0.002;
    settings.dt = record.dt / 3.0;  // every sample lies on the solver's time grid
    const auto thresholds = first_occurrence_thresholds(scene, record, settings);
    const auto& rocking = thresholds[static_cast<std::size_t>(SweepEvent::kRocking)];
    ASSERT_TRUE(rocking.has_value());
    EXPECT_GE(*rocking, expected_g - 1e-9);
    EXPECT_LE(*rocking - settings.tolerance_g, expected_g + 1e-9);
    EXPECT_FALSE(thresholds[static_cast<std::size_t>(SweepEvent::kSliding)].has_value());
    EXPECT_FALSE(thresholds[static_cast<std::size_t>(SweepEvent::kBaseStopHit)].has_value());
  }
}

// The rows of a plan do not depend on the threads or the shards that run them, and each is
// the thresholds of its own scene.
TEST(Sweep, RowsDoNotDependOnJobsOrShards) {
  const SceneParams base = isolated_with_friction();
  SweepSettings settings = coarse();
  settings.scan_points = 8;
  settings.pga_max_g = 2.0;
  settings.tolerance_g = 0.02;
  const SweepPlan plan =
      plan_thresholds(base, brienza(), SweepParameter::kMuS, {"mu_s", 0.2, 0.6, 3}, settings);
  JobRun run;
  std::size_t simulations = 0;
  std::vector<std::string> one;
  ASSERT_TRUE(run_plan(plan, {0, 1, 2}, run, one, &simulations));
  EXPECT_GT(simulations, 3u * 8u);
  EXPECT_EQ(testing::run_whole_plan(plan, 2), one);

  run.jobs = 2;
  run.shard_count = 2;
  std::vector<std::string> merged;
  ASSERT_EQ(shard_indices(3, run), (std::vector<std::size_t>{0, 2}));
  ASSERT_TRUE(run_plan(plan, shard_indices(3, run), run, merged));
  EXPECT_TRUE(merged[1].empty());
  run.shard_index = 2;
  std::vector<std::string> second;
  ASSERT_EQ(shard_indices(3, run), (std::vector<std::size_t>{1}));
  ASSERT_TRUE(run_plan(plan, shard_indices(3, run), run, second));
  merged[1] = second[1];
  EXPECT_EQ(merged, one);

  const Scene scene = sweep_scene(base, SweepParameter::kMuS, 0.4);
  EXPECT_EQ(one[1], "0.4" + fields(first_occurrence_thresholds(scene, brienza(), settings)));
}

TEST(Sweep, ValuesAreEvenlySpacedAndInclusive) {
  EXPECT_THAT(sweep_values(0.1, 1.5, 1), ::testing::ElementsAre(0.1));
  const auto v = sweep_values(0.1, 1.5, 8);
  ASSERT_EQ(v.size(), 8u);
  EXPECT_EQ(v.front(), 0.1);
  EXPECT_EQ(v.back(), 1.5);
  EXPECT_NEAR(v[1] - v[0], 0.2, 1e-12);
  EXPECT_THAT(sweep_values(2.0, 2.0, 3), ::testing::ElementsAre(2.0, 2.0, 2.0));
}

// The scene of a value: the parameter set in SI, the scene's derived quantities made from it.
TEST(Sweep, SweepSceneSetsTheParameterInSI) {
  const SceneParams ground = plinth::testing::paper_block();
  const Scene mu = sweep_scene(ground, SweepParameter::kMuS, 0.5);
  EXPECT_TRUE(mu.params.has_friction);
  EXPECT_DOUBLE_EQ(mu.params.friction.static_coefficient, 0.5);
  EXPECT_DOUBLE_EQ(mu.params.friction.kinetic_coefficient, 0.4);
  const Scene eccentric = sweep_scene(ground, SweepParameter::kEpsilon, 0.2);
  EXPECT_DOUBLE_EQ(eccentric.params.block.eccentricity, 0.06);
  EXPECT_DOUBLE_EQ(eccentric.b1, 0.36);  // derived by make_scene: b1 = b + e

  const SceneParams iso = plinth::testing::paper_isolated();
  const SceneParams tall = sweep_scene(iso, SweepParameter::kLambda, 4.0).params;
  EXPECT_DOUBLE_EQ(tall.block.com_height, 1.2);
  EXPECT_DOUBLE_EQ(tall.block.mass, iso.block.mass * 4.0 / 3.0);
  EXPECT_DOUBLE_EQ(tall.block.inertia, homogeneous_rectangle_inertia(tall.block.mass, 0.3, 1.2));
  EXPECT_DOUBLE_EQ(tall.base.mass, tall.block.mass);  // the mass ratio is kept
  EXPECT_DOUBLE_EQ(sweep_scene(iso, SweepParameter::kPeriod, 3.0).params.base.period, 3.0);
  EXPECT_DOUBLE_EQ(sweep_scene(iso, SweepParameter::kXi, 0.1).params.base.damping_ratio, 0.1);
  EXPECT_DOUBLE_EQ(sweep_scene(iso, SweepParameter::kMassRatio, 0.5).params.base.mass,
                   0.5 * iso.block.mass);
  EXPECT_DOUBLE_EQ(sweep_scene(isolated_with_friction(), SweepParameter::kUMax, 0.3)
                       .params.base_stops.max_displacement,
                   0.3);
  const std::vector<Scene> scenes = sweep_scenes(iso, SweepParameter::kPeriod, {1.0, 2.0});
  ASSERT_EQ(scenes.size(), 2u);
  EXPECT_DOUBLE_EQ(scenes[1].omega, 2.0 * std::numbers::pi / 2.0);  // Eq 26
}

TEST(Sweep, BadInputsSayWhatIsWrong) {
  EXPECT_EQ(input_error_text([] { (void)parse_sweep_parameter("mu"); }),
            "--param: unknown parameter 'mu' (one of mu_s, epsilon, lambda, T, xi, u_max, "
            "mass_ratio)");
  EXPECT_THAT(input_error_text([] { (void)sweep_values(0.1, 1.0, 0); }),
              HasSubstr("--steps: must be at least 1"));
  EXPECT_THAT(input_error_text([] { (void)sweep_values(1.0, 0.1, 5); }),
              HasSubstr("--from 1 is greater than --to 0.1"));
  EXPECT_THAT(input_error_text([] { (void)sweep_values(std::numeric_limits<double>::quiet_NaN(), 1.0, 5); }), HasSubstr("--from"));

  const SceneParams ground = plinth::testing::paper_block();
  EXPECT_EQ(input_error_text([&] { (void)sweep_scene(ground, SweepParameter::kPeriod, 2.0); }),
            "--param T = 2: the scene has no [base] (a block on the ground)");
  EXPECT_THAT(input_error_text([&] { (void)sweep_scene(ground, SweepParameter::kXi, 0.1); }),
              HasSubstr("no [base]"));
  EXPECT_THAT(input_error_text([&] { (void)sweep_scene(ground, SweepParameter::kMassRatio, 1.0); }),
              HasSubstr("no [base]"));
  const SceneParams iso = plinth::testing::paper_isolated();
  EXPECT_THAT(input_error_text([&] { (void)sweep_scene(iso, SweepParameter::kUMax, 0.2); }),
              HasSubstr("--param u_max = 0.2: the scene has no [base_stops]"));
  // make_scene's refusal names the parameter, the value and the field.
  const std::string negative =
      input_error_text([&] { (void)sweep_scene(iso, SweepParameter::kMuS, -0.1); });
  EXPECT_THAT(negative, HasSubstr("--param mu_s = -0.1: friction."));
  EXPECT_THAT(input_error_text([&] { (void)sweep_scene(iso, SweepParameter::kPeriod, 0.0); }),
              HasSubstr("--param T = 0: base.period"));

  // A plan checks every value before it is returned, and a run its own arguments.
  EXPECT_THAT(input_error_text([&] {
                (void)plan_thresholds(iso, brienza(), SweepParameter::kMuS, {"mu_s", -1.0, 0.5, 2},
                                      coarse());
              }),
              HasSubstr("--param mu_s = -1"));
  const SweepPlan plan =
      plan_thresholds(iso, brienza(), SweepParameter::kMuS, {"mu_s", 0.5, 0.5, 1}, coarse());
  std::vector<std::string> rows;
  JobRun bad_shard;
  bad_shard.shard_index = 3;
  bad_shard.shard_count = 2;
  EXPECT_EQ(input_error_text([&] { (void)run_plan(plan, {0}, bad_shard, rows); }),
            "--shard: must be i/N with 1 <= i <= N, got 3/2");
  EXPECT_THAT(input_error_text([&] { (void)shard_indices(1, bad_shard); }), HasSubstr("--shard"));
  JobRun no_jobs;
  no_jobs.jobs = 0;
  EXPECT_EQ(input_error_text([&] { (void)run_plan(plan, {0}, no_jobs, rows); }),
            "--jobs: must be 1 to 256, got 0");
  // A simulation's error names the value it ran for.
  SweepSettings big_step = coarse();
  big_step.dt = 0.01;
  const SweepPlan stiff =
      plan_thresholds(iso, brienza(), SweepParameter::kPeriod, {"T", 0.01, 0.01, 1}, big_step);
  EXPECT_THAT(input_error_text([&] { (void)testing::run_whole_plan(stiff); }),
              HasSubstr("--param T = 0.01: --dt 0.01: too large for a stable integration of this "
                        "scene's base (base.period T = 0.01 s"));
  SweepSettings bad = coarse();
  bad.tolerance_g = 0.0;
  EXPECT_THAT(input_error_text([&] { validate(bad); }), HasSubstr("--tol"));
}

// The scan points skipped below quiet_pga_g are points where nothing happens: the thresholds
// are the same with and without skipping, and fewer simulations run.
TEST(Sweep, SkippingTheQuietScanChangesNothing) {
  const Scene fig14c = load_scene_file(std::string(PLINTH_SOURCE_DIR) +
                                       "/sim/scenes/fig14c-slide-rocking-base-stops.toml");
  for (const Scene& scene : {plinth::testing::make(isolated_with_friction(0.6)), fig14c}) {
    SweepSettings settings = coarse();
    std::size_t skipping = 0;
    std::size_t all = 0;
    const auto fast = first_occurrence_thresholds(scene, brienza(), settings, &skipping);
    settings.skip_quiet_scan = false;
    const auto slow = first_occurrence_thresholds(scene, brienza(), settings, &all);
    EXPECT_EQ(fast, slow);  // bit for bit
    EXPECT_LE(skipping, all);
    // Below the quiet PGA the block stays in full contact: no event at all.
    const double quiet = quiet_pga_g(scene, brienza(), settings.dt);
    ASSERT_GT(quiet, 0.0);
    const Occurrences below = simulate_occurrences(scene, brienza(), quiet * scene.g, settings);
    EXPECT_EQ(std::count(below.occurred.begin(), below.occurred.end(), true), 0);
  }
  // The paper's block on its base without friction is quiet up to well above 2 g.
  EXPECT_GT(quiet_pga_g(plinth::testing::make(plinth::testing::paper_isolated()), brienza(), 5e-4),
            2.0);
}

// Searching one event gives the threshold it has among all events (the searches are
// independent), with fewer simulations.
TEST(Sweep, OneEventAloneHasTheThresholdItHasAmongAll) {
  const Scene scene = load_scene_file(std::string(PLINTH_SOURCE_DIR) +
                                      "/sim/scenes/fig14c-slide-rocking-base-stops.toml");
  SweepSettings settings = coarse();
  std::size_t all_runs = 0;
  const auto all = first_occurrence_thresholds(scene, brienza(), settings, &all_runs);
  for (const SweepEvent event : {SweepEvent::kRocking, SweepEvent::kFell}) {
    SCOPED_TRACE(sweep_event_name(event));
    const auto e = static_cast<std::size_t>(event);
    ASSERT_TRUE(all[e].has_value());
    settings.events = EventSet{}.set(e);
    std::size_t runs = 0;
    const auto alone = first_occurrence_thresholds(scene, brienza(), settings, &runs);
    ASSERT_TRUE(alone[e].has_value());
    EXPECT_EQ(*alone[e], *all[e]);
    EXPECT_EQ(std::count_if(alone.begin(), alone.end(), [](auto& t) { return t.has_value(); }), 1);
    EXPECT_LT(runs, all_runs);
  }
}

TEST(Sweep, PossibleEventsFollowTheSceneFeatures) {
  const auto names = [](EventSet events) {
    std::string text;
    for (std::size_t e = 0; e < kSweepEventCount; ++e) {
      if (events[e])
        text += std::string(text.empty() ? "" : " ") + sweep_event_name(static_cast<SweepEvent>(e));
    }
    return text;
  };
  EXPECT_EQ(names(possible_events(plinth::testing::make(plinth::testing::paper_isolated()))),
            "rocking overturned lift_off");
  EXPECT_EQ(names(possible_events(plinth::testing::make(isolated_with_friction()))),
            "sliding rocking slide_rocking out_of_base base_stop_hit fell overturned lift_off");
  SceneParams stops = isolated_with_friction();
  stops.has_sliding_stops = true;
  EXPECT_EQ(names(possible_events(plinth::testing::make(stops))),
            "sliding rocking slide_rocking base_stop_hit slide_stop_hit overturned lift_off");
  EXPECT_EQ(parse_sweep_event("fell"), SweepEvent::kFell);
  EXPECT_THAT(input_error_text([] { (void)parse_sweep_event("toppled"); }),
              HasSubstr("--event: unknown event 'toppled' (one of sliding, rocking,"));
}

// A raised stop flag ends a search (JobCancelled) and a run (run_plan returns false, and no
// row is reported).
TEST(Sweep, AStopFlagEndsTheRunWithoutRows) {
  const Scene scene = plinth::testing::make(isolated_with_friction());
  std::atomic<bool> stop{true};
  EXPECT_THROW((void)first_occurrence_thresholds(scene, brienza(), coarse(), nullptr, &stop),
               JobCancelled);
  const SweepPlan plan = plan_thresholds(isolated_with_friction(), brienza(), SweepParameter::kMuS,
                                         {"mu_s", 0.2, 0.6, 3}, coarse());
  JobRun run;
  run.jobs = 2;
  run.stop = &stop;
  std::size_t reported = 0;
  run.on_done = [&](std::size_t) { ++reported; };
  std::vector<std::string> rows;
  EXPECT_FALSE(run_plan(plan, {0, 1, 2}, run, rows));
  EXPECT_EQ(reported, 0u);
  EXPECT_EQ(rows, std::vector<std::string>(3));
}

// A two-parameter map of one event holds, cell for cell, the thresholds of the one-parameter
// sweeps at each value of the second parameter.
TEST(Sweep, TwoParameterMapMatchesOneParameterSweeps) {
  SweepSettings settings = coarse();
  settings.pga_max_g = 4.0;
  settings.tolerance_g = 0.02;
  const SceneParams base = plinth::testing::paper_isolated();
  const GridAxis lambda{"lambda", 3.0, 5.0, 2};
  const GridAxis epsilon{"epsilon", -0.3, 0.3, 2};
  const SweepPlan map =
      plan_threshold_map(base, brienza(), SweepParameter::kLambda, lambda, SweepParameter::kEpsilon,
                         epsilon, SweepEvent::kOverturned, settings);
  EXPECT_EQ(map.header, "lambda,epsilon,overturned");
  EXPECT_EQ(map.keys, (std::vector<std::string>{"3,-0.3", "3,0.3", "5,-0.3", "5,0.3"}));
  const std::vector<std::string> cells = testing::run_whole_plan(map);
  std::size_t found = 0;
  for (std::size_t j = 0; j < 2; ++j) {
    const double eps = j == 0 ? -0.3 : 0.3;
    const std::vector<std::string> rows = testing::run_whole_plan(
        plan_thresholds(sweep_scene(base, SweepParameter::kEpsilon, eps).params, brienza(),
                        SweepParameter::kLambda, lambda, settings));
    for (std::size_t i = 0; i < 2; ++i) {
      const std::string t =  // a copy: csv_fields returns a temporary
          csv_fields(rows[i])[1 + static_cast<std::size_t>(SweepEvent::kOverturned)];
      found += t.empty() ? 0u : 1u;
      EXPECT_EQ(cells[2 * i + j], map.keys[2 * i + j] + "," + t);
    }
  }
  EXPECT_GE(found, 2u);
  EXPECT_THAT(input_error_text([&] {
                (void)plan_threshold_map(base, brienza(), SweepParameter::kLambda, lambda,
                                         SweepParameter::kLambda, lambda, SweepEvent::kFell,
                                         settings);
              }),
              HasSubstr("--param2: must differ from --param"));
  EXPECT_THAT(input_error_text([&] {
                (void)plan_threshold_map(base, brienza(), SweepParameter::kLambda, lambda,
                                         SweepParameter::kPeriod, {"T", 2.0, 1.0, 2},
                                         SweepEvent::kFell, settings);
              }),
              HasSubstr("--from2 2 is greater than --to2 1"));
}

// The CSV map of a one-parameter sweep: the header names the parameter and every event, a row
// is the value and its thresholds in g (%.6g, empty where the event does not occur).
TEST(Sweep, ThresholdPlanRowsAreTheCsvMap) {
  SweepSettings settings = coarse();
  const SweepPlan plan = plan_thresholds(isolated_with_friction(), brienza(), SweepParameter::kMuS,
                                         {"mu_s", 0.2, 0.6, 2}, settings);
  EXPECT_EQ(plan.header,
            "mu_s,sliding,rocking,slide_rocking,out_of_base,base_stop_hit,slide_stop_hit,fell,"
            "overturned,lift_off");
  EXPECT_THAT(plan.settings,
              ::testing::StartsWith("# plinth-sweep thresholds grid=mu_s:0.2:0.6:2 "));
  JobRun run;
  std::vector<std::string> rows;
  ASSERT_TRUE(run_plan(plan, {1}, run, rows));
  const Thresholds direct = first_occurrence_thresholds(
      sweep_scene(isolated_with_friction(), SweepParameter::kMuS, 0.6), brienza(), settings);
  EXPECT_EQ(rows[1], "0.6" + fields(direct));
  EXPECT_EQ(csv_fields(rows[1]).size(), 1 + kSweepEventCount);
  EXPECT_TRUE(rows[0].empty());
}

// Coarser still: the comparisons below hold at any resolution.
SweepSettings quick() {
  SweepSettings s = coarse();
  s.scan_points = 10;
  s.tolerance_g = 0.02;
  s.dt = 2e-3;
  return s;
}

SceneParams bundled(const std::string& name) {
  return load_scene_file(std::string(PLINTH_SOURCE_DIR) + "/sim/scenes/" + name).params;
}

// The block on the ground keeps the block, gravity and friction, and loses the base and
// everything on it; the paper's isolated scene's is sim/scenes/non-isolated.toml.
TEST(SweepGround, CounterpartIsTheSameBlockOnTheGround) {
  SceneParams p = isolated_with_friction(0.4);
  p.gravity = 9.81;
  p.has_sliding_stops = true;
  p.sliding_stops.restitution = 0.5;
  const SceneParams g = ground_counterpart(p);
  EXPECT_FALSE(g.has_base);
  EXPECT_FALSE(g.has_base_stops);
  EXPECT_FALSE(g.has_support);
  EXPECT_FALSE(g.has_sliding_stops);
  EXPECT_TRUE(g.has_friction);
  EXPECT_EQ(g.friction.static_coefficient, 0.4);
  EXPECT_EQ(g.friction.kinetic_coefficient, p.friction.kinetic_coefficient);
  EXPECT_EQ(g.gravity, 9.81);
  EXPECT_EQ(g.block.half_width, p.block.half_width);
  EXPECT_EQ(g.block.com_height, p.block.com_height);
  EXPECT_EQ(g.block.eccentricity, p.block.eccentricity);
  EXPECT_EQ(g.block.mass, p.block.mass);
  EXPECT_EQ(g.block.inertia, p.block.inertia);
  const EventSet events = possible_events(plinth::testing::make(g));
  EXPECT_EQ(events, EventSet{}
                        .set(static_cast<std::size_t>(SweepEvent::kSliding))
                        .set(static_cast<std::size_t>(SweepEvent::kRocking))
                        .set(static_cast<std::size_t>(SweepEvent::kSlideRocking))
                        .set(static_cast<std::size_t>(SweepEvent::kOverturned))
                        .set(static_cast<std::size_t>(SweepEvent::kLiftOff)));
  EXPECT_EQ(fingerprint(ground_counterpart(bundled("paper-isolated.toml"))),
            fingerprint(bundled("non-isolated.toml")));
  for (const char* name : {"T", "xi", "u_max", "mass_ratio"}) {
    EXPECT_TRUE(parameter_needs_base(parse_sweep_parameter(name))) << name;
  }
  for (const char* name : {"mu_s", "epsilon", "lambda"}) {
    EXPECT_FALSE(parameter_needs_base(parse_sweep_parameter(name))) << name;
  }
}

// --compare-ground: the scene's own columns are those of a run without it, and the columns
// "<event>_ground" those of a run of sim/scenes/non-isolated.toml, to the bit.
TEST(SweepGround, ColumnsEqualARunOfTheBlockOnTheGround) {
  const SweepSettings settings = quick();
  const GridAxis mu{"mu_s", 0.3, 0.6, 2};
  const SweepPlan compared = plan_thresholds(bundled("paper-isolated.toml"), brienza(),
                                             SweepParameter::kMuS, mu, settings, true);
  const SweepPlan own = plan_thresholds(bundled("paper-isolated.toml"), brienza(),
                                        SweepParameter::kMuS, mu, settings);
  const SweepPlan ground =
      plan_thresholds(bundled("non-isolated.toml"), brienza(), SweepParameter::kMuS, mu, settings);
  EXPECT_EQ(compared.settings, own.settings + " compare=ground");
  EXPECT_EQ(compared.header,
            own.header +
                ",sliding_ground,rocking_ground,slide_rocking_ground,overturned_ground,lift_off_ground");
  const std::vector<std::string> rows = testing::run_whole_plan(compared);
  const std::vector<std::string> own_rows = testing::run_whole_plan(own);
  const std::vector<std::string> ground_rows = testing::run_whole_plan(ground);
  std::size_t found = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    SCOPED_TRACE(rows[i]);
    const std::vector<std::string> f = csv_fields(rows[i]);
    const std::vector<std::string> g = csv_fields(ground_rows[i]);
    ASSERT_EQ(f.size(), 1 + kSweepEventCount + 5);
    EXPECT_EQ(rows[i].substr(0, own_rows[i].size() + 1), own_rows[i] + ",");
    std::size_t column = 1 + kSweepEventCount;
    for (const SweepEvent e : {SweepEvent::kSliding, SweepEvent::kRocking,
                               SweepEvent::kSlideRocking, SweepEvent::kOverturned,
                               SweepEvent::kLiftOff}) {
      const std::string& expected = g[1 + static_cast<std::size_t>(e)];
      EXPECT_EQ(f[column++], expected) << sweep_event_name(e);
      found += expected.empty() ? 0U : 1U;
    }
  }
  EXPECT_GE(found, 4u);  // on the ground the block slides, and rocks at 0.33 g
}

// A parameter the ground lacks (T): one ground search for the whole sweep, the same fields on
// every row, and only the ground's possible events (no friction here: rocking, overturned).
TEST(SweepGround, BaseParameterGivesOneGroundRowSearchedOnce) {
  const SweepSettings settings = quick();
  const SceneParams base = plinth::testing::paper_isolated();
  const GridAxis period{"T", 1.0, 3.0, 3};
  const SweepPlan compared =
      plan_thresholds(base, brienza(), SweepParameter::kPeriod, period, settings, true);
  const SweepPlan own = plan_thresholds(base, brienza(), SweepParameter::kPeriod, period, settings);
  EXPECT_EQ(compared.header, own.header + ",rocking_ground,overturned_ground,lift_off_ground");
  std::size_t compared_runs = 0;
  std::size_t own_runs = 0;
  JobRun run;
  run.jobs = 2;
  std::vector<std::string> rows;
  std::vector<std::string> own_rows;
  ASSERT_TRUE(run_plan(compared, {0, 1, 2}, run, rows, &compared_runs));
  ASSERT_TRUE(run_plan(own, {0, 1, 2}, run, own_rows, &own_runs));
  std::size_t ground_runs = 0;
  const auto ground = first_occurrence_thresholds(plinth::testing::make(ground_counterpart(base)),
                                                  brienza(), settings, &ground_runs);
  EXPECT_EQ(compared_runs, own_runs + ground_runs);
  const std::string fields =
      "," + format_result(ground[static_cast<std::size_t>(SweepEvent::kRocking)]) + "," +
      format_result(ground[static_cast<std::size_t>(SweepEvent::kOverturned)]) + "," +
      format_result(ground[static_cast<std::size_t>(SweepEvent::kLiftOff)]);
  EXPECT_NE(fields, ",,,");
  for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i], own_rows[i] + fields);
}

// A two-parameter map: the ground column is the map of the block on the ground.
TEST(SweepGround, TwoParameterMapHasTheGroundColumn) {
  SweepSettings settings = quick();
  settings.pga_max_g = 4.0;
  const GridAxis lambda{"lambda", 3.0, 5.0, 2};
  const GridAxis epsilon{"epsilon", -0.3, 0.3, 2};
  const SweepPlan map = plan_threshold_map(
      plinth::testing::paper_isolated(), brienza(), SweepParameter::kLambda, lambda,
      SweepParameter::kEpsilon, epsilon, SweepEvent::kOverturned, settings, true);
  EXPECT_EQ(map.header, "lambda,epsilon,overturned,overturned_ground");
  EXPECT_THAT(map.settings, ::testing::EndsWith(" event=overturned compare=ground"));
  const SweepPlan ground = plan_threshold_map(
      plinth::testing::paper_block(), brienza(), SweepParameter::kLambda, lambda,
      SweepParameter::kEpsilon, epsilon, SweepEvent::kOverturned, settings);
  const std::vector<std::string> cells = testing::run_whole_plan(map);
  const std::vector<std::string> ground_cells = testing::run_whole_plan(ground);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const std::vector<std::string> f = csv_fields(cells[i]);
    ASSERT_EQ(f.size(), 4u);
    EXPECT_FALSE(f[3].empty());
    EXPECT_EQ(map.keys[i] + "," + f[3], ground_cells[i]);
  }
}

TEST(SweepGround, RefusesWhatCannotBeCompared) {
  const SweepSettings settings = quick();
  const GridAxis mu{"mu_s", 0.3, 0.6, 2};
  EXPECT_THAT(input_error_text([&] {
                (void)plan_thresholds(plinth::testing::paper_block(), brienza(),
                                      SweepParameter::kMuS, mu, settings, true);
              }),
              HasSubstr("--compare-ground: the scene has no [base]: it is already the block on "
                        "the ground"));
  const GridAxis lambda{"lambda", 3.0, 4.0, 2};
  const GridAxis epsilon{"epsilon", 0.0, 0.2, 2};
  const auto map_of = [&](const SceneParams& base, SweepEvent event) {
    return input_error_text([&] {
      (void)plan_threshold_map(base, brienza(), SweepParameter::kLambda, lambda,
                               SweepParameter::kEpsilon, epsilon, event, settings, true);
    });
  };
  EXPECT_THAT(map_of(isolated_with_friction(), SweepEvent::kFell),
              HasSubstr("--compare-ground: the block on the ground cannot have fell (it has no "
                        "support's edge to leave)"));
  EXPECT_THAT(map_of(isolated_with_friction(), SweepEvent::kBaseStopHit),
              HasSubstr("cannot have base_stop_hit (it has no base stops)"));
  EXPECT_THAT(map_of(plinth::testing::paper_isolated(), SweepEvent::kSliding),
              HasSubstr("cannot have sliding (the scene has no [friction])"));
  EXPECT_EQ(map_of(isolated_with_friction(), SweepEvent::kSlideRocking), "(no InputError)");
}

}  // namespace
}  // namespace plinth::host

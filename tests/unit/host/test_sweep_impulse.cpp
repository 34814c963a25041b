// plinth-sweep's impulsive analyses (section 5.3.1): the impulse map against the closed forms
// (Fig. 11 kind), and the impulse curves against Eq 37 and the energy of a block on the ground
// (Fig. 7 kind).
#include "plinth/host/sweep_impulse.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "plinth/core/closed_forms.h"
#include "plinth/host/input_error.h"
#include "test_support.h"
#include "test_sweep_support.h"

namespace plinth::host {
namespace {

using ::testing::HasSubstr;

// Impulse search settings: |I| scanned up to `impulse_max` at `scan_points` points, thresholds
// bisected to `tolerance`; the solver step left at its default.
ImpulseSearchSettings search_settings(double impulse_max, int scan_points, double tolerance) {
  return {.impulse_max = impulse_max, .tolerance = tolerance, .scan_points = scan_points};
}

// The paper's isolated block (lambda = 3, xi = 0.2, T = 2 s) over mu_s from 0.05 to 0.8 and |I|
// from 0.15 to 3 times Eq 37's threshold: away from the curves (5 %) the simulated start is the
// one the closed forms predict. A slide late in the first rocking phase (theta >= alpha / 2) is
// rocking as far as Eq 41 goes: it describes the onset (docs/model.md).
TEST(SweepImpulse, MapAgreesWithTheClosedFormsAwayFromTheCurves) {
  constexpr int kMu = 9;
  constexpr int kImpulse = 9;
  int compared = 0;
  std::array<int, 4> seen{};  // points compared per simulated start
  for (const double epsilon : {0.0, -0.3}) {
    const SceneParams base = plinth::testing::paper_isolated(epsilon);
    const double i_rock = rocking_impulse_threshold(plinth::testing::make(base), Corner::kLeft);
    for (int m = 0; m < kMu; ++m) {
      const double mu_s = 0.05 + 0.75 * m / (kMu - 1);
      const Scene scene = sweep_scene(base, SweepParameter::kMuS, mu_s);
      for (int k = 0; k < kImpulse; ++k) {
        const double impulse = i_rock * (0.15 + 2.85 * k / (kImpulse - 1));
        if (near_criteria_curves(scene, impulse, 0.05)) continue;
        const SimulatedStart got = simulate_impulse_start(scene, -impulse, 1e-4);
        const ImpulseStart start =
            got.start == ImpulseStart::kSlideRocking && got.slide_angle_ratio >= 0.5
                ? ImpulseStart::kRocking
                : got.start;
        // Where the damper's jump at t = 0+ already beats static friction, the block slides
        // first whatever the criteria say (near_criteria_curves keeps 5 % from that line).
        const bool at_once = mu_s * scene.g <= 2.0 * 0.2 * scene.omega * impulse;
        const ImpulseStart expected =
            at_once ? ImpulseStart::kSliding : predicted_impulse_start(scene, impulse);
        EXPECT_EQ(impulse_start_name(start), std::string(impulse_start_name(expected)))
            << "epsilon " << epsilon << ", mu_s " << mu_s << ", |I| " << impulse << " ("
            << impulse / i_rock << " I_R)";
        ++compared;
        ++seen[static_cast<std::size_t>(start)];
      }
    }
  }
  EXPECT_GT(compared, 90);
  // Full contact, sliding and rocking are all compared (slide-rocking's band is thin).
  EXPECT_GT(seen[0], 10);
  EXPECT_GT(seen[1], 10);
  EXPECT_GT(seen[2], 10);
}

TEST(SweepImpulse, ClosedFormsOfTheCriteria) {
  const Scene scene = sweep_scene(plinth::testing::paper_isolated(), SweepParameter::kMuS, 0.2);
  const ImpulseCriteria c = impulse_criteria(scene, 2.0);
  EXPECT_DOUBLE_EQ(c.sliding_impulse, sliding_impulse_threshold(scene));
  EXPECT_DOUBLE_EQ(c.rocking_impulse, rocking_impulse_threshold(scene, Corner::kLeft));
  EXPECT_DOUBLE_EQ(c.dividing_friction, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(c.rocking_slides_below, rocking_to_sliding_friction(scene, Corner::kLeft, 2.0));
  EXPECT_EQ(predicted_impulse_start(scene, 0.5 * c.sliding_impulse), ImpulseStart::kFullContact);
  EXPECT_EQ(predicted_impulse_start(scene, 2.0 * c.sliding_impulse), ImpulseStart::kSliding);
  EXPECT_TRUE(near_criteria_curves(scene, c.sliding_impulse * 1.01, 0.05));
  EXPECT_FALSE(near_criteria_curves(scene, c.sliding_impulse * 0.5, 0.05));
}

// The plan writes one documented row per (mu_s, |I|), mu_s slowest.
TEST(SweepImpulse, MapPlanRows) {
  const SweepPlan plan = plan_impulse_map(plinth::testing::paper_isolated(), {"mu_s", 0.2, 0.6, 2},
                                          {"impulse", 0.5, 2.5, 2}, 5e-4);
  EXPECT_EQ(plan.header, "mu_s,impulse,simulated,predicted,c_s,c_r,c_sr,c_rs");
  EXPECT_EQ(plan.keys, (std::vector<std::string>{"0.2,0.5", "0.2,2.5", "0.6,0.5", "0.6,2.5"}));
  const std::vector<std::string> rows = testing::run_whole_plan(plan);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_THAT(rows[0], ::testing::StartsWith("0.2,0.5,full_contact,full_contact,0.76"));
  EXPECT_THAT(rows[1], ::testing::StartsWith("0.2,2.5,sliding,sliding,"));
  EXPECT_THAT(rows[3], ::testing::StartsWith("0.6,2.5,rocking,rocking,"));
  EXPECT_THAT(testing::input_error_text([] {
                (void)plan_impulse_map(plinth::testing::paper_block(), {"mu_s", 0.2, 0.6, 2},
                                       {"impulse", 0.5, 2.5, 2}, 5e-4);
              }),
              HasSubstr("--impulse-map: needs a scene with a [base]"));
  EXPECT_THAT(testing::input_error_text([] {
                (void)plan_impulse_map(plinth::testing::paper_isolated(), {"mu_s", 0.2, 0.6, 2},
                                       {"impulse", 0.0, 2.5, 2}, 5e-4);
              }),
              HasSubstr("--impulse-from: |I| must be greater than zero"));
}

// On the base the smallest rocking impulse is Eq 37's (within the search's tolerance); the
// overturning impulse lies above it.
TEST(SweepImpulse, CurveOnTheBaseMatchesEq37) {
  ImpulseSearchSettings settings = search_settings(6.0, 12, 2e-3);
  for (const double period : {1.0, 3.0}) {
    const Scene scene = plinth::testing::make(plinth::testing::paper_isolated(0.0, period));
    const double eq37 = rocking_impulse_threshold(scene, Corner::kLeft);
    const ImpulseThresholds found = impulse_thresholds(scene, settings);
    ASSERT_TRUE(found.rocking.has_value());
    ASSERT_TRUE(found.overturned.has_value());
    EXPECT_GE(*found.rocking, eq37 * (1.0 - 1e-4)) << "T = " << period;
    EXPECT_LE(*found.rocking, eq37 * (1.0 + 1e-4) + settings.tolerance) << "T = " << period;
    EXPECT_GT(*found.overturned, *found.rocking);
  }
}

// On the ground the block overturns when the impulse's rocking energy lifts C over corner 1,
// or, for an eccentric block, over corner 2 after the first impact.
TEST(SweepImpulse, CurveOnTheGroundMatchesTheEnergyBound) {
  ImpulseSearchSettings settings = search_settings(4.0, 8, 2e-3);
  for (const double epsilon : {0.0, 0.2, -0.2}) {
    const double lambda = epsilon == 0.0 ? 5.0 : 2.0;
    const Scene scene =
        sweep_scene(plinth::testing::paper_block(epsilon), SweepParameter::kLambda, lambda);
    const double bound = ground_overturning_impulse(scene);
    const ImpulseThresholds found = impulse_thresholds(scene, settings);
    EXPECT_EQ(found.rocking, 0.0);
    ASSERT_TRUE(found.overturned.has_value());
    EXPECT_GE(*found.overturned, bound * (1.0 - 1e-4)) << "epsilon = " << epsilon;
    EXPECT_LE(*found.overturned, bound * (1.0 + 1e-3) + settings.tolerance)
        << "epsilon = " << epsilon;
  }
  const SweepPlan plan = plan_impulse_curve(plinth::testing::paper_block(), SweepParameter::kLambda,
                                            {"lambda", 3, 3, 1}, settings);
  EXPECT_EQ(plan.header,
            "lambda,rocking,overturned,rocking_closed_form,overturned_closed_form,lift_off");
  EXPECT_THAT(testing::input_error_text([&] {
                ImpulseSearchSettings bad = settings;
                bad.impulse_max = 0.0;
                (void)impulse_thresholds(plinth::testing::make(plinth::testing::paper_block()),
                                         bad);
              }),
              HasSubstr("--impulse-max: must be greater than zero"));
}

// --compare-ground: the ground's columns are those of the impulse curve of the block on the
// ground (overturned and its energy bound), to the bit; against T, one ground search for all.
TEST(SweepImpulse, CurveComparesTheBlockOnTheGround) {
  ImpulseSearchSettings settings = search_settings(4.0, 8, 5e-3);
  settings.dt = 1e-3;
  const GridAxis lambda{"lambda", 2.0, 4.0, 2};
  const SweepPlan compared = plan_impulse_curve(plinth::testing::paper_isolated(),
                                                SweepParameter::kLambda, lambda, settings, true);
  const SweepPlan own = plan_impulse_curve(plinth::testing::paper_isolated(),
                                           SweepParameter::kLambda, lambda, settings);
  const SweepPlan ground =
      plan_impulse_curve(plinth::testing::paper_block(), SweepParameter::kLambda, lambda, settings);
  EXPECT_EQ(compared.header,
            own.header + ",overturned_ground,overturned_closed_form_ground,lift_off_ground");
  EXPECT_EQ(compared.settings, own.settings + " compare=ground");
  const std::vector<std::string> rows = testing::run_whole_plan(compared);
  const std::vector<std::string> own_rows = testing::run_whole_plan(own);
  const std::vector<std::string> ground_rows = testing::run_whole_plan(ground);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    // The ground's row: lambda, rocking (0), overturned, 0, the energy bound, lift-off.
    const std::vector<std::string> g = csv_fields(ground_rows[i]);
    ASSERT_EQ(g.size(), 6u);
    EXPECT_FALSE(g[2].empty());
    EXPECT_EQ(rows[i], own_rows[i] + "," + g[2] + "," + g[4] + "," + g[5]);
  }

  const GridAxis period{"T", 1.0, 3.0, 3};
  const SweepPlan by_period = plan_impulse_curve(plinth::testing::paper_isolated(),
                                                 SweepParameter::kPeriod, period, settings, true);
  JobRun run;
  run.jobs = 2;
  std::vector<std::string> period_rows;
  std::size_t runs = 0;
  ASSERT_TRUE(run_plan(by_period, {0, 1, 2}, run, period_rows, &runs));
  std::size_t own_runs = 0;
  std::vector<std::string> own_period_rows;
  ASSERT_TRUE(run_plan(plan_impulse_curve(plinth::testing::paper_isolated(),
                                          SweepParameter::kPeriod, period, settings),
                       {0, 1, 2}, run, own_period_rows, &own_runs));
  std::size_t ground_runs = 0;
  const Scene on_ground = plinth::testing::make(plinth::testing::paper_block());
  const ImpulseThresholds found = impulse_thresholds(on_ground, settings, &ground_runs);
  EXPECT_EQ(runs, own_runs + ground_runs);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(period_rows[i], own_period_rows[i] + "," + format_result(found.overturned) + "," +
                                  format_result(ground_overturning_impulse(on_ground)) + "," +
                                  format_result(found.lift_off));
  }
  EXPECT_THAT(testing::input_error_text([&] {
                (void)plan_impulse_curve(plinth::testing::paper_block(), SweepParameter::kLambda,
                                         lambda, settings, true);
              }),
              HasSubstr("--compare-ground: the scene has no [base]"));
}

}  // namespace
}  // namespace plinth::host

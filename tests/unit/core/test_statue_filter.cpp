// The statue sensor's filter (statue_filter.h): members weighted by the measured rotation, the
// phase from the measurement, the weighted members' risk once informative, the worst member's
// before and when no member explains the measurement.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "plinth/core/statue_filter.h"
#include "test_support.h"

namespace plinth {
namespace statue_filter_test {
namespace {

using testing::make;
using testing::paper_block;
using testing::wide_block;
using testing::ensemble_estimator_settings;
using testing::no_forecast;

constexpr double kRate = 200.0;  // ensemble_estimator_settings()'s

// 1 Hz sine of `amplitude_g`, ramped in over its first second.
GroundAcceleration shaking(int n, double amplitude_g) {
  const double t = n / kRate;
  const double ramp = std::fmin(1.0, t);
  return {static_cast<Real>(ramp * amplitude_g * kStandardGravity *
                            std::sin(2.0 * std::numbers::pi * t)),
          0.0};
}

// The box's members, the true statue (an estimator fed the same ground: its theta' is what the
// gyroscope measures, with white noise of `noise_rad_s`, a BMI088's at 200 Hz) and the filter.
struct FilterRun {
  FilterRun(std::vector<Scene> statues, const Scene& truth_scene, double noise_rad_s = 0.002,
            const StatueFilterSettings& settings = {})
      : scenes(std::move(statues)),
        truth_scene_(truth_scene),
        ensemble(std::make_unique<Ensemble>()),
        truth(std::make_unique<PlanarEstimator>()),
        noise(noise_rad_s) {
    EXPECT_TRUE(ensemble->start(scenes, ensemble_estimator_settings(), no_forecast(), {}).ok());
    ensemble->restart({});
    EXPECT_TRUE(truth->start(truth_scene_, ensemble_estimator_settings(), {}).ok());
    EXPECT_TRUE(filter
                    .start(settings, ensemble_estimator_settings(), {},
                           static_cast<int>(scenes.size()))
                    .ok());
  }
  // One sample; `measured` replaces the true statue's rate when given (not the model).
  // The box's risk without the sensor: the ensemble's worst member's.
  [[nodiscard]] Real worst_member_risk() const {
    EnsembleRisk r;
    ensemble->risk(r);
    return r.risk.total;
  }
  void push(GroundAcceleration g, const double* measured = nullptr) {
    ensemble->push(g);
    truth->push(g);
    const double rate =
        measured != nullptr ? *measured : truth->state()[kThetaDot] + noise * gauss(random);
    filter.on_sample(*ensemble, g, {static_cast<Real>(rate)});
  }
  std::vector<Scene> scenes;
  Scene truth_scene_;
  std::unique_ptr<Ensemble> ensemble;
  std::unique_ptr<PlanarEstimator> truth;
  StatueFilter filter;
  double noise;
  std::mt19937 random{24};
  std::normal_distribution<double> gauss;
};

TEST(StatueFilter, SettingsNameTheirField) {
  StatueFilterSettings s;
  EXPECT_TRUE(validate(s).ok());
  s.memory_s = 0.0;
  EXPECT_EQ(validate(s).field, std::string("statue_filter.memory_s"));
  s = {};
  s.model_tolerance = Real(3);
  EXPECT_EQ(validate(s).field, std::string("statue_filter.model_tolerance"));
  s = {};
  s.credible_weight = Real(1.5);
  EXPECT_EQ(validate(s).field, std::string("statue_filter.credible_weight"));
  s = {};
  s.ruled_out_fraction = Real(0);
  EXPECT_EQ(validate(s).field, std::string("statue_filter.ruled_out_fraction"));
  s = {};
  s.interval_s = 0.001;  // shorter than a sample at 200 Hz
  StatueFilter f;
  EXPECT_EQ(f.start(s, ensemble_estimator_settings(), {}, 2).field, std::string("statue_filter.interval_s"));
  EXPECT_EQ(f.start({}, ensemble_estimator_settings(), {}, kMaxEnsembleMembers + 1).field,
            std::string("uncertainty"));
}

// At rest under weak shaking nothing tells the members apart: uniform weights, not informative,
// explained; the risk is the worst member's.
TEST(StatueFilter, StillnessTellsNothing) {
  FilterRun run({wide_block(), make(paper_block())}, wide_block());
  for (int n = 0; n < 600; ++n) run.push(shaking(n, 0.1));
  const StatueEstimate& e = run.filter.estimate();
  EXPECT_TRUE(e.measuring);
  EXPECT_EQ(e.mode.phase, Phase::kFullContact);
  EXPECT_NEAR(e.weights[0], 0.5, 1e-3);
  EXPECT_NEAR(e.effective_members, 2.0, 1e-3);
  EXPECT_FALSE(e.informative);
  EXPECT_TRUE(e.explained);
  EXPECT_FALSE(e.weighted);
  EXPECT_GT(e.intervals, 20);
}

// The paper's block is the statue: it rocks at 0.4 g, the wide one would not. The filter finds
// it, takes the phase from the measurement and weighs the risk on it.
TEST(StatueFilter, TheRockingStatueIsTheSlenderMember) {
  FilterRun run({wide_block(), make(paper_block())}, make(paper_block()));
  bool rocked = false;
  int n = 0;
  for (; n < 2000 && !run.truth->mode().terminal(); ++n) {
    run.push(shaking(n, 0.4));
    const StatueEstimate& e = run.filter.estimate();
    if (run.truth->mode().rocking() && std::fabs(run.truth->state()[kTheta]) > 0.01) {
      rocked = true;
      ASSERT_EQ(e.mode.phase, Phase::kRocking) << n;
      ASSERT_EQ(e.mode.corner, run.truth->mode().corner) << n;
      ASSERT_NEAR(e.tilt, run.truth->state()[kTheta], 0.01) << n;
    }
  }
  ASSERT_TRUE(rocked);
  const StatueEstimate& e = run.filter.estimate();
  EXPECT_GT(e.weights[1], 0.95);
  EXPECT_TRUE(e.informative);
  EXPECT_TRUE(e.explained) << e.best_score;
  EXPECT_EQ(e.best_member, 1);
  EXPECT_TRUE(e.weighted);
  EXPECT_EQ(e.risk_member, 1);
}

// The wide block is the statue and stands; the slender member rocks in its own simulation (its
// risk is the box's without the sensor), but the measurement rules it out: the risk is the wide
// block's, at the measured (resting) state.
TEST(StatueFilter, AStandingStatueRulesTheFragileMemberOut) {
  FilterRun run({make(paper_block()), wide_block()}, wide_block());
  double worst_without_sensor = 0.0;
  for (int n = 0; n < 800; ++n) {
    run.push(shaking(n, 0.5));
    worst_without_sensor = std::fmax(worst_without_sensor, run.worst_member_risk());
  }
  ASSERT_GT(worst_without_sensor, 0.9);  // the paper's block, simulated, overturns
  const StatueEstimate& e = run.filter.estimate();
  EXPECT_EQ(e.mode.phase, Phase::kFullContact);
  EXPECT_GT(e.weights[1], 0.95);
  EXPECT_TRUE(e.informative);
  EXPECT_TRUE(e.explained) << e.best_score;
  EXPECT_TRUE(e.weighted);
  EXPECT_LT(e.risk.total, 0.05);
}

// Three members, the statue one of the two wide ones: ruling the slender one out leaves two
// equally likely, never informative. The slender member's own simulation rocks while the statue
// stands: its own theta' disagrees with the measured one at once (its own risk no longer counts)
// and the intervals of standing rule it out; the risk is the wide members', the forecast's
// probability theirs.
TEST(StatueFilter, AMemberTheStandingStatueContradictsIsLeftOut) {
  FilterRun run({wide_block(), make(paper_block()), wide_block()}, wide_block());
  double worst_without_sensor = 0.0;
  for (int n = 0; n < 800; ++n) {
    run.push(shaking(n, 0.5));
    worst_without_sensor = std::fmax(worst_without_sensor, run.worst_member_risk());
    const StatueEstimate& e = run.filter.estimate();
    if (run.ensemble->member(1).mode().rocking()) {
      ASSERT_LT(e.risk.total, 0.5) << n;  // never the rocking member's own risk
    }
  }
  ASSERT_GT(worst_without_sensor, 0.9);  // the paper's block, simulated, overturns
  const StatueEstimate& e = run.filter.estimate();
  EXPECT_FALSE(e.informative);  // two wide members remain, alike
  EXPECT_TRUE(e.explained);
  EXPECT_EQ(e.ruled_out, 1);
  EXPECT_EQ(e.ruled_out_members, 0b010U);
  EXPECT_LT(e.risk.total, 0.05);
  EXPECT_NE(e.risk_member, 1);
  ForecastOutcome f;
  f.valid = true;
  f.members = 3;
  f.collapsing = 1;
  f.probability = 1.0 / 3.0;
  f.collapsing_members = 0b010;  // the slender member's forecast collapses
  EXPECT_EQ(weighted_collapse_probability(f, e), 0.0);
}

// A member whose own theta' disagrees with the measured one is left out of the risk at once,
// before any evidence (ruling out made as hard as can be): the statue stands while the slender
// member rocks in its own simulation.
TEST(StatueFilter, AMemberWhoseOwnRateDisagreesIsLeftOutAtOnce) {
  StatueFilterSettings settings;
  settings.ruled_out_fraction = Real(1e-30);
  settings.memory_s = 1e-3;  // the evidence forgotten within an interval
  FilterRun run({wide_block(), make(paper_block()), wide_block()}, wide_block(), 0.002,
                settings);
  bool disagreed = false;
  for (int n = 0; n < 800; ++n) {
    run.push(shaking(n, 0.5));
    const StatueEstimate& e = run.filter.estimate();
    const PlanarEstimator& slender = run.ensemble->member(1);
    if (!slender.mode().rocking() || std::fabs(slender.state()[kThetaDot]) < 0.1) continue;
    disagreed = true;
    ASSERT_EQ(e.disagreeing_members, 0b010U) << n;
    ASSERT_EQ(e.ruled_out, 0) << n;
    ASSERT_NE(e.risk_member, 1) << n;
  }
  EXPECT_TRUE(disagreed);
}

// Before the measurement is informative, the risk is the worst member's (as without the sensor).
TEST(StatueFilter, BeforeInformativeTheRiskIsTheWorstMembers) {
  FilterRun run({wide_block(), make(paper_block())}, make(paper_block()));
  run.push(shaking(0, 0.4));
  const StatueEstimate& e = run.filter.estimate();
  ASSERT_FALSE(e.informative);
  EnsembleRisk r;
  run.ensemble->risk(r);
  EXPECT_EQ(e.risk.total, r.risk.total);
}

// An anchored statue (the measured rate stays 0) under shaking that rocks every member (1.2 g): no member
// explains it; the risk falls back to the worst member's, never less.
TEST(StatueFilter, AnAnchoredStatueIsExplainedByNoMember) {
  FilterRun run({wide_block(), make(paper_block())}, wide_block());
  const double still = 0.0;
  bool unexplained = false;
  for (int n = 0; n < 1000; ++n) {
    run.push(shaking(n, 1.2), &still);
    const StatueEstimate& e = run.filter.estimate();
    EnsembleRisk r;
    run.ensemble->risk(r);
    if (!e.explained) {
      unexplained = true;
      ASSERT_FALSE(e.weighted) << n;
      ASSERT_GE(e.risk.total, r.risk.total) << n;
    }
  }
  EXPECT_TRUE(unexplained);
  EXPECT_FALSE(run.filter.estimate().explained);
}

// A loose sensor: it swings (0.3 rad/s at 3 Hz) while the ground is quiet and every member sits.
TEST(StatueFilter, ALooseSensorIsExplainedByNoMember) {
  FilterRun run({wide_block(), make(paper_block())}, wide_block());
  for (int n = 0; n < 600; ++n) {
    const double swing = 0.3 * std::sin(2.0 * std::numbers::pi * 3.0 * n / kRate);
    run.push({}, &swing);
  }
  const StatueEstimate& e = run.filter.estimate();
  EXPECT_FALSE(e.explained) << e.best_score;
  EXPECT_FALSE(e.weighted);
  EXPECT_EQ(e.mode.phase, Phase::kRocking);  // what the sensor says, though no member does
  EnsembleRisk r;
  run.ensemble->risk(r);
  EXPECT_EQ(r.risk.total, 0.0);  // every member sits
  EXPECT_GT(e.risk.total, 0.0);  // the worst member's at the measured state
}

// A restart forgets: uniform weights, at rest, no innovation.
TEST(StatueFilter, AResetForgets) {
  FilterRun run({wide_block(), make(paper_block())}, make(paper_block()));
  for (int n = 0; n < 600; ++n) run.push(shaking(n, 0.4));
  ASSERT_TRUE(run.filter.estimate().informative);
  run.filter.reset();
  const StatueEstimate& e = run.filter.estimate();
  EXPECT_FALSE(e.measuring);
  EXPECT_FALSE(e.informative);
  EXPECT_EQ(e.intervals, 0);
  EXPECT_EQ(e.weights[0], Real(0.5));
  EXPECT_EQ(e.tilt, 0.0);
}

// The forecast weighted: the weight of the members that collapse.
TEST(StatueFilter, TheForecastIsWeightedOnceTheEstimateIs) {
  ForecastOutcome f;
  f.valid = true;
  f.members = 3;
  f.collapsing = 1;
  f.probability = 1.0 / 3.0;
  f.collapsing_members = 0b100;
  StatueEstimate e;
  e.weights[0] = Real(0.5);
  e.weights[1] = Real(0.3);
  e.weights[2] = Real(0.2);
  EXPECT_EQ(weighted_collapse_probability(f, e), f.probability);
  e.weighted = true;
  EXPECT_NEAR(weighted_collapse_probability(f, e), 0.2, 1e-6);
  // Not weighted: the members neither ruled out nor disagreeing, counted.
  e.weighted = false;
  e.disagreeing_members = 0b001;
  EXPECT_NEAR(weighted_collapse_probability(f, e), 0.5, 1e-12);
  e.ruled_out_members = 0b010;
  e.ruled_out = 1;
  EXPECT_NEAR(weighted_collapse_probability(f, e), 1.0, 1e-12);
  e.disagreeing_members = 0b100;
  EXPECT_EQ(weighted_collapse_probability(f, e), 0.0);
  e.disagreeing_members = 0b101;  // none left: the forecast's own
  EXPECT_EQ(weighted_collapse_probability(f, e), f.probability);
}

}  // namespace
}  // namespace statue_filter_test
}  // namespace plinth

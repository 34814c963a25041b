// The statue sensor's filter (statue_filter.h): members weighted by the measured rotation, the
// phase from the measurement, the weighted members' risk once informative, the worst member's
// before and when no member explains the measurement.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
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
using testing::paper_isolated;
using testing::wide_block;
using testing::ensemble_estimator_settings;
using testing::no_forecast;
using testing::with_friction;

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
    const double rate = measured != nullptr
                            ? *measured
                            : rate_gain * truth->state()[kThetaDot] + noise * gauss(random);
    StatueMeasurement m{static_cast<Real>(rate)};
    ground_velocity += 0.5 * (previous_ground + g.horizontal) / kRate;
    previous_ground = g.horizontal;
    const Vector2r velocity = sensor_velocity();
    if (accelerometer) {
      const double read = reads_ground   ? static_cast<double>(g.horizontal)
                          : reads_rest ? 0.0
                          : averaging  ? sample_mean_specific_force(velocity)
                                       : true_specific_force();
      m.has_acceleration = true;
      m.specific_force_m_s2 = static_cast<Real>(read + acceleration_bias +
                                                acceleration_noise * gauss(acceleration_random));
    }
    previous_velocity = velocity;
    filter.on_sample(*ensemble, g, m);
  }
  // The sensor's velocity (world frame, the ground's added; default mount, 1 m up on the axis):
  // the pivot's (the corner it rocks about; at rest any) u' + x' and theta' about it.
  [[nodiscard]] Vector2r sensor_velocity() const {
    const State& y = truth->state();
    const Real offset = truth_scene_.corner(truth->mode().corner).offset;
    const Real th = y[kTheta];
    const Vector2r r(std::cos(th) * offset - std::sin(th), std::sin(th) * offset + std::cos(th));
    return Vector2r(ground_velocity + y[kUDot] + y[kXDot] - y[kThetaDot] * r.y(),
                    y[kThetaDot] * r.x());
  }
  // A sensor whose output is its acceleration's mean over the sample (an ideal anti-alias
  // filter): the change of its velocity over the sample, an impact's jump included, plus
  // gravity, in the block's frame.
  [[nodiscard]] double sample_mean_specific_force(const Vector2r& velocity) const {
    const Vector2r a = (velocity - previous_velocity) * kRate;
    const double th = truth->state()[kTheta];
    return std::cos(th) * a.x() + std::sin(th) * (a.y() + kStandardGravity);
  }
  // What the accelerometer at the default mount (1 m up, on the axis) reads on the true statue.
  [[nodiscard]] double true_specific_force() const {
    return simulated_specific_force(truth_scene_, truth->mode(), truth->state(),
                                    truth->simulator().accelerations(), truth->ground(), {})
        .x();
  }
  std::vector<Scene> scenes;
  Scene truth_scene_;
  std::unique_ptr<Ensemble> ensemble;
  std::unique_ptr<PlanarEstimator> truth;
  StatueFilter filter;
  double noise;
  std::mt19937 random{24};
  std::normal_distribution<double> gauss;
  // The accelerometer, fed when `accelerometer`: white noise of acceleration_noise m/s2 rms
  // (the default acceleration_noise_m_s2) and a bias its offset window left.
  bool accelerometer = false;
  bool averaging = false;  // the reading is the sample's mean, not the value at its end
  bool reads_rest = false;    // the accelerometer reads a sensor at rest (gravity alone)
  bool reads_ground = false;  // it reads the ground's motion (a sensor on the plinth)
  double rate_gain = 1.0;     // the gyroscope's gain (a wrong range or unit)
  double acceleration_noise = 0.03;
  double acceleration_bias = 0.0;
  std::mt19937 acceleration_random{26};
  double ground_velocity = 0.0;  // m/s, the ground's, by the trapezoid rule
  double previous_ground = 0.0;
  Vector2r previous_velocity = Vector2r::Zero();
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

// The sliding test's settings, each named.
TEST(StatueFilter, SlideSettingsNameTheirField) {
  const auto field = [](auto change) {
    StatueFilterSettings s;
    change(s);
    return std::string(validate(s).field);
  };
  EXPECT_EQ(field([](StatueFilterSettings& s) { s.acceleration_noise_m_s2 = 0; }),
            "statue_filter.acceleration_noise_m_s2");
  EXPECT_EQ(field([](StatueFilterSettings& s) { s.acceleration_bias_m_s2 = -0.1; }),
            "statue_filter.acceleration_bias_m_s2");
  EXPECT_EQ(field([](StatueFilterSettings& s) { s.acceleration_bias_m_s2 = NAN; }),
            "statue_filter.acceleration_bias_m_s2");
  EXPECT_EQ(field([](StatueFilterSettings& s) { s.slide_tolerance = 1; }),
            "statue_filter.slide_tolerance");
  EXPECT_EQ(field([](StatueFilterSettings& s) { s.slide_filter_s = 0; }),
            "statue_filter.slide_filter_s");
  EXPECT_EQ(field([](StatueFilterSettings& s) { s.slide_onset_s = 2; }),
            "statue_filter.slide_onset_s");
  EXPECT_EQ(field([](StatueFilterSettings& s) { s.slide_end_s = -1; }),
            "statue_filter.slide_end_s");
  StatueFilterSettings s;
  s.acceleration_bias_m_s2 = 0;  // no bias left: allowed
  s.slide_tolerance = 0;
  EXPECT_TRUE(validate(s).ok());
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
  settings.informative_fraction = Real(1e-6);  // the weights never used
  FilterRun run({wide_block(), make(paper_block()), wide_block()}, wide_block(), 0.002,
                settings);
  int first_rocking = -1;
  for (int n = 0; n < 800; ++n) {
    run.push(shaking(n, 0.5));
    const StatueEstimate& e = run.filter.estimate();
    const PlanarEstimator& slender = run.ensemble->member(1);
    if (!slender.mode().rocking() || std::fabs(slender.state()[kThetaDot]) < 0.1) continue;
    if (first_rocking < 0) first_rocking = n;
    // Left out by its rate at once; later also by its evidence (ruled out).
    ASSERT_EQ((e.disagreeing_members | e.ruled_out_members) & 0b010U, 0b010U) << n;
    if (n < first_rocking + 10) {
      ASSERT_EQ(e.disagreeing_members, 0b010U) << n;  // within its first interval
      ASSERT_EQ(e.ruled_out, 0) << n;
    }
    ASSERT_NE(e.risk_member, 1) << n;
  }
  EXPECT_GE(first_rocking, 0);
}

// ---------------------------------------------------------------------------------------------
// Corroboration by the ground sensors (docs/statue-filter.md)

// The first sample at which the filter was not corroborated, and why; -1: never.
struct Refuted {
  int at = -1;
  StatueRefutation why = StatueRefutation::kNone;
};
template <typename Push>
Refuted first_refutation(FilterRun& run, int samples, Push push) {
  Refuted r;
  for (int n = 0; n < samples && !run.truth->mode().terminal(); ++n) {
    push(n);
    const StatueEstimate& e = run.filter.estimate();
    if (r.at < 0 && !e.corroborated) r = {n, e.refutation};
  }
  return r;
}

// A correct sensor on the slender statue, rocking up to its collapse under 0.4 g: corroborated
// throughout (its accelerometer reads what a block on the ground's base reads).
TEST(StatueFilter, ACorrectSensorIsCorroboratedUpToTheCollapse) {
  FilterRun run({wide_block(), make(paper_block())}, make(paper_block()));
  run.accelerometer = true;
  run.acceleration_bias = 0.05;
  bool rocked = false;
  const Refuted r = first_refutation(run, 4000, [&](int n) {
    run.push(shaking(n, 0.4));
    rocked = rocked || std::fabs(run.truth->state()[kTheta]) > 0.05;
  });
  EXPECT_TRUE(rocked);
  EXPECT_EQ(r.at, -1) << statue_refutation_name(r.why);
  EXPECT_TRUE(run.filter.estimate().follows_base);
}

// The sensor reads rest (come off the statue, frozen): its accelerometer does not follow the
// shaking ground. Refused within follow_onset_s of the ground's acceleration leaving the noise
// and bias band, long before any member rocks.
TEST(StatueFilter, ASensorReadingRestDoesNotFollowTheGround) {
  FilterRun run({make(paper_block()), wide_block()}, wide_block());
  run.accelerometer = true;
  run.reads_rest = true;
  const Refuted r = first_refutation(run, 800, [&](int n) { run.push(shaking(n, 0.5)); });
  ASSERT_GE(r.at, 0);
  EXPECT_EQ(r.why, StatueRefutation::kDoesNotFollowBase);
  EXPECT_LT(r.at, 0.3 * kRate);  // the ramp reaches 0.05 g within 0.1 s
  // Refused for good while the ground shakes.
  for (int n = 800; n < 1200; ++n) {
    run.push(shaking(n, 0.5));
    ASSERT_FALSE(run.filter.estimate().corroborated) << n;
  }
}

// A gyroscope at half its gain (a wrong range setting) on the rocking slender statue: its tilt
// and lever arm no longer match what the accelerometer reads. Refused while the statue rocks,
// before it overturns.
TEST(StatueFilter, AGyroscopeAtHalfGainIsRefusedWhileTheStatueRocks) {
  FilterRun run({wide_block(), make(paper_block())}, make(paper_block()));
  run.accelerometer = true;
  run.rate_gain = 0.5;
  int rocking_from = -1;
  const Refuted r = first_refutation(run, 4000, [&](int n) {
    run.push(shaking(n, 0.4));
    if (rocking_from < 0 && std::fabs(run.truth->state()[kTheta]) > 0.01) rocking_from = n;
  });
  ASSERT_GE(rocking_from, 0);
  ASSERT_GE(r.at, 0);
  EXPECT_EQ(r.why, StatueRefutation::kDoesNotFollowBase);
  EXPECT_GE(r.at, rocking_from - static_cast<int>(0.2 * kRate));  // not before it moves
}

// A sensor on the plinth: its accelerometer follows the ground, its gyroscope reads still. While
// some member stands, nothing contradicts it (docs: what one sensor cannot detect); once every
// member rocks, the still reading is a contradiction, not evidence.
TEST(StatueFilter, StillWhileEveryMemberRocksIsAContradiction) {
  const Scene slender = make(paper_block());
  const double still = 0.0;
  {  // By default the members' flow at rest (Eq 16's onset) already leaves it unexplained.
    FilterRun run({slender, slender}, slender);
    run.accelerometer = true;
    run.reads_ground = true;
    const Refuted r = first_refutation(run, 4000, [&](int n) {
      run.push(shaking(n, 0.4), &still);
    });
    ASSERT_GE(r.at, 0);
    EXPECT_TRUE(r.why == StatueRefutation::kStillWhileMembersRock ||
                r.why == StatueRefutation::kUnexplained)
        << statue_refutation_name(r.why);
  }
  StatueFilterSettings lenient;  // the score test as lenient as allowed: the contradiction alone
  lenient.unexplained_score = Real(50);
  FilterRun run({slender, slender}, slender, 0.002, lenient);
  run.accelerometer = true;
  run.reads_ground = true;
  const Refuted r = first_refutation(run, 4000, [&](int n) {
    run.push(shaking(n, 0.4), &still);
  });
  ASSERT_GE(r.at, 0);
  EXPECT_EQ(r.why, StatueRefutation::kStillWhileMembersRock);
  for (int m = 0; m < 2; ++m) {
    EXPECT_NE(run.ensemble->member(m).mode().phase, Phase::kFullContact) << m;
  }
}

// Without an accelerometer sample for follow_onset_s nothing corroborates the gyroscope.
TEST(StatueFilter, NoAccelerometerNoCorroboration) {
  FilterRun run({wide_block(), make(paper_block())}, wide_block());
  run.accelerometer = false;
  const Refuted r = first_refutation(run, 400, [&](int n) { run.push(shaking(n, 0.1)); });
  EXPECT_EQ(r.why, StatueRefutation::kNoAccelerometer);
  EXPECT_EQ(r.at, static_cast<int>(std::lround(0.15 * kRate)) - 1);
}

// A refused sensor is trusted again once every member and the statue sat in full contact for
// trust_again_s with its accelerometer following; not before.
TEST(StatueFilter, ARefusedSensorIsTrustedAgainAfterRest) {
  StatueFilterSettings settings;
  settings.trust_again_s = 2.0;
  FilterRun run({wide_block()}, wide_block(), 0.002, settings);
  run.accelerometer = true;
  run.reads_rest = true;
  for (int n = 0; n < 400; ++n) run.push(shaking(n, 0.2));
  ASSERT_FALSE(run.filter.estimate().corroborated);
  run.reads_rest = false;  // fixed: it reads the statue again; the ground is still
  int trusted_at = -1;
  for (int n = 0; n < 1000 && trusted_at < 0; ++n) {
    run.push({});
    if (run.filter.estimate().corroborated) trusted_at = n;
  }
  EXPECT_GE(trusted_at, static_cast<int>(2.0 * kRate) - 1);
  EXPECT_LE(trusted_at, static_cast<int>(2.5 * kRate));
  EXPECT_EQ(run.filter.estimate().refutation, StatueRefutation::kNone);
}

// The bounds of the settings that decide how far the sensor may lower the risk: each refused
// outside its range, the key and the limit named.
TEST(StatueFilter, TheLoweringSettingsHaveBounds) {
  struct Case {
    void (*change)(StatueFilterSettings&);
    const char* field;
    double limit;
  };
  const Case cases[] = {
      {[](StatueFilterSettings& s) { s.unexplained_score = Real(1e30); },
       "statue_filter.unexplained_score", 50},
      {[](StatueFilterSettings& s) { s.unexplained_score = Real(1); },
       "statue_filter.unexplained_score", 2},
      {[](StatueFilterSettings& s) { s.rest_rate_rad_s = Real(100); },
       "statue_filter.rest_rate_rad_s", 0.05},
      {[](StatueFilterSettings& s) { s.rest_tilt_rad = Real(0.05); },
       "statue_filter.rest_tilt_rad", 0.01},
      {[](StatueFilterSettings& s) { s.credible_weight = Real(0.9); },
       "statue_filter.credible_weight", 0.5},
      {[](StatueFilterSettings& s) { s.ruled_out_fraction = Real(0.8); },
       "statue_filter.ruled_out_fraction", 0.5},
      {[](StatueFilterSettings& s) { s.rate_noise_rad_s = Real(1); },
       "statue_filter.rate_noise_rad_s", 0.05},
      {[](StatueFilterSettings& s) { s.model_tolerance = Real(0.01); },
       "statue_filter.model_tolerance", 0.05},
      {[](StatueFilterSettings& s) { s.acceleration_bias_m_s2 = Real(5); },
       "statue_filter.acceleration_bias_m_s2", 1},
      {[](StatueFilterSettings& s) { s.follow_tolerance = Real(1); },
       "statue_filter.follow_tolerance", 0.7},
      {[](StatueFilterSettings& s) { s.contradiction_rate_rad_s = Real(2); },
       "statue_filter.contradiction_rate_rad_s", 0.5},
      {[](StatueFilterSettings& s) { s.trust_again_s = 0.1; }, "statue_filter.trust_again_s",
       1},
      {[](StatueFilterSettings& s) { s.memory_s = 1e4; }, "statue_filter.memory_s", 600},
  };
  for (const Case& c : cases) {
    StatueFilterSettings s;
    c.change(s);
    const Error e = validate(s);
    EXPECT_EQ(e.code, ErrorCode::kOutOfRange) << c.field;
    EXPECT_STREQ(e.field, c.field);
    EXPECT_DOUBLE_EQ(e.limit, c.limit) << c.field;
  }
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

// An anchored statue (the measured rate stays 0) under shaking that lifts every member off from
// rest (1.2 g; two slender members, so that none predicts the statue's stillness): the span of
// their predictions leaves it out, so it is unexplained; the risk falls back to the worst
// member's, never less. (With a member that stands at that shaking, stillness is inside the
// span: that sensor is a contradiction's case, StillWhileEveryMemberRocksIsAContradiction.)
TEST(StatueFilter, AnAnchoredStatueIsExplainedByNoMember) {
  SceneParams stockier = paper_block();  // 5 % wider: uplift at 0.35 g, the paper's at 0.33 g
  stockier.block.half_width = 0.315;
  stockier.block.inertia = homogeneous_rectangle_inertia(stockier.block.mass, 0.315, 0.9);
  FilterRun run({make(paper_block()), make(stockier)}, make(paper_block()));
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

// A statue between the members (half-width 0.375 m, between the paper's 0.3 and the wide 0.6),
// rocking: each member's prediction misses its rate by more than the tolerance at times, but
// the members span the declared uncertainty and the statue stays inside their span: explained.
TEST(StatueFilter, AStatueBetweenTheMembersIsExplained) {
  SceneParams between = paper_block();
  between.block.half_width = 0.375;
  between.block.inertia = homogeneous_rectangle_inertia(between.block.mass, 0.375, 0.9);
  FilterRun run({make(paper_block()), wide_block()}, make(between), 0.0);
  bool rocked = false;
  for (int n = 0; n < 1600; ++n) {
    run.push(shaking(n, 0.6));
    rocked = rocked || run.truth->mode().rocking();
    ASSERT_TRUE(run.filter.estimate().explained) << n;
  }
  EXPECT_TRUE(rocked);
  EXPECT_GT(run.filter.estimate().intervals, 10);
}

// Lifting off and landing: the interval in which the statue leaves or regains full contact holds
// two phases (and at lift-off a tilt within its noise of 0, which may name the wrong corner),
// its members' predictions one. Such intervals are not scored: the statue the members model
// exactly stays explained through its lift-off (scored, that interval alone made it unexplained).
TEST(StatueFilter, LiftOffAndLandingIntervalsAreNotScored) {
  FilterRun run({make(paper_block()), wide_block()}, make(paper_block()), 0.003);
  int lift_offs = 0;
  bool was_rocking = false;
  for (int n = 0; n < 3000; ++n) {
    run.push(shaking(n, 0.36));
    const bool rocking = run.truth->mode().rocking();
    lift_offs += rocking && !was_rocking ? 1 : 0;
    was_rocking = rocking;
    ASSERT_TRUE(run.filter.estimate().explained) << n;
  }
  EXPECT_GE(lift_offs, 1);
}

// One interval is no statistic: a lone 6-sigma spike of the rate on a still statue in a quiet
// ground (the only interval the signal gate lets through) does not make it unexplained.
TEST(StatueFilter, ALoneSpikeOfNoiseIsNoEvidence) {
  FilterRun run({make(paper_block()), wide_block()}, make(paper_block()), 0.0);
  const double still = 0.0;
  const double spike = 6.0 * 0.003;  // 6 x rate_noise_rad_s
  for (int n = 0; n < 600; ++n) {
    run.push({}, n == 300 ? &spike : &still);
    ASSERT_TRUE(run.filter.estimate().explained) << n;
  }
}

// Still is not upright: a statue held leaning (0.05 rad, its rate 0 for 0.3 s, longer than
// rest_time_s) by the ground's push keeps its tilt while its accelerometer reads the lean
// (g sin 0.05 = 0.49 m/s2); the same stillness with the accelerometer reading the block upright
// is the gyroscope's drift, and the tilt goes back to 0.
TEST(StatueFilter, AStatueHeldLeaningKeepsItsTilt) {
  for (const bool reads_lean : {true, false}) {
    FilterRun run({make(paper_block()), wide_block()}, make(paper_block()), 0.0);
    run.accelerometer = true;
    run.reads_ground = true;  // upright on the (still) ground: 0
    run.acceleration_noise = 0.0;
    const double rising = 0.25;  // rad/s for 0.2 s: 0.05 rad
    const double still = 0.0;
    for (int n = 0; n < 40; ++n) run.push({}, &rising);
    run.reads_ground = !reads_lean;
    run.reads_rest = false;
    run.acceleration_bias = reads_lean ? kStandardGravity * std::sin(0.05) : 0.0;
    for (int n = 0; n < 60; ++n) run.push({}, &still);
    if (reads_lean) {
      EXPECT_NEAR(run.filter.estimate().tilt, 0.05, 0.002);
    } else {
      EXPECT_EQ(run.filter.estimate().tilt, 0.0);
    }
  }
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

// A valid forecast of `members` members, those of the bits of `collapsing_members` collapsing.
ForecastOutcome forecast_of(int members, std::uint32_t collapsing_members) {
  ForecastOutcome f;
  f.valid = true;
  f.members = members;
  f.collapsing = std::popcount(collapsing_members);
  f.probability = static_cast<double>(f.collapsing) / members;
  f.collapsing_members = collapsing_members;
  return f;
}

// The forecast weighted: the weight of the members that collapse.
TEST(StatueFilter, TheForecastIsWeightedOnceTheEstimateIs) {
  const ForecastOutcome f = forecast_of(3, 0b100);
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

// Every member collapses and the weights, normalised as the filter normalises them, sum past 1
// by a rounding: the probability is 1, not above it (the alarm policy would take it for an
// internal fault and show `fault` in place of `alarm`).
TEST(StatueFilter, TheWeightedForecastNeverExceedsOne) {
  const ForecastOutcome f = forecast_of(3, 0b111);
  StatueEstimate e;
  e.weighted = true;
  const Real raw[3] = {Real(0.5014295859466933), Real(0.794983493746024),
                       Real(0.0771069862639161)};
  const Real sum = raw[0] + raw[1] + raw[2];
  Real total = 0;
  for (int m = 0; m < 3; ++m) {
    e.weights[static_cast<std::size_t>(m)] = raw[m] / sum;
    total += e.weights[static_cast<std::size_t>(m)];
  }
  if constexpr (sizeof(Real) == sizeof(double)) {
    ASSERT_GT(total, Real(1));  // the case, in double
  }
  EXPECT_EQ(weighted_collapse_probability(f, e), 1.0);
}


// --- Sliding, from the accelerometer ---

// The paper's block on the ground with Coulomb friction: mu_s 0.15, mu_k 0.12. Its uplift needs
// 0.33 g, more than friction ever passes on: it slides and never rocks.
Scene sliding_block() { return make(with_friction(paper_block(), 0.15, 0.12)); }

// The same with mu_s 0.8, mu_k 0.7: it rocks before it could slide.
Scene gripping_block() { return make(with_friction(paper_block(), 0.8, 0.7)); }

// `amplitude_g` at 1 Hz as shaking(), for `shake_s`, then still.
GroundAcceleration burst(int n, double amplitude_g, double shake_s) {
  return n / kRate < shake_s ? shaking(n, amplitude_g) : GroundAcceleration{};
}

// The specific force the accelerometer reads against the simulator's motion (the sign
// conventions): sliding, the block's acceleration is its kinetic friction's, -mu_k g sign(x')
// (Eqs 4-5), and the vertical reads g; in full contact it moves with the ground; rocking freely
// (Eq 34's impulse, the ground still after it), the reading turned back into the world frame
// less gravity is the second difference of the sensor's position about the pivot.
TEST(StatueFilter, TheAccelerometerReadsTheSimulatedMotion) {
  const Scene slider = sliding_block();
  const StatueAccelerometerMount mount{Real(1.2), Real(0.1)};
  Simulator sim;
  SolverSettings solver;
  solver.step = 1e-4;
  ASSERT_TRUE(
      Simulator::create(slider, Excitation::sine_pulse(Real(0.5 * kStandardGravity), 1.0), solver,
                        sim)
          .ok());
  sim.start_at_rest();
  int sliding = 0;
  int sticking = 0;
  while (sim.time() < 1.0 && !sim.mode().terminal()) {
    sim.step();
    const GroundAcceleration g = sim.ground(sim.time());
    const Vector2r f =
        simulated_specific_force(slider, sim.mode(), sim.state(), sim.accelerations(), g, mount);
    if (sim.mode().phase == Phase::kSliding) {
      ++sliding;
      ASSERT_NEAR(f.x(), -0.12 * kStandardGravity * sim.mode().slide_direction, 1e-9);
      ASSERT_NEAR(f.y(), kStandardGravity, 1e-9);
    } else if (sim.mode().phase == Phase::kFullContact) {
      ++sticking;
      ASSERT_NEAR(f.x(), g.horizontal, 1e-9);
    }
  }
  EXPECT_GT(sliding, 1000);
  EXPECT_GT(sticking, 100);

  const Scene rocker = make(paper_block());
  ASSERT_TRUE(Simulator::create(rocker, Excitation::none(), solver, sim).ok());
  sim.start_with_impulse(Real(0.4));  // the ground's velocity jumps by -0.4 m/s
  // The sensor's position from the pivot, world frame.
  const auto position = [&](const Simulator& s) {
    const Real offset = rocker.corner(s.mode().corner).offset + mount.offset_m;
    const Real th = s.state()[kTheta];
    return Vector2r(std::cos(th) * offset - std::sin(th) * mount.height_m,
                    std::sin(th) * offset + std::cos(th) * mount.height_m);
  };
  std::vector<Vector2r> p;
  std::vector<Vector2r> a;
  std::vector<Corner> corner;
  while (sim.time() < 1.5 && !sim.mode().terminal()) {
    sim.step();
    ASSERT_TRUE(sim.mode().rocking());
    const Vector2r f = simulated_specific_force(rocker, sim.mode(), sim.state(),
                                                sim.accelerations(), {}, mount);
    const Real th = sim.state()[kTheta];
    a.emplace_back(std::cos(th) * f.x() - std::sin(th) * f.y(),
                   std::sin(th) * f.x() + std::cos(th) * f.y() - kStandardGravity);
    p.push_back(position(sim));
    corner.push_back(sim.mode().corner);
  }
  int compared = 0;
  for (std::size_t k = 1; k + 1 < p.size(); ++k) {
    if (corner[k - 1] != corner[k] || corner[k + 1] != corner[k]) continue;  // an impact
    const Vector2r second = (p[k + 1] - 2 * p[k] + p[k - 1]) / (solver.step * solver.step);
    ASSERT_NEAR(a[k].x(), second.x(), 1e-3) << k;
    ASSERT_NEAR(a[k].y(), second.y(), 1e-3) << k;
    ++compared;
  }
  EXPECT_GT(compared, 10000);
}

// What the filter made of a block that slides and never rocks (its own scene the box's one
// member), under 1 Hz shaking of `amplitude_g` for `shake_s`, then still, `seconds` in all; the
// accelerometer at the default noise and a bias of 0.1 m/s2 left. Times in s from the start.
struct SlideTimeline {
  double first_truth = -1.0;  // the truth first slides
  double last_truth = -1.0;   // and last
  double first_measured = -1.0;
  int truth_sliding = 0;  // samples
  int both = 0;           // samples both slide
  int same_direction = 0;  // of those, in the truth's direction
  int stale = 0;  // samples measured sliding while the truth had stuck for 0.4 s (or never slid)
  Phase last_phase = Phase::kFullContact;  // measured at the end
};

SlideTimeline slide_timeline(const Scene& block, double amplitude_g, double shake_s,
                             double seconds, const StatueFilterSettings& settings = {}) {
  FilterRun run({block}, block, 0.002, settings);
  run.accelerometer = true;
  run.acceleration_bias = 0.1;
  SlideTimeline r;
  for (int n = 0; n < static_cast<int>(seconds * kRate); ++n) {
    run.push(burst(n, amplitude_g, shake_s));
    const double t = n / kRate;
    const Mode& truth = run.truth->mode();
    const StatueEstimate& e = run.filter.estimate();
    EXPECT_FALSE(truth.rocking()) << t;
    EXPECT_FALSE(e.mode.rocking()) << t;
    EXPECT_TRUE(e.acceleration_used) << t;
    if (truth.sliding()) {
      if (r.first_truth < 0.0) r.first_truth = t;
      r.last_truth = t;
      ++r.truth_sliding;
    }
    if (e.mode.sliding()) {
      EXPECT_EQ(e.mode.phase, Phase::kSliding) << t;
      if (r.first_measured < 0.0) r.first_measured = t;
      if (r.last_truth < 0.0 || t - r.last_truth >= 0.4) ++r.stale;
    }
    if (truth.sliding() && e.mode.sliding()) {
      ++r.both;
      r.same_direction += truth.slide_direction == e.mode.slide_direction ? 1 : 0;
    }
  }
  r.last_phase = run.filter.estimate().mode.phase;
  return r;
}

// A block sliding on the ground under 0.25 g for 4 s: the filter says sliding within 0.25 s of
// the truth's first slide, for most of the truth's sliding, in its direction, never while the
// truth has stuck for 0.4 s, and full contact again after the last slide.
TEST(StatueFilter, ASlidingBlockIsMeasuredSliding) {
  const SlideTimeline r = slide_timeline(sliding_block(), 0.25, 4.0, 6.0);
  ASSERT_GT(r.first_truth, 0.0);
  EXPECT_GT(r.truth_sliding, 200);
  EXPECT_GE(r.first_measured, r.first_truth);
  EXPECT_LT(r.first_measured - r.first_truth, 0.25) << r.first_truth;
  EXPECT_GT(r.both, 0.6 * r.truth_sliding) << r.both << " of " << r.truth_sliding;
  EXPECT_GT(r.same_direction, 0.9 * r.both) << r.same_direction << " of " << r.both;
  EXPECT_EQ(r.stale, 0);
  EXPECT_EQ(r.last_phase, Phase::kFullContact);
}

// The same on the paper's isolated base (T = 2 s, xi = 0.2) under 0.3 g for 5 s: the base's
// acceleration is the member's, its block's reaction included (the member the true statue).
StatueFilterSettings sliding_on_isolated_base() {
  StatueFilterSettings s;
  s.slide_on_isolated_base = true;
  return s;
}

TEST(StatueFilter, ASlidingBlockOnAnIsolatedBaseIsMeasuredSliding) {
  const SlideTimeline r = slide_timeline(make(with_friction(paper_isolated(), 0.15, 0.12)), 0.3,
                                         5.0, 8.0, sliding_on_isolated_base());
  ASSERT_GT(r.first_truth, 0.0);
  EXPECT_GT(r.truth_sliding, 100);
  EXPECT_LT(r.first_measured - r.first_truth, 0.25) << r.first_truth;
  EXPECT_GT(r.both, r.truth_sliding / 2) << r.both << " of " << r.truth_sliding;
  EXPECT_EQ(r.stale, 0);
  EXPECT_EQ(r.last_phase, Phase::kFullContact);
}

// By default an isolated base is not tested (the members' simulated bases are not the statue's):
// the same slide is not measured, and the accelerometer is said unused.
TEST(StatueFilter, AnIsolatedBaseIsNotTestedByDefault) {
  const Scene block = make(with_friction(paper_isolated(), 0.15, 0.12));
  FilterRun run({block}, block);
  run.accelerometer = true;
  int truth_sliding = 0;
  for (int n = 0; n < static_cast<int>(8.0 * kRate); ++n) {
    run.push(burst(n, 0.3, 5.0));
    truth_sliding += run.truth->mode().sliding() ? 1 : 0;
    ASSERT_FALSE(run.filter.estimate().mode.sliding()) << n / kRate;
    ASSERT_FALSE(run.filter.estimate().acceleration_used) << n / kRate;
  }
  EXPECT_GT(truth_sliding, 100);
}

// Sliding is said only when no member's base explains the reading. Members: the block on the
// paper's isolated base and on the ground; the accelerometer reads what the block reads sticking
// to an isolated base (a simulation of it: its absolute acceleration). Never sliding with both
// members; with the ground's member alone, the same readings are sliding.
TEST(StatueFilter, SlidingOnlyWhenNoMembersBaseExplainsTheReading) {
  const Scene isolated = make(with_friction(paper_isolated(), 0.15, 0.12));
  const auto slid = [&](std::vector<Scene> members) {
    FilterRun run(std::move(members), isolated, 0.002, sliding_on_isolated_base());
    bool sliding = false;
    for (int n = 0; n < 4 * static_cast<int>(kRate); ++n) {
      const GroundAcceleration g = shaking(n, 0.3);
      run.ensemble->push(g);
      run.truth->push(g);  // the block on the isolated base
      StatueMeasurement m{0.0};
      m.has_acceleration = true;
      m.specific_force_m_s2 =
          run.truth->simulator().accelerations().u + run.truth->ground().horizontal;
      run.filter.on_sample(*run.ensemble, g, m);
      EXPECT_TRUE(run.filter.estimate().acceleration_used);
      sliding = sliding || run.filter.estimate().mode.sliding();
    }
    return sliding;
  };
  EXPECT_FALSE(slid({isolated, sliding_block()}));
  EXPECT_TRUE(slid({sliding_block()}));
}

// A block that rocks (0.4 g, as TheRockingStatueIsTheSlenderMember) and grips (mu_s 0.8): its
// impacts and lever arm's accelerations are never taken for sliding.
TEST(StatueFilter, ARockingBlockIsNeverMeasuredSliding) {
  FilterRun run({gripping_block()}, gripping_block());
  run.accelerometer = true;
  run.averaging = true;  // the impacts' jumps in the reading
  run.acceleration_bias = 0.1;
  int rocked = 0;
  for (int n = 0; n < 2000 && !run.truth->mode().terminal(); ++n) {
    run.push(shaking(n, 0.4));
    ASSERT_FALSE(run.truth->mode().sliding()) << n;
    rocked += run.truth->mode().rocking() ? 1 : 0;
    const StatueEstimate& e = run.filter.estimate();
    ASSERT_FALSE(e.mode.sliding()) << n << " relative " << e.relative_acceleration
                                   << " threshold " << e.slide_threshold;
  }
  EXPECT_GT(rocked, 200);
}

// The accelerometer's noise at the stated level (and a bias left of 0.15 m/s2) under shaking
// too weak to slide the block, for 60 s: never sliding.
TEST(StatueFilter, NoiseAloneIsNeverSliding) {
  FilterRun run({sliding_block()}, sliding_block());
  run.accelerometer = true;
  run.acceleration_bias = 0.15;
  for (int n = 0; n < 60 * static_cast<int>(kRate); ++n) {
    run.push(shaking(n, 0.1));
    ASSERT_FALSE(run.truth->mode().sliding()) << n;
    ASSERT_FALSE(run.filter.estimate().mode.sliding()) << n;
  }
  EXPECT_TRUE(run.filter.estimate().acceleration_used);
}

// While sliding is measured, a missing or faulty accelerometer sample (none fresh, or not
// finite) gives the gyroscope's phase at once; its return starts the test afresh.
TEST(StatueFilter, AMissingAccelerometerFallsBackToTheGyroscope) {
  FilterRun run({sliding_block()}, sliding_block());
  run.accelerometer = true;
  int n = 0;
  for (; n < 4 * static_cast<int>(kRate) && !run.filter.estimate().mode.sliding(); ++n) {
    run.push(shaking(n, 0.25));
  }
  ASSERT_TRUE(run.filter.estimate().mode.sliding());
  ASSERT_TRUE(run.truth->mode().sliding());
  // No fresh sample.
  run.accelerometer = false;
  run.push(shaking(n++, 0.25));
  EXPECT_EQ(run.filter.estimate().mode.phase, Phase::kFullContact);
  EXPECT_FALSE(run.filter.estimate().acceleration_used);
  // A sample that is not a number.
  run.ensemble->push(shaking(n, 0.25));
  run.truth->push(shaking(n, 0.25));
  StatueMeasurement m{run.truth->state()[kThetaDot]};
  m.has_acceleration = true;
  m.specific_force_m_s2 = std::numeric_limits<Real>::quiet_NaN();
  run.filter.on_sample(*run.ensemble, shaking(n++, 0.25), m);
  EXPECT_EQ(run.filter.estimate().mode.phase, Phase::kFullContact);
  EXPECT_FALSE(run.filter.estimate().acceleration_used);
  // Back: not sliding before the onset's time has passed again.
  run.accelerometer = true;
  run.push(shaking(n++, 0.25));
  EXPECT_TRUE(run.filter.estimate().acceleration_used);
  EXPECT_FALSE(run.filter.estimate().mode.sliding());
}

// A scene without [friction] never slides: its measured phase is the gyroscope's whatever the
// accelerometer reads (an accelerometer reading 3 m/s2 on a still statue and ground).
TEST(StatueFilter, AStatueThatCannotSlideIsNotTested) {
  FilterRun run({make(paper_block())}, make(paper_block()));
  const double still = 0.0;
  for (int n = 0; n < 400; ++n) {
    run.ensemble->push({});
    run.truth->push({});
    StatueMeasurement m{static_cast<Real>(still)};
    m.has_acceleration = true;
    m.specific_force_m_s2 = 3.0;
    run.filter.on_sample(*run.ensemble, {}, m);
    ASSERT_EQ(run.filter.estimate().mode.phase, Phase::kFullContact);
    ASSERT_FALSE(run.filter.estimate().acceleration_used);
  }
}

// A slender block whose friction (mu_s 0.4, mu_k 0.32) barely grips, under 0.8 g: it rocks, and
// slides while rocking before it overturns. The filter says slide-rocking while the truth does,
// and never sliding while the truth has not slid for 0.4 s.
TEST(StatueFilter, ARockingBlockThatSlidesIsMeasuredSlideRocking) {
  const Scene block = make(with_friction(paper_block(), 0.4, 0.32));
  FilterRun run({block}, block);
  run.accelerometer = true;
  run.averaging = true;
  run.acceleration_bias = 0.1;
  int truth_slide_rocking = 0;
  int both = 0;
  double last_truth = -1.0;
  for (int n = 0; n < 1200 && !run.truth->mode().terminal(); ++n) {
    run.push(shaking(n, 0.8));
    const double t = n / kRate;
    const Mode& truth = run.truth->mode();
    const Mode& e = run.filter.estimate().mode;
    if (truth.sliding()) last_truth = t;
    truth_slide_rocking += truth.phase == Phase::kSlideRocking ? 1 : 0;
    if (e.sliding()) {
      ASSERT_GE(last_truth, 0.0) << t;
      ASSERT_LT(t - last_truth, 0.4) << t;
    }
    both += truth.phase == Phase::kSlideRocking && e.phase == Phase::kSlideRocking ? 1 : 0;
  }
  ASSERT_GT(truth_slide_rocking, 20);
  EXPECT_GT(both, truth_slide_rocking / 3);
}

}  // namespace
}  // namespace statue_filter_test
}  // namespace plinth

// The statues of one axis (ensemble.h): members fed the same motion, the worst member's risk,
// restarts, the nominal statue's events; the forecast's own tests are test_forecast.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "plinth/core/ensemble.h"
#include "test_support.h"

namespace plinth {
namespace {

using testing::make;
using testing::paper_block;
using testing::paper_isolated;

EstimatorSettings ensemble_estimator_settings() {
  EstimatorSettings e;
  e.sample_rate_hz = 200.0;
  e.steps_per_sample = 4;
  return e;
}

ForecastSettings no_forecast() {
  ForecastSettings f;
  f.enabled = false;
  return f;
}

// A block twice as wide as the paper's (uplift at 2g/3): it stands where the paper's rocks.
Scene wide_block() {
  SceneParams wide = paper_block();
  wide.block.half_width = 0.6;
  wide.block.inertia = homogeneous_rectangle_inertia(wide.block.mass, 0.6, 0.9);
  return make(wide);
}

// The ensemble with the scenes it refers to (on the heap: 17 estimators and a forecaster).
struct EnsembleRun {
  explicit EnsembleRun(std::vector<Scene> statues, const ForecastSettings& fs = no_forecast())
      : scenes(std::move(statues)), ensemble(std::make_unique<Ensemble>()) {
    EXPECT_TRUE(ensemble->start(scenes, ensemble_estimator_settings(), fs, {}).ok());
    ensemble->restart({});
  }
  std::vector<Scene> scenes;
  std::unique_ptr<Ensemble> ensemble;
};

double shaking(int n, double amplitude_g) {
  return amplitude_g * kStandardGravity * std::sin(2.0 * std::numbers::pi * n / 200.0);
}

// The wide block first (the nominal statue), the paper's second: under 0.4 g at 1 Hz the
// paper's block rocks and overturns, so the worst risk is member 1's once it rocks, and it is
// overturning_risk of that member at every sample; the nominal risk stays member 0's.
TEST(Ensemble, RiskIsTheWorstMembersAndNamesIt) {
  EnsembleRun s({wide_block(), make(paper_block())});
  const Ensemble& e = *s.ensemble;
  bool member_one_worse = false;
  for (int n = 0; n < 600; ++n) {
    s.ensemble->push({shaking(n, 0.4), 0.0});
    EnsembleRisk r;
    e.risk(r);
    const Risk r0 = overturning_risk(s.scenes[0], e.member(0).mode(), e.member(0).state());
    const Risk r1 = overturning_risk(s.scenes[1], e.member(1).mode(), e.member(1).state());
    ASSERT_EQ(r.nominal_risk.total, r0.total) << n;
    ASSERT_EQ(r.risk.total, std::fmax(r0.total, r1.total)) << n;
    ASSERT_EQ(r.worst_member, r1.total > r0.total ? 1 : 0) << n;
    member_one_worse = member_one_worse || r.worst_member == 1;
  }
  EXPECT_TRUE(member_one_worse);
  EXPECT_TRUE(e.member(1).mode().terminal());
  EnsembleRisk last;
  e.risk(last);
  EXPECT_EQ(last.risk.total, 1.0);
  EXPECT_FALSE(e.nominal().mode().terminal());
}

TEST(Ensemble, EveryMemberTakesTheSameMotion) {
  EnsembleRun s({make(paper_block()), make(paper_block())});
  for (int n = 0; n < 300; ++n) s.ensemble->push({shaking(n, 0.3), 0.1});
  EXPECT_EQ(s.ensemble->member(0).state(), s.ensemble->member(1).state());
  EXPECT_EQ(s.ensemble->member(1).samples(), 300);
}

TEST(Ensemble, InFullContactUntilAMemberMoves) {
  EnsembleRun s({wide_block(), make(paper_block())});
  int n = 0;
  while (s.ensemble->in_full_contact() && n < 400) s.ensemble->push({shaking(n++, 0.4), 0.0});
  ASSERT_LT(n, 400);
  EXPECT_EQ(s.ensemble->nominal().mode().phase, Phase::kFullContact);  // the wide one stands
  EXPECT_NE(s.ensemble->member(1).mode().phase, Phase::kFullContact);
}

// A restart: every member at rest in full contact again, the forecast forgotten.
TEST(Ensemble, ARestartPutsEveryMemberAtRestAndForgetsTheForecast) {
  ForecastSettings fs;
  fs.horizon_s = 2.0;
  fs.window_s = 1.0;
  fs.work_steps_per_s = 1e9;
  EnsembleRun s({make(paper_block()), wide_block()}, fs);
  for (int n = 0; n < 600; ++n) s.ensemble->push({shaking(n, 0.4), 0.0});
  ASSERT_TRUE(s.ensemble->forecaster().latest().valid);
  ASSERT_TRUE(s.ensemble->nominal().mode().terminal());
  s.ensemble->restart({0.5, 0.0});
  EXPECT_FALSE(s.ensemble->forecaster().latest().valid);
  for (int m = 0; m < 2; ++m) {
    EXPECT_EQ(s.ensemble->member(m).mode().phase, Phase::kFullContact);
    EXPECT_EQ(s.ensemble->member(m).state(), State::Zero());
    EXPECT_EQ(s.ensemble->member(m).samples(), 0);
  }
}

struct NominalEventCount final : EventSink {
  void on_event(const Event&) override { ++events; }
  int events = 0;
};

// The nominal statue's events reach the sink, before and after a restart; the other members'
// do not (member 1 is the wide block, which stands).
TEST(Ensemble, TheNominalStatuesEventsReachTheSinkAcrossRestarts) {
  EnsembleRun s({make(paper_block()), wide_block()});
  NominalEventCount sink;
  s.ensemble->set_event_sink(&sink);
  for (int n = 0; n < 400; ++n) s.ensemble->push({shaking(n, 0.4), 0.0});
  const int before = sink.events;
  EXPECT_GT(before, 0);
  s.ensemble->restart({});
  for (int n = 0; n < 400; ++n) s.ensemble->push({shaking(n, 0.4), 0.0});
  EXPECT_GT(sink.events, before);
  EnsembleRun wide_first({wide_block(), make(paper_block())});
  NominalEventCount quiet;
  wide_first.ensemble->set_event_sink(&quiet);
  for (int n = 0; n < 400; ++n) wide_first.ensemble->push({shaking(n, 0.4), 0.0});
  EXPECT_EQ(quiet.events, 0);
}

// The base's absolute acceleration u'' + u_G'': on the ground (no base), the ground's; on an
// isolated base started at rest under a steady push, 0 at first (the base's inertia holds it),
// then the ground's once the device has taken up the push.
TEST(Ensemble, BaseAccelerationIsTheGroundsWithoutABaseAndLagsWithOne) {
  EnsembleRun ground({make(paper_block())});
  ground.ensemble->push({0.7, 0.0});
  EXPECT_EQ(ground.ensemble->base_acceleration(), Real(0.7));
  EnsembleRun isolated({make(paper_isolated())});
  isolated.ensemble->restart({0.5, 0.0});
  EXPECT_NEAR(isolated.ensemble->base_acceleration(), 0.0, 1e-12);
  for (int n = 0; n < 200 * 40; ++n) isolated.ensemble->push({0.5, 0.0});
  EXPECT_EQ(isolated.ensemble->nominal().mode().phase, Phase::kFullContact);
  EXPECT_NEAR(isolated.ensemble->base_acceleration(), 0.5, 1e-3);
}

// What start() refuses, each naming its field.
TEST(Ensemble, RefusesWhatItCannotRun) {
  const auto field = [](std::span<const Scene> members, EstimatorSettings es, ForecastSettings fs,
                        RiskSettings rs = {}) {
    auto e = std::make_unique<Ensemble>();
    return std::string(e->start(members, es, fs, rs).field);
  };
  const std::vector<Scene> too_many(static_cast<std::size_t>(kMaxEnsembleMembers) + 1,
                                    make(paper_block()));
  EXPECT_EQ(field(too_many, ensemble_estimator_settings(), no_forecast()), "uncertainty");
  const std::vector<Scene> one{make(paper_block())};
  EstimatorSettings slow = ensemble_estimator_settings();
  slow.steps_per_sample = 0;
  EXPECT_EQ(field(one, slow, no_forecast()), "estimator.steps_per_sample");
  ForecastSettings fs;
  fs.horizon_s = -1.0;
  EXPECT_EQ(field(one, ensemble_estimator_settings(), fs), "forecast.horizon_s");
  RiskSettings rs;
  rs.base_stop_weight = 2.0;
  EXPECT_EQ(field(one, ensemble_estimator_settings(), no_forecast(), rs), "risk.base_stop_weight");
  EXPECT_EQ(field(one, ensemble_estimator_settings(), no_forecast()), "");
}

}  // namespace
}  // namespace plinth

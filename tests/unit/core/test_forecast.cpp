// The ensemble's two-level design (ensemble_design.h) and the forecaster (forecast.h), run by
// the ensemble (ensemble.h).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <set>
#include <utility>
#include <vector>

#include "plinth/core/ensemble.h"
#include "plinth/core/ensemble_design.h"
#include "plinth/core/forecast.h"
#include "test_support.h"

namespace plinth {
namespace {

using testing::make;
using testing::paper_block;
using testing::paper_isolated;

std::vector<DesignPoint> design(int d) {
  std::vector<DesignPoint> points(kMaxDesignPoints);
  const int n = two_level_design(d, points);
  points.resize(static_cast<std::size_t>(n));
  return points;
}

TEST(EnsembleDesign, CountsAreTheCentrePlusTheCorners) {
  EXPECT_EQ(design_point_count(0), 2);  // 2^0 = 1 corner: the centre again (d = 0)
  EXPECT_EQ(design_point_count(2), 5);
  EXPECT_EQ(design_point_count(3), 9);
  EXPECT_EQ(design_point_count(4), 9);
  EXPECT_EQ(design_point_count(7), 9);
  EXPECT_EQ(design_point_count(8), 17);
  EXPECT_EQ(design_point_count(15), 17);
  EXPECT_EQ(design_point_count(16), 0);
  EXPECT_EQ(design_point_count(-1), 0);
}

TEST(EnsembleDesign, RefusesAnOutputTooSmall) {
  std::array<DesignPoint, 4> small{};
  EXPECT_EQ(two_level_design(2, small), 0);  // needs 5
  EXPECT_EQ(two_level_design(1, small), 3);
}

// For every dimension: the centre first; every corner coordinate -1 or +1, unused ones 0;
// every column balanced; no two columns equal (or opposite), so each parameter's extremes are
// present and told apart; no two runs equal.
TEST(EnsembleDesign, ColumnsAreBalancedAndDistinct) {
  for (int d = 1; d <= kMaxUncertainParameters; ++d) {
    SCOPED_TRACE(d);
    const std::vector<DesignPoint> p = design(d);
    ASSERT_EQ(static_cast<int>(p.size()), design_point_count(d));
    for (double z : p[0]) EXPECT_EQ(z, 0.0);
    std::set<std::vector<double>> runs;
    for (std::size_t r = 1; r < p.size(); ++r) {
      for (int i = 0; i < kMaxUncertainParameters; ++i) {
        if (i < d) {
          EXPECT_EQ(std::fabs(p[r][static_cast<std::size_t>(i)]), 1.0);
        } else {
          EXPECT_EQ(p[r][static_cast<std::size_t>(i)], 0.0);
        }
      }
      runs.insert(std::vector<double>(p[r].begin(), p[r].begin() + d));
    }
    EXPECT_EQ(runs.size(), p.size() - 1);
    for (int i = 0; i < d; ++i) {
      double sum = 0.0;
      for (std::size_t r = 1; r < p.size(); ++r) sum += p[r][static_cast<std::size_t>(i)];
      EXPECT_EQ(sum, 0.0) << "column " << i;
      for (int j = 0; j < i; ++j) {
        double dot = 0.0;
        for (std::size_t r = 1; r < p.size(); ++r) {
          dot += p[r][static_cast<std::size_t>(i)] * p[r][static_cast<std::size_t>(j)];
        }
        EXPECT_LT(std::fabs(dot), static_cast<double>(p.size() - 1)) << i << " vs " << j;
      }
    }
  }
}

// Up to three parameters the design is the full factorial: every corner, so the most fragile
// combination of extremes is always a member.
TEST(EnsembleDesign, UpToThreeParametersHoldsEveryCorner) {
  const std::vector<DesignPoint> p = design(3);
  std::set<std::vector<double>> corners;
  for (std::size_t r = 1; r < p.size(); ++r) corners.insert({p[r][0], p[r][1], p[r][2]});
  EXPECT_EQ(corners.size(), 8U);
}

// Four parameters: D = ABC, resolution IV (no main effect aliased with a two-factor one).
TEST(EnsembleDesign, FourParametersUseTheResolutionFourFraction) {
  for (const DesignPoint& z : design(4)) EXPECT_EQ(z[3], z[0] * z[1] * z[2]);
}

ForecastSettings quick_settings(Continuation continuation = Continuation::kRecentWindow) {
  ForecastSettings s;
  s.continuation = continuation;
  s.horizon_s = 3.0;
  s.window_s = 1.0;
  s.interval_s = 0.25;
  s.rate_hz = 200.0;
  s.work_steps_per_s = 1e9;  // every forecast completes within the sample that starts it
  return s;
}

EstimatorSettings estimator_settings() {
  EstimatorSettings e;
  e.sample_rate_hz = 200.0;
  e.steps_per_sample = 4;
  return e;
}

// The statues of one axis (an Ensemble, ensemble.h) with the scenes it refers to, fed a signal
// sample by sample.
struct Statues {
  Statues(std::vector<Scene> statues, const ForecastSettings& fs) : scenes(std::move(statues)) {
    EXPECT_TRUE(ensemble.start(scenes, estimator_settings(), fs, {}).ok());
    ensemble.restart({});
  }
  void push(double horizontal) { ensemble.push({horizontal, 0.0}); }
  [[nodiscard]] const Forecaster& forecaster() const { return ensemble.forecaster(); }
  [[nodiscard]] const PlanarEstimator& member(int m) const { return ensemble.member(m); }
  std::vector<Scene> scenes;
  Ensemble ensemble;
};

TEST(Forecaster, StillGroundForecastsNoCollapse) {
  Statues e({make(paper_block()), make(paper_isolated())}, quick_settings());
  for (int n = 0; n < 400; ++n) e.push(0.0);
  const ForecastOutcome& f = e.forecaster().latest();
  ASSERT_TRUE(f.valid);
  EXPECT_EQ(f.members, 2);
  EXPECT_EQ(f.collapsing, 0);
  EXPECT_EQ(f.probability, 0.0);
  EXPECT_EQ(f.worst_member, -1);
  EXPECT_EQ(f.collapse_in_s, -1.0);
}

TEST(Forecaster, NothingBeforeTheWindowIsFull) {
  Statues e({make(paper_block())}, quick_settings());
  for (int n = 0; n < 199; ++n) e.push(0.0);  // 199 samples: the 1 s window holds 200
  EXPECT_FALSE(e.forecaster().latest().valid);
  e.push(0.0);
  EXPECT_TRUE(e.forecaster().latest().valid);
}

// A sine at 1 Hz of 0.4 g overturns the paper's block (uplift at g/3) 1.7 s after it starts
// and leaves a member twice as wide (uplift at 2g/3) standing. The first forecast, after one
// window (1 s), says so and names the slender member.
TEST(Forecaster, TellsTheMemberThatFallsFromTheOneThatStands) {
  SceneParams wide = paper_block();
  wide.block.half_width = 0.6;
  wide.block.inertia = homogeneous_rectangle_inertia(wide.block.mass, 0.6, 0.9);
  Statues e({make(wide), make(paper_block())}, quick_settings());
  const double amplitude = 0.4 * kStandardGravity;
  ForecastOutcome first_valid;
  for (int n = 0; n < 260 && !first_valid.valid; ++n) {
    e.push(amplitude * std::sin(2.0 * std::numbers::pi * 1.0 * n / 200.0));
    first_valid = e.forecaster().latest();
  }
  ASSERT_TRUE(first_valid.valid);
  EXPECT_EQ(first_valid.collapsing, 1);
  EXPECT_DOUBLE_EQ(first_valid.probability, 0.5);
  EXPECT_EQ(first_valid.worst_member, 1);
  EXPECT_GT(first_valid.collapse_in_s, 0.0);
  EXPECT_LE(first_valid.collapse_in_s, 3.0);
  EXPECT_FALSE(e.member(1).mode().terminal());  // a forecast, not a report
}

// The forecast is the simulator run from the member's state under the window repeated: the
// same collapse time as a direct run of the same continuation.
TEST(Forecaster, EqualsADirectRunOfTheContinuation) {
  const Scene scene = make(paper_block());
  ForecastSettings fs = quick_settings();
  fs.growth = 1.5;
  Statues e({scene}, fs);
  const double amplitude = 0.3 * kStandardGravity;
  std::vector<double> fed;
  for (int n = 0; n < 200; ++n) {
    const double a = amplitude * std::sin(2.0 * std::numbers::pi * 1.5 * n / 200.0);
    fed.push_back(a);
    e.push(a);
  }
  const ForecastOutcome& f = e.forecaster().latest();
  ASSERT_TRUE(f.valid);
  ASSERT_EQ(f.collapsing, 1) << "the test wants a collapse to compare";
  // The last 200 samples, oldest first, repeated, times 1.5.
  std::vector<double> h;
  for (int i = 0; i < 601; ++i) h.push_back(1.5 * fed[static_cast<std::size_t>(i % 200)]);
  std::vector<double> v(h.size(), 0.0);
  SolverSettings solver;
  solver.step = 1.0 / (200.0 * fs.steps_per_period);
  solver.exact_full_contact = true;
  Simulator sim;
  ASSERT_TRUE(Simulator::create(scene,
                                Excitation::record({h.data(), h.size(), 1.0 / 200.0},
                                                   {v.data(), v.size(), 1.0 / 200.0}),
                                solver, sim)
                  .ok());
  sim.start_from(e.member(0).mode(), e.member(0).state());
  while (!sim.mode().terminal() && sim.time() < fs.horizon_s) sim.step();
  ASSERT_TRUE(sim.mode().terminal());
  EXPECT_DOUBLE_EQ(f.collapse_in_s, sim.time());
}

// The work is spread: no sample takes more than its share of steps (plus the one that ends a
// member), and a forecast still completes.
TEST(Forecaster, SpreadsItsWorkOverTheSamples) {
  ForecastSettings fs = quick_settings();
  fs.work_steps_per_s = 20000.0;  // 100 steps per sample at 200 Hz
  Statues e({make(paper_block()), make(paper_block(0.1)), make(paper_isolated())}, fs);
  std::int64_t before = e.forecaster().steps_taken();
  std::int64_t most = 0;
  for (int n = 0; n < 1400; ++n) {
    e.push(0.05 * kStandardGravity * std::sin(n * 0.1));
    most = std::max(most, e.forecaster().steps_taken() - before);
    before = e.forecaster().steps_taken();
  }
  EXPECT_LE(most, 100);
  ASSERT_TRUE(e.forecaster().latest().valid);  // 3 members x 1200 steps = 36 samples each
  EXPECT_EQ(e.forecaster().latest().collapsing, 0);
}

// The strongest window comes back in the forecast, fading with memory_s: after a burst that
// the block survives, the forecast from the calm that follows still overturns it; long after,
// it does not.
TEST(Forecaster, StrongestWindowFadesWithItsMemory) {
  ForecastSettings fs = quick_settings(Continuation::kStrongestWindow);
  fs.memory_s = 5.0;
  fs.growth = 1.5;
  Statues e({make(paper_block())}, fs);
  // One period (1 s) of 0.4 g at 1 Hz: the block rocks and survives it.
  for (int n = 0; n < 200; ++n) {
    e.push(0.4 * kStandardGravity * std::sin(2.0 * std::numbers::pi * n / 200.0));
  }
  bool forecast_collapse_while_calm = false;
  int n = 0;
  for (; n < 200 * 4; ++n) {
    e.push(0.0);
    if (e.member(0).mode().phase == Phase::kFullContact && e.forecaster().latest().collapsing > 0) {
      forecast_collapse_while_calm = true;
    }
  }
  ASSERT_FALSE(e.member(0).mode().terminal());
  EXPECT_TRUE(forecast_collapse_while_calm);
  for (; n < 200 * 25; ++n) e.push(0.0);
  EXPECT_EQ(e.forecaster().latest().collapsing, 0);  // 0.6 g exp(-25 / 10): 0.05 g
}

TEST(Forecaster, ARestartForgetsTheMotionAndTheForecast) {
  Statues e({make(paper_block())}, quick_settings());
  for (int n = 0; n < 300; ++n) e.push(0.0);
  ASSERT_TRUE(e.forecaster().latest().valid);
  e.ensemble.restart({});
  EXPECT_FALSE(e.forecaster().latest().valid);
  EXPECT_FALSE(e.forecaster().running());
}

TEST(Forecaster, DisabledDoesNothing) {
  ForecastSettings fs = quick_settings();
  fs.enabled = false;
  Statues e({make(paper_block())}, fs);
  for (int n = 0; n < 400; ++n) e.push(0.0);
  EXPECT_FALSE(e.forecaster().latest().valid);
  EXPECT_EQ(e.forecaster().steps_taken(), 0);
}

TEST(ForecastSettings, RefusesWhatCannotWork) {
  const auto field = [](ForecastSettings s, double rate = 200.0) {
    return std::string(validate(s, rate).field);
  };
  EXPECT_EQ(field(ForecastSettings{}), "");
  ForecastSettings s;
  s.horizon_s = 0.0;
  EXPECT_EQ(field(s), "forecast.horizon_s");
  s = {};
  s.horizon_s = std::nan("");
  EXPECT_EQ(field(s), "forecast.horizon_s");
  s = {};
  s.window_s = 0.1;
  EXPECT_EQ(field(s), "forecast.window_s");
  s = {};
  s.window_s = 6.0;  // 1200 samples at 200 Hz
  EXPECT_EQ(field(s), "forecast.window_s");
  s = {};
  s.horizon_s = 10.0;
  s.window_s = 1.0;
  s.rate_hz = 1000.0;  // 10001 samples
  EXPECT_EQ(field(s, 1000.0), "forecast.horizon_s");
  s = {};
  s.growth = 5.0;
  EXPECT_EQ(field(s), "forecast.growth");
  s = {};
  s.steps_per_period = 0;
  EXPECT_EQ(field(s), "forecast.steps_per_period");
  s = {};
  s.work_steps_per_s = 10.0;
  EXPECT_EQ(field(s), "forecast.work_steps_per_s");
  s = {};
  s.interval_s = -1.0;
  EXPECT_EQ(field(s), "forecast.interval_s");
  s = {};
  s.continuation = static_cast<Continuation>(7);
  EXPECT_EQ(field(s), "forecast.continuation");
  s = {};
  s.rate_hz = 10.0;
  EXPECT_EQ(field(s), "forecast.rate_hz");
}

// The continuation's rate follows the input's by whole ratios: 1000 Hz input averaged 5 to 1.
TEST(Forecaster, AveragesAFasterInputDown) {
  ForecastSettings fs = quick_settings();
  Forecaster f;
  ASSERT_TRUE(f.start(fs, 1000.0).ok());
  const Scene scene = make(paper_block());
  EstimatorSettings es;
  es.sample_rate_hz = 1000.0;
  es.steps_per_sample = 1;
  std::vector<PlanarEstimator> members(1);
  ASSERT_TRUE(members[0].start(scene, es, {}).ok());
  for (int n = 0; n < 999; ++n) {
    members[0].push({});
    f.on_sample({}, members[0].time(), members);
  }
  EXPECT_FALSE(f.latest().valid);  // 999 input samples: 199 window samples
  for (int n = 0; n < 5; ++n) {
    members[0].push({});
    f.on_sample({}, members[0].time(), members);
  }
  EXPECT_TRUE(f.latest().valid);
}

}  // namespace
}  // namespace plinth

// The real-time estimator (estimator.h) and the overturning risk (risk.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "bundled_records.h"
#include "plinth/core/estimator.h"
#include "plinth/core/risk.h"
#include "plinth/core/stability.h"
#include "plinth/host/record_io.h"
#include "plinth/host/scene_toml.h"
#include "test_paths.h"
#include "test_support.h"

namespace plinth {
namespace {

using testing::RecordingSink;

using ::plinth::testing::kSource;

using testing::brienza;

// The estimator fed sample by sample gives what the simulator gives on the whole record at the
// same step: the same events at the same times, the same state at the end.
void expect_same_as_simulator(const Scene& scene, const host::Record& record, double gamma,
                              int steps_per_sample) {
  const double rate = 1.0 / record.dt;
  EstimatorSettings settings;
  settings.sample_rate_hz = rate;
  settings.steps_per_sample = steps_per_sample;

  RecordingSink reference;
  const Excitation excitation = Excitation::record(record.horizontal_signal(), {}, gamma);
  SolverSettings solver;
  solver.step = settings.step();
  Simulator sim;
  ASSERT_TRUE(Simulator::create(scene, excitation, solver, sim).ok());
  sim.set_event_sink(&reference);
  sim.start_at_rest();

  RecordingSink estimated;
  PlanarEstimator estimator;
  ASSERT_TRUE(estimator.start(scene, settings, {gamma * record.horizontal[0], 0.0}).ok());
  estimator.set_event_sink(&estimated);
  for (std::size_t n = 1; n < record.horizontal.size(); ++n) {
    estimator.push({gamma * record.horizontal[n], 0.0});
    for (int i = 0; i < steps_per_sample; ++i) sim.step();
    ASSERT_EQ(estimator.mode().phase, sim.mode().phase) << "t = " << sim.time();
    if (sim.mode().terminal()) break;
  }
  ASSERT_GT(reference.events.size(), 2U);
  ASSERT_EQ(estimated.events.size(), reference.events.size());
  for (std::size_t i = 0; i < reference.events.size(); ++i) {
    EXPECT_EQ(estimated.events[i].kind, reference.events[i].kind) << i;
    EXPECT_NEAR(estimated.events[i].t, reference.events[i].t, 1e-9) << i;
  }
  for (Eigen::Index k = 0; k < 6; ++k) {
    EXPECT_NEAR(estimator.state()[k], sim.state()[k], 1e-9 * (1.0 + std::fabs(sim.state()[k])));
  }
}

TEST(Estimator, SameEventsAsTheSimulatorOnTheSameSamples) {
  const host::Record record = brienza();  // dt = 0.0025 s: 400 Hz
  // Rocking, impacts and overturning on the base.
  expect_same_as_simulator(testing::make(testing::paper_isolated(0.0)), record, 30.0, 2);
  // Sliding, slide-rocking, base stops, the support's edge (docs/fig14.md, kind c).
  const Scene fig14c =
      host::load_scene_file(kSource + "/sim/scenes/fig14c-slide-rocking-base-stops.toml");
  expect_same_as_simulator(fig14c, record, 2.3 * kStandardGravity / record.peak_horizontal(), 4);
}

TEST(Estimator, RefusesBadSettingsNamingTheField) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  PlanarEstimator estimator;
  EstimatorSettings settings;
  settings.sample_rate_hz = 50.0;
  EXPECT_STREQ(estimator.start(scene, settings, {}).field, "estimator.sample_rate_hz");
  settings.sample_rate_hz = std::nan("");
  EXPECT_STREQ(estimator.start(scene, settings, {}).field, "estimator.sample_rate_hz");
  settings.sample_rate_hz = 200.0;
  settings.steps_per_sample = 0;
  EXPECT_STREQ(estimator.start(scene, settings, {}).field, "estimator.steps_per_sample");
  settings.steps_per_sample = 4;
  EXPECT_STREQ(estimator.start(scene, settings, {std::nan(""), 0.0}).field, "sample");
  EXPECT_FALSE(estimator.started());
  // A stiff, light base: 100 Hz with one step is unstable; the error names the steps per
  // sample with their limit, the fewest that are stable, and that many are.
  SceneParams stiff = testing::paper_isolated(0.0, 0.02);
  stiff.base.mass *= 0.01;
  const Scene stiff_scene = testing::make(stiff);
  settings.sample_rate_hz = 100.0;
  settings.steps_per_sample = 1;
  const Error e = estimator.start(stiff_scene, settings, {});
  EXPECT_STREQ(e.field, "estimator.steps_per_sample");
  EXPECT_NEAR(e.limit, 0.01 / largest_stable_step(stiff_scene), 1e-9);
  ASSERT_LE(std::ceil(e.limit), 64.0);
  settings.steps_per_sample = static_cast<int>(std::ceil(e.limit)) - 1;
  EXPECT_STREQ(estimator.start(stiff_scene, settings, {}).field, "estimator.steps_per_sample");
  settings.steps_per_sample = static_cast<int>(std::ceil(e.limit));
  EXPECT_TRUE(estimator.start(stiff_scene, settings, {}).ok());
  // Each stepper's own limit (semi-implicit Euler's is below RK4's for this damped base: it
  // needs 68 steps per sample, more than the 64 the box takes: plinth-monitor then names the
  // scene's base.period).
  settings.solver.stepper = Stepper::kSemiImplicitEuler;
  settings.steps_per_sample = 1;
  const Error euler = estimator.start(stiff_scene, settings, {});
  EXPECT_STREQ(euler.field, "estimator.steps_per_sample");
  EXPECT_NEAR(euler.limit, 0.01 / largest_stable_step(stiff_scene, Stepper::kSemiImplicitEuler),
              1e-9);
  EXPECT_GT(std::ceil(euler.limit), 64.0);
  // A base no step count makes stable (T = 20 us): the count it would need, far beyond 64.
  settings.solver.stepper = Stepper::kRk4Located;
  const Scene rigid = testing::make(testing::paper_isolated(0.0, 2e-5));
  const Error base = estimator.start(rigid, settings, {});
  EXPECT_STREQ(base.field, "estimator.steps_per_sample");
  EXPECT_NEAR(base.limit, 0.01 / largest_stable_step(rigid), 1e-9 * base.limit);
}

TEST(Risk, ZeroAtRestOneAtCollapse) {
  const Scene s = testing::make(testing::paper_isolated(0.0));
  EXPECT_EQ(overturning_risk(s, Mode{}, State::Zero()).total, 0.0);
  Mode over;
  over.phase = Phase::kOverturned;
  EXPECT_EQ(overturning_risk(s, over, State::Zero()).total, 1.0);
  EXPECT_EQ(overturning_risk(s, over, State::Zero()).overturning, 1.0);
  Mode fell;
  fell.phase = Phase::kFell;
  EXPECT_EQ(overturning_risk(s, fell, State::Zero()).falling, 1.0);
}

// Rocking: the energy ratio; at rest at angle theta it is the potential energy's share of the
// barrier, (h'(theta) - h) / (r - h); at the critical angle it is 1.
TEST(Risk, RockingIsTheEnergyAgainstTheBarrier) {
  const Scene s = testing::make(testing::paper_isolated(0.2));
  Mode mode;
  mode.phase = Phase::kRocking;
  for (const Corner corner : {Corner::kLeft, Corner::kRight}) {
    mode.corner = corner;
    const CornerGeometry& c = s.corner(corner);
    State y = State::Zero();
    y[kTheta] = 0.5 * c.sign * c.critical_angle;
    const double h_arm = c.offset * std::sin(y[kTheta]) + s.h * std::cos(y[kTheta]);
    EXPECT_NEAR(overturning_risk(s, mode, y).overturning, (h_arm - s.h) / (c.radius - s.h), 1e-12);
    y[kTheta] = c.sign * c.critical_angle;
    EXPECT_NEAR(overturning_risk(s, mode, y).total, 1.0, 1e-12);
    // From theta = 0 with the rate that just reaches the critical angle on fixed ground.
    y[kTheta] = 0.0;
    y[kThetaDot] = -c.sign * std::sqrt(2.0 * s.m * s.g * (c.radius - s.h) / c.inertia);
    EXPECT_NEAR(overturning_risk(s, mode, y).total, 1.0, 1e-12);
    y[kThetaDot] *= std::sqrt(0.3);
    EXPECT_NEAR(overturning_risk(s, mode, y).total, 0.3, 1e-12);
  }
}

// Sliding towards the support's edge: the stopping distance against what is left.
TEST(Risk, SlidingTowardsTheEdge) {
  SceneParams p = testing::paper_isolated(0.0);
  p.has_friction = true;
  p.friction = {0.4, 0.3};
  p.has_support = true;
  p.support = {0.1};
  const Scene s = testing::make(p);
  Mode mode;
  mode.phase = Phase::kSliding;
  mode.slide_direction = 1;
  State y = State::Zero();
  y[kXDot] = 0.5;
  const double stopping = 0.25 / (2.0 * 0.3 * s.g);
  EXPECT_NEAR(overturning_risk(s, mode, y).falling, stopping / (0.1 + s.b2), 1e-12);
  y[kXDot] = -0.5;  // moving the other way: the same against the left edge
  mode.slide_direction = -1;
  EXPECT_NEAR(overturning_risk(s, mode, y).falling, stopping / (0.1 + s.b1), 1e-12);
  // Over the edge at rest: the share of C's distance to the edge used.
  Mode still;
  still.overhang = 1;
  State over = State::Zero();
  over[kX] = 0.1 + 0.25 * s.b2;
  EXPECT_NEAR(overturning_risk(s, still, over).falling, 0.25, 1e-12);
  // With sliding stops the block cannot fall.
  p.has_sliding_stops = true;
  p.sliding_stops = {0.7};
  EXPECT_EQ(overturning_risk(testing::make(p), mode, y).falling, 0.0);
}

TEST(Risk, BaseStopsWeighted) {
  SceneParams p = testing::paper_isolated(0.0);
  p.has_base_stops = true;
  p.base_stops = {0.2, 0.7};
  const Scene s = testing::make(p);
  State y = State::Zero();
  y[kU] = 0.1;
  EXPECT_NEAR(overturning_risk(s, Mode{}, y).base_stops, 0.5 * 0.5, 1e-12);
  EXPECT_NEAR(overturning_risk(s, Mode{}, y, {1.0}).total, 0.5, 1e-12);
  y[kU] = 0.3;
  EXPECT_NEAR(overturning_risk(s, Mode{}, y).total, 0.5, 1e-12);
  EXPECT_FALSE(validate(RiskSettings{1.5}).ok());
  EXPECT_FALSE(validate(RiskSettings{std::nan("")}).ok());
}

// The risk leads the collapse: on Brienza scaled past overturning, it crosses 0.5 and 0.8
// before the block overturns, and reaches 1 at the overturn.
TEST(Risk, LeadsTheOverturn) {
  const Scene s = testing::make(testing::paper_isolated(0.0));
  const host::Record record = brienza();
  EstimatorSettings settings;
  settings.sample_rate_hz = 1.0 / record.dt;
  PlanarEstimator estimator;
  const double gamma = 20.0;
  ASSERT_TRUE(estimator.start(s, settings, {gamma * record.horizontal[0], 0.0}).ok());
  double crossed_half = -1.0;
  double crossed_08 = -1.0;
  for (std::size_t n = 1; n < record.horizontal.size() && !estimator.mode().terminal(); ++n) {
    estimator.push({gamma * record.horizontal[n], 0.0});
    const double r = overturning_risk(s, estimator.mode(), estimator.state()).total;
    if (crossed_half < 0.0 && r >= 0.5) crossed_half = estimator.time();
    if (crossed_08 < 0.0 && r >= 0.8) crossed_08 = estimator.time();
  }
  ASSERT_EQ(estimator.mode().phase, Phase::kOverturned);
  ASSERT_GT(crossed_half, 0.0);
  EXPECT_LT(crossed_half, estimator.time() - 0.05);
  EXPECT_LE(crossed_half, crossed_08);
  EXPECT_LT(crossed_08, estimator.time());
  EXPECT_EQ(overturning_risk(s, estimator.mode(), estimator.state()).total, 1.0);
}

}  // namespace
}  // namespace plinth

namespace plinth {
namespace {

// How long before the collapse the risk crosses each alarm policy's "on" threshold
// (advisory 0.1, warning 0.5, alarm 0.8; monitor/alarm_policy.h), on every bundled record
// scaled just past the collapse of three scenes (overturning on the base, overturning on the
// ground, falling off the base). Printed as the table of docs/monitor.md.
struct LeadTimes {
  double gamma = 0.0;
  double collapse_t = -1.0;
  Phase collapse = Phase::kFullContact;
  double crossed[3] = {-1.0, -1.0, -1.0};
};

LeadTimes lead_times(const Scene& scene, const host::Record& record, double gamma) {
  LeadTimes r;
  r.gamma = gamma;
  SolverSettings solver;
  solver.step = std::fmin(record.dt / 4.0, 1e-3);
  Simulator sim;
  const Excitation ex = Excitation::record(record.horizontal_signal(), {}, gamma);
  if (!Simulator::create(scene, ex, solver, sim).ok()) return r;
  sim.start_at_rest();
  const double thresholds[3] = {0.1, 0.5, 0.8};
  while (sim.time() < record.duration() && !sim.mode().terminal()) {
    sim.step();
    const double risk = overturning_risk(scene, sim.mode(), sim.state()).total;
    for (int k = 0; k < 3; ++k) {
      if (r.crossed[k] < 0.0 && risk >= thresholds[k]) r.crossed[k] = sim.time();
    }
  }
  if (sim.mode().terminal()) {
    r.collapse_t = sim.time();
    r.collapse = sim.mode().phase;
  }
  return r;
}

TEST(Risk, LeadsTheCollapseOnEveryBundledRecord) {
  const std::vector<std::string> records = {
      "irpinia1980_brienza_000", "irpinia1980_brienza_270", "irpinia1980_calitri_000",
      "irpinia1980_calitri_270", "irpinia1980_bagnoli_000", "irpinia1980_bagnoli_270",
      "friuli1976-09-15_buia_000", "friuli1976-09-15_buia_270", "friuli1976-09-11_buia_NS",
      "elcentro1940_180"};
  const std::vector<std::pair<std::string, std::string>> scenes = {
      {"paper-isolated", kSource + "/sim/scenes/paper-isolated.toml"},
      {"non-isolated", kSource + "/sim/scenes/non-isolated.toml"},
      {"fig14c (falls)", kSource + "/sim/scenes/fig14c-slide-rocking-base-stops.toml"}};
  std::printf("| scene | record | PGA (g) | collapse | at (s) | lead of risk 0.1 | 0.5 | 0.8 |\n"
              "|---|---|---|---|---|---|---|---|\n");
  int collapses = 0;
  for (const auto& [scene_name, scene_path] : scenes) {
    const Scene scene = host::load_scene_file(scene_path);
    for (const std::string& name : records) {
      const host::Record record =
          host::read_at2(kSource + "/sim/data/records/" + name + ".AT2", kStandardGravity);
      // Just past the collapse: a 25 % PGA grid from 0.1 g to 6 g, then four bisections of the
      // first interval that collapses (to within 1.5 %).
      const auto at = [&](double pga_g) {
        return lead_times(scene, record, pga_g * kStandardGravity / record.peak_horizontal());
      };
      LeadTimes r;
      double low = 0.0;
      double high = 0.1;
      for (; high <= 6.0; low = high, high *= 1.25) {
        r = at(high);
        if (r.collapse_t >= 0.0) break;
      }
      if (r.collapse_t < 0.0) continue;
      for (int i = 0; i < 4 && low > 0.0; ++i) {
        const double mid = 0.5 * (low + high);
        const LeadTimes m = at(mid);
        if (m.collapse_t >= 0.0) {
          high = mid;
          r = m;
        } else {
          low = mid;
        }
      }
      ++collapses;
      std::printf("| %s | %s | %.3f | %s | %.3f |", scene_name.c_str(), name.c_str(),
                  r.gamma * record.peak_horizontal() / kStandardGravity,
                  phase_name(r.collapse), r.collapse_t);
      for (int k = 0; k < 3; ++k) {
        // Every threshold is crossed, and no later than the collapse itself.
        EXPECT_GE(r.crossed[k], 0.0) << scene_name << " " << name << " threshold " << k;
        EXPECT_LE(r.crossed[k], r.collapse_t) << scene_name << " " << name;
        std::printf(" %.3f |", r.collapse_t - r.crossed[k]);
      }
      std::printf("\n");
      // The warning comes before the collapse, not with it.
      EXPECT_GT(r.collapse_t - r.crossed[1], 0.0) << scene_name << " " << name;
    }
  }
  EXPECT_GE(collapses, 25);
}

}  // namespace
}  // namespace plinth

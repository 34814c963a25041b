// The isolated system: impact maps (Eqs 21-24), base stops (Eqs 28-29), energy and momentum.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "bundled_records.h"
#include "plinth/core/energy.h"
#include "plinth/core/internal/resets.h"
#include "plinth/host/record_io.h"
#include "test_support.h"

namespace plinth {
namespace {

using internal::base_stop_hold_reset;
using internal::base_stop_reset;
using internal::impact_velocity_ratio;
using internal::lever_arms;
using internal::LeverArms;
using internal::opposite;
using internal::rocking_impact_reset;
using testing::make;
using testing::paper_isolated;
using testing::RecordingSink;

// Velocity of C, (horizontal, vertical), for rocking about `c` at theta, from Eq 6.
Eigen::Vector2d centre_velocity(const Scene& s, const CornerGeometry& c, const State& y) {
  const LeverArms arm = lever_arms(s, c, y[kTheta]);
  return {y[kUDot] - arm.vertical * y[kThetaDot], arm.horizontal * y[kThetaDot]};
}

// Angular momentum of the block about the point where corner `about` is, and the horizontal
// momentum of block and base, computed from the kinematics alone.
struct Momenta {
  double angular;
  double horizontal;
};

Momenta momenta(const Scene& s, const CornerGeometry& pivot, const CornerGeometry& about,
                const State& y) {
  const Eigen::Vector2d v = centre_velocity(s, pivot, y);
  const LeverArms r = lever_arms(s, about, y[kTheta]);  // C relative to `about`
  return {s.inertia_c * y[kThetaDot] + s.m * (r.horizontal * v.y() - r.vertical * v.x()),
          s.m * v.x() + (s.total_mass - s.m) * y[kUDot]};
}

// The corrected Eqs 21-22: the impact map conserves the block's angular momentum about the
// new corner and the horizontal momentum of block and base.
TEST(ImpactReset, ConservesAngularAndHorizontalMomentum) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> speed(-2.0, 2.0);
  for (const double epsilon : {0.0, 0.35, -0.6}) {
    for (const double mass_ratio : {0.05, 1.0, 20.0}) {
      SceneParams p = paper_isolated(epsilon);
      p.base.mass = mass_ratio * p.block.mass;
      const Scene s = make(p);
      for (const Corner from : {Corner::kLeft, Corner::kRight}) {
        Mode mode;
        mode.phase = Phase::kRocking;
        mode.corner = from;
        State y = State::Zero();
        y[kUDot] = speed(rng);
        y[kThetaDot] = -s.corner(from).sign * std::fabs(speed(rng));  // returning to theta = 0
        const CornerGeometry& to = s.corner(opposite(from));
        const Momenta before = momenta(s, s.corner(from), to, y);
        rocking_impact_reset(s, true, mode, y);
        ASSERT_EQ(mode.corner, opposite(from));
        const Momenta after = momenta(s, to, to, y);
        EXPECT_NEAR(after.angular, before.angular, 1e-9 * std::fabs(before.angular) + 1e-9);
        EXPECT_NEAR(after.horizontal, before.horizontal,
                    1e-9 * std::fabs(before.horizontal) + 1e-9);
      }
    }
  }
}

// The printed Eq 23 (with r_1 sin(alpha_1) = b_1) is our ratio; the printed Eq 24 has the
// opposite sign to the one Eqs 6-8 imply (it follows the +m h u' of the printed Eqs 21-22).
TEST(ImpactReset, PrintedEq23HoldsAndEq24HasTheOppositeSign) {
  const Scene s = make(paper_isolated(0.3));
  const double m = s.m, h = s.h, mt = s.total_mass, i1 = s.corner1.inertia, i2 = s.corner2.inertia;
  const double r1_sin_a1 = s.corner1.radius * std::sin(s.corner1.critical_angle);
  const double eq23 = (m * m * h * h - i1 * mt + 2.0 * m * s.b * r1_sin_a1 * mt) /
                      (m * m * h * h - i2 * mt);
  EXPECT_NEAR(impact_velocity_ratio(s, Corner::kRight, true), eq23, 1e-14);
  const double theta_dot = -0.4;
  const double eq24_delta_u_dot =
      h * m * (i1 - i2 - 2.0 * s.b * m * r1_sin_a1) / (h * h * m * m - i2 * mt) * theta_dot;
  Mode mode;
  mode.phase = Phase::kRocking;
  State y = State::Zero();
  y[kThetaDot] = theta_dot;
  rocking_impact_reset(s, true, mode, y);
  EXPECT_NEAR(y[kUDot], -eq24_delta_u_dot, 1e-14);
  EXPECT_GT(y[kUDot], 0.0) << "the block loses rightward momentum, the base gains it";
}

// Energy never grows across a reset: impacts at theta = 0, base stops (Eq 29 with the
// consistent theta' change) and holding the base.
TEST(Resets, EnergyNeverGrows) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  SceneParams p = paper_isolated(0.2);
  p.has_base_stops = true;
  for (const double eta : {0.0, 0.5, 1.0}) {
    p.base_stops = {0.2, eta};
    const Scene s = make(p);
    for (int i = 0; i < 2000; ++i) {
      Mode mode;
      mode.phase = Phase::kRocking;
      mode.corner = unit(rng) > 0.0 ? Corner::kLeft : Corner::kRight;
      const double sign = s.corner(mode.corner).sign;
      State y = State::Zero();
      y[kU] = 0.2;
      y[kUDot] = 2.0 * std::fabs(unit(rng));  // towards the right stop
      y[kTheta] = sign * 0.3 * std::fabs(unit(rng));
      y[kThetaDot] = 2.0 * unit(rng);
      const double before = mechanical_energy(s, mode, y);
      State hit = y;
      base_stop_reset(s, +1, mode, hit);
      EXPECT_LE(mechanical_energy(s, mode, hit), before + 1e-12 * std::fabs(before));
      EXPECT_DOUBLE_EQ(hit[kUDot], -eta * y[kUDot]);  // Eq 29
      State held = y;
      Mode held_mode = mode;
      base_stop_hold_reset(s, +1, held_mode, held);
      EXPECT_LE(mechanical_energy(s, held_mode, held), before + 1e-12 * std::fabs(before));
      State impact = y;
      impact[kTheta] = 0.0;
      impact[kThetaDot] = -sign * std::fabs(y[kThetaDot]);
      Mode impact_mode = mode;
      const double before_impact = mechanical_energy(s, impact_mode, impact);
      rocking_impact_reset(s, true, impact_mode, impact);
      EXPECT_LE(mechanical_energy(s, impact_mode, impact), before_impact);
    }
  }
}

// Why Eq 29 needs the theta' change: keeping theta' while u' reverses can create energy.
TEST(Resets, PrintedEq29WithThetaDotUnchangedCanCreateEnergy) {
  SceneParams p = paper_isolated(0.0);
  p.has_base_stops = true;
  p.base_stops = {0.2, 1.0};
  const Scene s = make(p);
  Mode mode;
  mode.phase = Phase::kRocking;
  State y = State::Zero();
  y[kU] = 0.2;
  y[kUDot] = 1.0;
  y[kTheta] = 0.05;
  y[kThetaDot] = 1.0;
  const double before = mechanical_energy(s, mode, y);
  State printed = y;
  printed[kUDot] = -y[kUDot];
  EXPECT_GT(mechanical_energy(s, mode, printed), before * 1.1);
  State ours = y;
  base_stop_reset(s, +1, mode, ours);
  EXPECT_NEAR(mechanical_energy(s, mode, ours), before, 1e-9 * before);  // eta = 1: elastic
}

using testing::brienza;

// Eq 28: the base never passes its stops, and each hit reverses u' by eta_i (Eq 29).
TEST(BaseStops, BoundTheBaseAndReverseItsVelocity) {
  const host::Record record = brienza();
  for (const double eta : {0.7, 0.0}) {
    SceneParams p = paper_isolated(0.0);
    p.has_base_stops = true;
    p.base_stops = {0.08, eta};
    const Scene s = make(p);
    RecordingSink sink;
    SolverSettings settings;
    Simulator sim;
    const Excitation ex =
        Excitation::record(record.horizontal_signal(), {}, kStandardGravity / record.peak_horizontal());
    ASSERT_TRUE(Simulator::create(s, ex, settings, sim).ok());
    sim.set_event_sink(&sink);
    sim.start_at_rest();
    while (sim.time() < 30.0 && !sim.mode().terminal()) {
      sim.step();
      ASSERT_LE(std::fabs(sim.state()[kU]), 0.08 + 1e-12) << "t = " << sim.time();
    }
    ASSERT_GE(sink.count(EventKind::kBaseStopHit), 2) << "eta = " << eta;
    for (const Event& e : sink.events) {
      if (e.kind != EventKind::kBaseStopHit) continue;
      EXPECT_DOUBLE_EQ(e.after, -eta * e.before);
      EXPECT_GT(e.side * e.before, 0.0) << "the base moves into the stop it hits";
    }
    if (eta == 0.0) {
      // A plastic stop holds the base until the ground pulls it away again.
      EXPECT_GE(sink.count(EventKind::kBaseStopHeld), 1);
      EXPECT_GE(sink.count(EventKind::kBaseStopReleased), 1);
    }
    EXPECT_EQ(sim.chatter_steps(), 0);
  }
}

// The rest criterion ends rocking in a finite number of impacts and steps (no Zeno loop).
TEST(RestCriterion, FreeRockingOnTheBaseComesToRest) {
  const Scene s = make(paper_isolated(0.1, 2.0, 0.0));
  RecordingSink sink;
  SolverSettings settings;
  settings.step = 1e-3;
  Simulator sim;
  ASSERT_TRUE(Simulator::create(s, Excitation::none(), settings, sim).ok());
  sim.set_event_sink(&sink);
  Mode mode;
  mode.phase = Phase::kRocking;
  State y = State::Zero();
  y[kTheta] = 0.15;
  sim.start_from(mode, y);
  while (sim.mode().phase != Phase::kFullContact && sim.time() < 60.0) sim.step();
  EXPECT_EQ(sim.mode().phase, Phase::kFullContact);
  ASSERT_NE(sink.first(EventKind::kRockingStop), nullptr);
  EXPECT_LT(sink.count(EventKind::kImpact), 200);
  // It stopped at the first impact that left less than the documented fraction of the
  // overturning energy (SolverSettings::rest_energy_ratio).
  const Event& stop = *sink.first(EventKind::kRockingStop);
  const Corner to = opposite(stop.corner);
  const double after = impact_velocity_ratio(s, to, true) * stop.before;
  const double threshold = settings.rest_energy_ratio * overturning_energy(s, to);
  EXPECT_LT(0.5 * s.corner(to).inertia * after * after, threshold);
  const Event& last_impact = sink.events[sink.events.size() - 2];
  ASSERT_EQ(last_impact.kind, EventKind::kImpact);
  EXPECT_GE(0.5 * s.corner(last_impact.corner).inertia * last_impact.after * last_impact.after,
            settings.rest_energy_ratio * overturning_energy(s, last_impact.corner));
  EXPECT_EQ(stop.state[kThetaDot], 0.0);
  EXPECT_EQ(stop.state[kTheta], 0.0);
}

}  // namespace
}  // namespace plinth

// A block on fixed ground (no base): Housner's results, onset, energy and mirror symmetry.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "bundled_records.h"
#include "plinth/core/closed_forms.h"
#include "plinth/core/energy.h"
#include "plinth/core/internal/resets.h"
#include "plinth/host/record_io.h"
#include "test_support.h"

namespace plinth {
namespace {

using internal::impact_velocity_ratio;
using internal::opposite;
using testing::make;
using testing::paper_block;
using testing::RecordingSink;

Simulator free_rocking(const Scene& s, double theta0, double dt, EventSink* sink) {
  SolverSettings settings;
  settings.step = dt;
  Simulator sim;
  if (!Simulator::create(s, Excitation::none(), settings, sim).ok()) __builtin_trap();
  sim.set_event_sink(sink);
  Mode mode;
  mode.phase = Phase::kRocking;
  mode.corner = theta0 > 0.0 ? Corner::kLeft : Corner::kRight;
  State y = State::Zero();
  y[kTheta] = theta0;
  sim.start_from(mode, y);
  return sim;
}

TEST(Housner, ImpactVelocityRatioOfASymmetricBlock) {
  const Scene s = make(paper_block(0.0));
  RecordingSink sink;
  Simulator sim = free_rocking(s, 0.1, 1e-3, &sink);
  while (sink.first(EventKind::kImpact) == nullptr && sim.time() < 5.0 && !sim.mode().terminal()) {
    sim.step();
  }
  const Event* impact = sink.first(EventKind::kImpact);
  ASSERT_NE(impact, nullptr);
  EXPECT_EQ(impact->corner, Corner::kRight);
  EXPECT_NEAR(impact->after / impact->before, housner_velocity_ratio(std::atan(1.0 / 3.0)),
              1e-12);
  EXPECT_NEAR(impact->after / impact->before, 0.85, 1e-12);
}

// For an eccentric block on the ground, Eq 23 with m_b -> infinity:
// theta'+/theta'- = (I_1 - 2 m b b_1) / I_2 from corner 1 to corner 2, and the mirror.
TEST(Housner, ImpactVelocityRatioOfAnEccentricBlockIsEq23WithoutBase) {
  const Scene s = make(paper_block(0.35));
  const double to_right = (s.corner1.inertia - 2.0 * s.m * s.b * s.b1) / s.corner2.inertia;
  const double to_left = (s.corner2.inertia - 2.0 * s.m * s.b * s.b2) / s.corner1.inertia;
  EXPECT_NEAR(impact_velocity_ratio(s, Corner::kRight, false), to_right, 1e-14);
  EXPECT_NEAR(impact_velocity_ratio(s, Corner::kLeft, false), to_left, 1e-14);
  RecordingSink sink;
  Simulator sim = free_rocking(s, 0.03, 1e-3, &sink);
  while (sink.count(EventKind::kImpact) < 2 && sim.time() < 5.0 && !sim.mode().terminal()) {
    sim.step();
  }
  ASSERT_EQ(sink.count(EventKind::kImpact), 2);
  EXPECT_NEAR(sink.events[0].after / sink.events[0].before, to_right, 1e-12);
  EXPECT_NEAR(sink.events[1].after / sink.events[1].before, to_left, 1e-12);
}

// Rocking starts on fixed ground exactly when u_G'' reaches g b_1 / h (or -g b_2 / h).
TEST(Housner, RockingStartsWhenGroundAccelerationReachesGb1OverH) {
  const Scene s = make(paper_block(0.2));
  const double period = 0.5;
  for (const double sign : {1.0, -1.0}) {
    const Corner corner = sign > 0.0 ? Corner::kLeft : Corner::kRight;
    const double threshold = s.g * s.corner(corner).onset_ratio;  // g b_i / h
    const double amplitude = sign * 1.5 * threshold;
    RecordingSink sink;
    testing::run(s, Excitation::sine_pulse(amplitude, period), 0.3, 1e-3, &sink);
    const Event* onset = sink.first(EventKind::kRockingStart);
    ASSERT_NE(onset, nullptr);
    EXPECT_EQ(onset->corner, corner);
    const double expected = period / (2.0 * std::numbers::pi) * std::asin(1.0 / 1.5);
    EXPECT_NEAR(onset->t, expected, 1e-12);
    // Just below the threshold the block stays in full contact through the pulse's first half
    // (the second half may rock it about the other, weaker or stronger, corner).
    RecordingSink quiet;
    testing::run(s, Excitation::sine_pulse(sign * 0.999 * threshold, period), 0.5 * period, 1e-3,
                 &quiet);
    EXPECT_TRUE(quiet.events.empty());
  }
}

// Undamped free rocking keeps its energy between impacts; at theta = 0 all of it is kinetic,
// I_i theta'^2 / 2, so an impact scales it by (I_to / I_from) (theta'+ / theta'-)^2.
TEST(Housner, FreeRockingConservesEnergyBetweenImpacts) {
  const Scene s = make(paper_block(0.1));
  RecordingSink sink;
  Simulator sim = free_rocking(s, 0.2, 1e-4, &sink);
  double energy = rocking_energy(s, sim.mode(), sim.state());
  std::size_t seen = 0;
  int impacts = 0;
  while (impacts < 6 && sim.time() < 30.0) {
    sim.step();
    const double now = rocking_energy(s, sim.mode(), sim.state());
    if (sink.events.size() == seen) {
      EXPECT_NEAR(now, energy, 1e-10 * energy) << "t = " << sim.time();
    } else {
      const Event& e = sink.events.back();
      ASSERT_EQ(e.kind, EventKind::kImpact);
      const double ratio = e.after / e.before;
      const double inertia_ratio =
          s.corner(e.corner).inertia / s.corner(opposite(e.corner)).inertia;
      EXPECT_NEAR(now, energy * inertia_ratio * ratio * ratio, 1e-9 * energy)
          << "impact at t = " << e.t;
      seen = sink.events.size();
      ++impacts;
    }
    energy = now;
  }
}

// The response to (epsilon, input) mirrored is the response mirrored.
TEST(Housner, MirroredSceneAndInputGiveTheMirroredResponse) {
  const host::Record record = testing::brienza();
  const double gamma = 1.0 * kStandardGravity / record.peak_horizontal();
  for (const bool isolated : {false, true}) {
    SceneParams p = isolated ? testing::paper_isolated(0.3, 1.0) : paper_block(0.3);
    if (isolated) {
      p.has_base_stops = true;
      p.base_stops = {0.05, 0.7};
    }
    SceneParams q = p;
    q.block.eccentricity = -p.block.eccentricity;
    const Scene s = make(p);
    const Scene mirrored = make(q);
    RecordingSink a;
    RecordingSink b;
    const Simulator sa =
        testing::run(s, Excitation::record(record.horizontal_signal(), {}, gamma), 20.0, 1e-4, &a);
    const Simulator sb = testing::run(
        mirrored, Excitation::record(record.horizontal_signal(), {}, -gamma), 20.0, 1e-4, &b);
    ASSERT_GT(a.events.size(), 3U) << "the run must exercise events";
    ASSERT_EQ(a.events.size(), b.events.size());
    for (std::size_t i = 0; i < a.events.size(); ++i) {
      EXPECT_EQ(a.events[i].kind, b.events[i].kind);
      EXPECT_NEAR(a.events[i].t, b.events[i].t, 1e-12);
      if (a.events[i].kind == EventKind::kRockingStart || a.events[i].kind == EventKind::kImpact ||
          a.events[i].kind == EventKind::kOverturned) {
        EXPECT_EQ(a.events[i].corner, opposite(b.events[i].corner));
      }
      EXPECT_EQ(a.events[i].side, -b.events[i].side);
    }
    EXPECT_EQ(sa.mode().phase, sb.mode().phase);
    for (const StateIndex i : {kU, kTheta, kUDot, kThetaDot}) {
      EXPECT_NEAR(sa.state()[i], -sb.state()[i], 1e-9) << "component " << i;
    }
  }
}

// An impulse on fixed ground sets the block rocking about the corner it is thrown on, with
// the angular momentum about that corner: theta'(0+) = -m h I / I_i.
TEST(Housner, ImpulseOnFixedGroundStartsRocking) {
  const Scene s = make(paper_block(0.2));
  for (const double impulse : {0.3, -0.3}) {
    RecordingSink sink;
    SolverSettings settings;
    Simulator sim;
    ASSERT_TRUE(Simulator::create(s, Excitation::none(), settings, sim).ok());
    sim.set_event_sink(&sink);
    sim.start_with_impulse(impulse);
    const Corner corner = impulse > 0.0 ? Corner::kRight : Corner::kLeft;
    ASSERT_EQ(sink.events.size(), 1U);
    EXPECT_EQ(sink.events[0].corner, corner);
    EXPECT_EQ(sim.mode().phase, Phase::kRocking);
    EXPECT_DOUBLE_EQ(sim.state()[kThetaDot], -s.m * s.h * impulse / s.corner(corner).inertia);
  }
}

// Overturning: a large impulse carries |theta| past alpha_i, and the event says so there.
TEST(Housner, OverturnsWhenThetaPassesTheCriticalAngle) {
  const Scene s = make(paper_block(0.0));
  RecordingSink sink;
  const Simulator sim = testing::run(s, Excitation::none(), 5.0, 1e-4, &sink, -3.0);
  const Event* over = sink.first(EventKind::kOverturned);
  ASSERT_NE(over, nullptr);
  EXPECT_EQ(sim.mode().phase, Phase::kOverturned);
  EXPECT_NEAR(std::fabs(over->state[kTheta]), s.corner1.critical_angle, 1e-15);
  RecordingSink survives;
  testing::run(s, Excitation::none(), 5.0, 1e-4, &survives, -0.5);
  EXPECT_EQ(survives.first(EventKind::kOverturned), nullptr);
  EXPECT_NE(survives.first(EventKind::kRockingStop), nullptr);
}

}  // namespace
}  // namespace plinth

namespace plinth {
namespace {

// Eq 16 with vertical ground motion: rocking starts when u_G'' reaches (b_1/h)(g + v_G'').
TEST(Housner, VerticalGroundAccelerationShiftsTheOnset) {
  const Scene s = testing::make(testing::paper_block(0.2));
  // A horizontal ramp 0 -> 1 g over 2 s, sampled every 10 ms, and a steady vertical -0.4 g.
  std::vector<double> horizontal(201), vertical(201, -0.4 * s.g);
  for (std::size_t i = 0; i < horizontal.size(); ++i) {
    horizontal[i] = s.g * static_cast<double>(i) / 200.0;
  }
  const Excitation ground = Excitation::record({horizontal.data(), horizontal.size(), 0.01},
                                               {vertical.data(), vertical.size(), 0.01});
  testing::RecordingSink sink;
  testing::run(s, ground, 2.0, 1e-3, &sink);
  const Event* onset = sink.first(EventKind::kRockingStart);
  ASSERT_NE(onset, nullptr);
  EXPECT_EQ(onset->corner, Corner::kLeft);
  // u_G''(t) = g t / 2 reaches (b1/h)(g - 0.4 g) at t = 2 (b1/h)(0.6).
  EXPECT_NEAR(onset->t, 2.0 * s.corner1.onset_ratio * 0.6, 1e-9);
}

}  // namespace
}  // namespace plinth

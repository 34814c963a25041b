// Zeno sequences end: impacts piling up as rocking dies out, stick-slip at zero velocity, a base
// pressed against its stop, a block pressed against a sliding stop. Each run must reach its end
// time (time advances every step) with a bounded number of events and come to rest, for every
// stepper.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "test_support.h"

namespace plinth {
namespace {

using testing::make;

// Counts events per kind without storing them (some runs have thousands).
class CountingSink final : public EventSink {
 public:
  void on_event(const Event& e) override {
    ++counts[static_cast<std::size_t>(e.kind)];
    ++total;
  }
  [[nodiscard]] long count(EventKind kind) const { return counts[static_cast<std::size_t>(kind)]; }

  std::array<long, 16> counts{};
  long total = 0;
};

struct ZenoRun {
  CountingSink sink;
  Mode mode;
  State state;
  std::int64_t steps = 0;
  std::int64_t located = 0;         // events located (Simulator::event_count)
  std::int64_t most_in_a_step = 0;  // located events in the busiest step
  std::int64_t chatter_steps = 0;
  bool finite = true;
};

// Runs to t_end, a step at a time, checking time advances by one step each time.
ZenoRun run_to(const Scene& scene, const Excitation& excitation, Stepper stepper, double dt,
               double t_end, const Mode& mode = {}, const State& y = State::Zero(),
               int max_events_per_step = SolverSettings{}.max_events_per_step) {
  SolverSettings settings;
  settings.max_events_per_step = max_events_per_step;
  settings.stepper = stepper;
  settings.step = dt;
  ZenoRun r;
  Simulator sim;
  if (!Simulator::create(scene, excitation, settings, sim).ok()) __builtin_trap();
  sim.set_event_sink(&r.sink);
  sim.start_from(mode, y);
  const auto steps = static_cast<std::int64_t>(std::llround(t_end / dt));
  for (std::int64_t i = 0; i < steps && !sim.mode().terminal(); ++i) {
    const std::int64_t before = sim.event_count();
    sim.step();
    EXPECT_EQ(sim.step_count(), i + 1);
    r.most_in_a_step = std::max(r.most_in_a_step, sim.event_count() - before);
    r.finite = r.finite && sim.state().allFinite();
  }
  r.mode = sim.mode();
  r.state = sim.state();
  r.steps = sim.step_count();
  r.located = sim.event_count();
  r.chatter_steps = sim.chatter_steps();
  return r;
}

void report(const char* what, Stepper stepper, const ZenoRun& r) {
  std::printf(
      "%-32s %-20s %6lld steps, %5lld events (%ld reported), at most %lld in a step, "
      "%lld chatter steps\n",
      what, stepper_name(stepper), static_cast<long long>(r.steps),
      static_cast<long long>(r.located), r.sink.total, static_cast<long long>(r.most_in_a_step),
      static_cast<long long>(r.chatter_steps));
}

// A slender block on the ground (lambda = 5: Housner's ratio 1 - 1.5 sin^2(alpha) = 0.94).
Scene slender_block() {
  SceneParams p = testing::paper_block();
  p.block.com_height = 1.5;
  p.block.inertia = homogeneous_rectangle_inertia(p.block.mass, 0.3, 1.5);
  return make(p);
}

// Free rocking of `s` let go at rest at half its critical angle, for 80 s.
ZenoRun let_go(const Scene& s, Stepper stepper, double dt,
               int max_events_per_step = SolverSettings{}.max_events_per_step) {
  State y = State::Zero();
  y[kTheta] = 0.5 * s.corner1.critical_angle;
  return run_to(s, Excitation::none(), stepper, dt, 80.0, {Phase::kRocking, Corner::kLeft}, y,
                max_events_per_step);
}

// The slender block let go rocks with ever shorter and smaller cycles: infinitely many impacts
// in a finite time, ended by the rest criterion.
TEST(Zeno, ImpactsPilingUpAsRockingDiesOutOnTheGround) {
  const Scene s = slender_block();
  // At 10 ms the last cycles are shorter than a step: many impacts are located in one step.
  for (const Stepper stepper : kAllSteppers) {
    for (const double dt : {1e-3, 1e-2}) {
      const ZenoRun r = let_go(s, stepper, dt);
      report(dt < 5e-3 ? "rocking dies out on the ground" : "... at 10 ms steps", stepper, r);
      EXPECT_TRUE(r.finite);
      EXPECT_EQ(r.steps, std::llround(80.0 / dt));
      EXPECT_EQ(r.mode.phase, Phase::kFullContact) << "comes to rest";
      EXPECT_EQ(r.sink.count(EventKind::kRockingStop), 1);
      EXPECT_GT(r.sink.count(EventKind::kImpact), 15);  // the sequence is long...
      EXPECT_LT(r.located, 5000);                       // ...and finite
      EXPECT_LE(r.most_in_a_step, 64);
    }
  }
}

// With at most 4 events a step, the sequence's end is cut short as chatter: rocking brought to
// rest within the step (max_events_per_step). (Semi-implicit Euler's rocking dies out at 10 ms
// before its cycles get that short.)
TEST(Zeno, ChatterWithinAStepIsSettled) {
  const Scene s = slender_block();
  for (const Stepper stepper : {Stepper::kRk4Located, Stepper::kHeunLocated}) {
    const ZenoRun r = let_go(s, stepper, 1e-2, 4);
    report("chatter settled (4 a step)", stepper, r);
    EXPECT_EQ(r.steps, 8000);
    EXPECT_EQ(r.mode.phase, Phase::kFullContact);
    EXPECT_GE(r.chatter_steps, 1);
    EXPECT_LE(r.most_in_a_step, 4);
  }
}

// The same on the isolated base (the paper's block, lambda = 3), the base taking momentum at
// each impact.
TEST(Zeno, ImpactsPilingUpAsRockingDiesOutOnTheBase) {
  const Scene s = make(testing::paper_isolated());
  State y = State::Zero();
  y[kTheta] = 0.5 * s.corner1.critical_angle;
  for (const Stepper stepper : kAllSteppers) {
    const ZenoRun r =
        run_to(s, Excitation::none(), stepper, 1e-4, 20.0, {Phase::kRocking, Corner::kLeft}, y);
    report("rocking dies out on the base", stepper, r);
    EXPECT_TRUE(r.finite);
    EXPECT_EQ(r.steps, 200000);
    EXPECT_EQ(r.mode.phase, Phase::kFullContact);
    EXPECT_EQ(r.sink.count(EventKind::kRockingStop), 1);
    EXPECT_GT(r.sink.count(EventKind::kImpact), 10);
    EXPECT_LT(r.located, 2000);
    EXPECT_LE(r.most_in_a_step, 64);
  }
}

// A ground acceleration `value` + `wiggle` cos(0.37 n) at samples n 0.01 s apart, m/s2 (the
// wiggle's ground velocity has no drift).
struct SampledInput {
  std::vector<double> samples;
  Excitation excitation;

  SampledInput(double value, double duration, double wiggle = 0.0) {
    for (int i = 0; i * 0.01 <= duration; ++i)
      samples.push_back(value + wiggle * std::cos(0.37 * i));
    excitation = Excitation::record({samples.data(), samples.size(), 0.01});
  }
};

using testing::with_friction;

// Stick-slip at zero velocity: the ground pushes the block exactly at the friction limit
// (mu_s = mu_k = 0.2, u_G'' = 0.2 g), wiggling by 1e-6 of it, so that x' keeps returning to 0
// and the contact keeps switching between sticking and slipping.
TEST(Zeno, StickSlipAtTheFrictionLimit) {
  const Scene s = make(with_friction(testing::paper_block(), 0.2, 0.2));
  const SampledInput input(0.2 * kStandardGravity, 3.0, 0.2e-6 * kStandardGravity);
  for (const Stepper stepper : kAllSteppers) {
    const ZenoRun r = run_to(s, input.excitation, stepper, 1e-3, 3.0);
    report("stick-slip at the friction limit", stepper, r);
    EXPECT_TRUE(r.finite);
    EXPECT_EQ(r.steps, 3000);
    EXPECT_FALSE(r.mode.rocking());
    EXPECT_GT(r.sink.count(EventKind::kSlidingStart), 0);
    EXPECT_LT(r.located, 20000);
    EXPECT_LE(r.most_in_a_step, 64);
    EXPECT_LT(std::fabs(r.state[kXDot]), 1e-3) << "creeps at most";
  }
}

// Frictionless (mu = 0) on the isolated base under a tiny forcing: every reversal of the base
// reverses x'; with no force at all the block stays put instead of sliding at zero speed.
TEST(Zeno, FrictionlessBlockUnderTinyForcing) {
  const Scene s = make(with_friction(testing::paper_isolated(), 0.0, 0.0));
  const SampledInput input(0.0, 5.0, 1e-9);
  for (const Stepper stepper : kAllSteppers) {
    const ZenoRun r = run_to(s, input.excitation, stepper, 1e-3, 6.0);
    report("frictionless, tiny forcing", stepper, r);
    EXPECT_TRUE(r.finite);
    EXPECT_EQ(r.steps, 6000);
    EXPECT_LT(r.located, 6000) << "at most about one event a step";
    EXPECT_LE(r.most_in_a_step, 64);
    EXPECT_LT(std::fabs(r.state[kX]), 1e-6);
  }
}

// A steady push holds the base against its left stop (u_max = 1 cm, static deflection 10 cm):
// rebounds of restitution 0.7 pile up until the base rests on the stop.
TEST(Zeno, BasePressedAgainstItsStop) {
  SceneParams p = testing::paper_isolated();
  p.has_base_stops = true;
  p.base_stops = {0.01, 0.7};
  const Scene s = make(p);
  const SampledInput input(1.0, 5.0);
  for (const Stepper stepper : kAllSteppers) {
    const ZenoRun r = run_to(s, input.excitation, stepper, 1e-4, 4.0);
    report("base pressed against its stop", stepper, r);
    EXPECT_TRUE(r.finite);
    EXPECT_EQ(r.steps, 40000);
    EXPECT_EQ(r.mode.held_stop, -1) << "rests on the left stop";
    EXPECT_EQ(r.sink.count(EventKind::kBaseStopHeld), 1);
    EXPECT_GT(r.sink.count(EventKind::kBaseStopHit), 5);
    EXPECT_LT(r.located, 200);
    EXPECT_DOUBLE_EQ(r.state[kU], -0.01);
  }
}

// A steady push slides the block into its left sliding stop (x_hat = 2 cm, eta_s = 0.7): the
// rebounds pile up until it sticks against the stop.
TEST(Zeno, BlockPressedAgainstASlidingStop) {
  for (const bool on_base : {false, true}) {
    SceneParams p =
        with_friction(on_base ? testing::paper_isolated() : testing::paper_block(), 0.1, 0.08);
    p.has_support = true;
    p.support = {0.02};
    p.has_sliding_stops = true;
    p.sliding_stops = {0.7};
    const Scene s = make(p);
    const SampledInput input(2.0, 5.0);  // 2 m/s2: twice what static friction holds
    for (const Stepper stepper : kAllSteppers) {
      const ZenoRun r = run_to(s, input.excitation, stepper, 1e-4, on_base ? 4.0 : 2.0);
      report(on_base ? "block against a stop, on the base" : "block against a stop, ground",
             stepper, r);
      EXPECT_TRUE(r.finite);
      EXPECT_GT(r.sink.count(EventKind::kSlideStopHit), 5);
      EXPECT_LT(r.located, 500);
      EXPECT_LE(r.most_in_a_step, 64);
      EXPECT_FALSE(r.mode.sliding()) << "sticks against the stop";
      EXPECT_NEAR(r.state[kX], -0.02, 1e-7);  // step ends: the last slide may pass it a little
    }
  }
}

}  // namespace
}  // namespace plinth

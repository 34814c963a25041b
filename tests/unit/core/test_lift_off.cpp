// Lift-off: where the support's normal force on the block reaches 0 the model (which has no free
// flight) ends, an event located inside the step like the others, in every phase.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iterator>
#include <random>
#include <vector>

#include "plinth/core/internal/flows.h"
#include "plinth/core/internal/guards.h"
#include "test_support.h"

namespace plinth {
namespace {

using internal::contact_force;
using internal::contact_kinematics;
using internal::lift_off_guard;
using internal::Pivot;
using internal::pivot_of;
using internal::rocking_flow;
using internal::slide_rocking_flow;
using internal::SinCos;
using testing::make;
using testing::paper_block;
using testing::paper_isolated;
using testing::RecordingSink;
using testing::with_friction;

// A vertical record falling linearly from 0 at t = 0 to `peak` m/s2 at `t_peak`, then held.
struct Ramp {
  std::vector<double> zeros;
  std::vector<double> vertical;
  double dt = 0.01;
  Ramp(double peak, double t_peak, double duration) {
    const auto n = static_cast<std::size_t>(std::lround(duration / dt)) + 1;
    zeros.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      vertical.push_back(peak * std::fmin(1.0, static_cast<double>(i) * dt / t_peak));
    }
  }
  [[nodiscard]] Excitation excitation() const {
    return Excitation::record({zeros.data(), zeros.size(), dt},
                              {vertical.data(), vertical.size(), dt});
  }
};

// A block as wide as it is tall (b = h = 0.5 m) on the ground: it rocks from u_G'' = g and
// spins fast without overturning.
Scene squat_block() {
  SceneParams p = paper_block();
  p.block.half_width = 0.5;
  p.block.com_height = 0.5;
  p.block.inertia = homogeneous_rectangle_inertia(p.block.mass, 0.5, 0.5);
  return make(p);
}

// Minus the normal force of Eq 12 (about a body corner) or Eq 14 (about the support's corner),
// per unit mass, as printed; `a` the phase's accelerations (x'' enters neither).
double printed_lift_off_witness(const Scene& s, const Pivot& pivot, const State& y,
                                GroundAcceleration ag, const Accelerations& a) {
  const double th = y[kTheta], td = y[kThetaDot];
  const double b_hat = pivot.geometry.offset, h = s.h;
  const double gv = s.g + ag.vertical;
  if (!pivot.overhanging) {
    const double bp = b_hat * std::cos(th) - h * std::sin(th);  // Eq 9
    const double hp = b_hat * std::sin(th) + h * std::cos(th);
    return -(gv + bp * a.theta - hp * td * td);  // Eq 12 / m
  }
  return -(gv * std::cos(th) - (a.u + ag.horizontal) * std::sin(th) + 2.0 * y[kXDot] * td +
           b_hat * a.theta - h * td * td);  // Eq 14 / m
}

// Full contact: the block leaves the ground where g + v_G'' reaches 0, located inside the step
// on the record's linear interpolation (v_G'' = -2 g t / 1 s reaches -g at t = 0.5 s; the step
// 7e-4 s puts no grid point there), and the run ends there.
TEST(LiftOff, FullContactEndsWhereTheGroundFallsFasterThanGravity) {
  for (const bool isolated : {false, true}) {
    const Scene s = make(isolated ? paper_isolated(0.2) : paper_block(0.2));
    const Ramp ramp(-2.0 * s.g, 1.0, 3.0);
    RecordingSink sink;
    Simulator sim = testing::run(s, ramp.excitation(), 3.0, 7e-4, &sink);
    const Event* lift = sink.first(EventKind::kLiftOff);
    ASSERT_NE(lift, nullptr) << (isolated ? "isolated" : "on the ground");
    EXPECT_NEAR(lift->t, 0.5, 1e-9);
    EXPECT_NEAR(lift->before, 0.0, 1e-6);  // g + v_G'' at the event
    EXPECT_EQ(lift->phase, Phase::kLiftedOff);
    EXPECT_EQ(sim.mode().phase, Phase::kLiftedOff);
    EXPECT_TRUE(sim.mode().terminal());
    EXPECT_FALSE(sim.mode().collapsed());
    EXPECT_EQ(&sink.events.back(), lift) << "nothing after the lift-off";
    // The run ends: further steps change nothing.
    const State at_end = sim.state();
    const double t_end = sim.time();
    EXPECT_LT(t_end, 0.5 + 7e-4 + 1e-12);
    sim.step();
    EXPECT_EQ(sim.time(), t_end);
    EXPECT_EQ(sim.state(), at_end);
  }
}

// Where the ground already falls faster than gravity at the start, the block lifts off at t = 0.
TEST(LiftOff, AtTheStartWhenTheGroundAlreadyFalls) {
  const Scene s = make(paper_isolated());
  const std::vector<double> zeros(11, 0.0);
  const std::vector<double> falling(11, -1.5 * s.g);
  const Excitation e =
      Excitation::record({zeros.data(), zeros.size(), 0.01}, {falling.data(), falling.size(), 0.01});
  RecordingSink sink;
  const Simulator sim = testing::run(s, e, 0.1, 1e-3, &sink);
  ASSERT_EQ(sink.events.size(), 1U);
  EXPECT_EQ(sink.events[0].kind, EventKind::kLiftOff);
  EXPECT_EQ(sink.events[0].t, 0.0);
  EXPECT_EQ(sink.events[0].left, Phase::kFullContact);
  EXPECT_EQ(sim.mode().phase, Phase::kLiftedOff);
}

// Without lift-off nothing changes: under the same ramp stopped short of -g the block never
// leaves (and a ramp to exactly -g touches 0 only at its end, which does not count as crossing
// before it).
TEST(LiftOff, NotWhileGravityStillWins) {
  const Scene s = make(paper_isolated(0.2));
  const Ramp ramp(-0.95 * s.g, 1.0, 3.0);
  RecordingSink sink;
  const Simulator sim = testing::run(s, ramp.excitation(), 3.0, 1e-3, &sink);
  EXPECT_EQ(sink.first(EventKind::kLiftOff), nullptr);
  EXPECT_EQ(sim.mode().phase, Phase::kFullContact);
  EXPECT_NEAR(sim.time(), 3.0, 1e-9);
}

// The paper's eccentric block on its base with friction (mu_s 0.5, mu_k 0.4) and a support of
// clearance 0.1 m: every rocking phase, about a corner of the body or of the support.
Scene rocking_phases_scene() {
  SceneParams p = with_friction(paper_isolated(0.3), 0.5, 0.4);
  p.has_support = true;
  p.support = {0.1};
  return make(p);
}

// A random rocking (or, `sliding`, slide-rocking) mode about either corner, of the body or
// (`overhanging`) of the support, and a state in it: |theta| <= max_angle rad, |theta'| <=
// max_rate rad/s, |u'| and |x'| <= 1 m/s.
struct RockingSample {
  Mode mode;
  State y;
};
RockingSample random_rocking_sample(std::mt19937& rng, bool overhanging, bool sliding,
                                    double max_angle, double max_rate) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  RockingSample r;
  r.mode.phase = sliding ? Phase::kSlideRocking : Phase::kRocking;
  r.mode.corner = unit(rng) > 0.0 ? Corner::kLeft : Corner::kRight;
  const double sign = r.mode.corner == Corner::kLeft ? 1.0 : -1.0;
  const double x = overhanging ? -sign * (0.1 + 0.2 * std::fabs(unit(rng))) : 0.09 * unit(rng);
  r.y << 0.1 * unit(rng), x, sign * max_angle * std::fabs(unit(rng)), unit(rng),
      sliding ? unit(rng) : 0.0, max_rate * unit(rng);
  r.mode.slide_direction = static_cast<std::int8_t>(unit(rng) > 0.0 ? 1 : -1);
  r.mode.overhang = static_cast<std::int8_t>(overhanging ? -sign : 0);
  return r;
}

// The witness in the rocking phases is the printed normal force: Eq 12 about a body corner
// (pure rocking and slide-rocking), Eq 14 about the support's corner (slide-rocking, with x'),
// and contact_force's normal component, for random states and inputs.
TEST(LiftOff, RockingWitnessIsThePrintedNormalForce) {
  const Scene s = rocking_phases_scene();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 300; ++i) {
    const bool overhanging = i % 3 == 2;
    const bool sliding = i % 3 != 0;
    const auto [mode, y] = random_rocking_sample(rng, overhanging, sliding, 0.3, 3.0);
    const GroundAcceleration ag{10.0 * unit(rng), 8.0 * unit(rng)};
    const Pivot pivot = pivot_of(s, mode, y);
    ASSERT_EQ(pivot.overhanging, overhanging);
    const Accelerations a =
        sliding ? slide_rocking_flow(s, pivot.geometry, overhanging, mode.slide_direction, y, ag,
                                     true)
                : rocking_flow(s, pivot.geometry, y, ag, true);
    const SinCos trig{std::sin(y[kTheta]), std::cos(y[kTheta])};
    const double witness = lift_off_guard(s, mode, y, ag, a, trig);
    const double scale = s.g + 30.0;
    EXPECT_NEAR(witness, printed_lift_off_witness(s, pivot, y, ag, a), 1e-12 * scale)
        << "sample " << i;
    const double normal =
        contact_force(s, contact_kinematics(s, pivot.geometry, overhanging, y), a, ag).normal;
    EXPECT_NEAR(witness, -normal / s.m, 1e-12 * scale) << "sample " << i;
  }
  // Full contact and sliding: Y = m (g + v_G''), whatever the state.
  for (const Phase phase : {Phase::kFullContact, Phase::kSliding}) {
    Mode mode;
    mode.phase = phase;
    EXPECT_DOUBLE_EQ(lift_off_guard(s, mode, State::Zero(), {3.0, -2.0}, {}, SinCos{}),
                     -(s.g - 2.0));  // m (g + v_G'') / m, to rounding
  }
}

// The solver's steps take lift_off_bound for the witness far from lift-off (guards.h): it must
// be negative only where the witness is, and not below it but by roundings. Random rocking and
// slide-rocking states about either corner of the body or of the support, the ground's vertical
// acceleration set so that the witness lies at chosen distances from 0: far below and above it,
// and within 1e-9 to 1e-15 of the terms' size, where only the margin for roundings tells them
// apart.
TEST(LiftOff, TheBoundIsNegativeOnlyWhereTheWitnessIs) {
  const Scene s = rocking_phases_scene();
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double gaps[] = {-0.5, -1e-3, -1e-9, -1e-12, -1e-15, 0.0, 1e-15, 1e-12, 1e-9, 1e-3, 0.5};
  int answered[2] = {0, 0};
  constexpr int kSamples = 20000;
  for (int i = 0; i < kSamples; ++i) {
    const bool overhanging = i % 4 == 3;
    const auto [mode, y] = random_rocking_sample(rng, overhanging, i % 2 == 1, 0.6, 4.0);
    const Accelerations a{20.0 * unit(rng), 5.0 * unit(rng), 30.0 * unit(rng)};
    const SinCos trig = internal::sin_cos(y[kTheta]);
    // The witness with the ground still vertically: -Y / m = -(g + v_G'') cos - rest; set
    // v_G'' so that -Y / m = -gap times the terms' size.
    GroundAcceleration ag{10.0 * unit(rng), 0.0};
    const double cos_weight = overhanging ? trig.cos : 1.0;
    const double rest = -lift_off_guard(s, mode, y, ag, a, trig) - s.g * cos_weight;
    const double size = s.g + std::fabs(rest) + 40.0;
    const double gap = gaps[static_cast<std::size_t>(i) % std::size(gaps)];
    ag.vertical = (gap * size - rest) / cos_weight - s.g;
    const double bound = internal::lift_off_bound(s, mode, y, ag, a, trig);
    const double witness = lift_off_guard(s, mode, y, ag, a, trig);
    if (bound >= 0.0) continue;
    ++answered[overhanging ? 1 : 0];
    EXPECT_LT(witness, 0.0) << "sample " << i << ", gap " << gap;
    // An upper bound, to roundings (overhanging it is tight: every term has its worst sign).
    EXPECT_GE(bound, witness - 1e-13 * size) << "sample " << i << ", gap " << gap;
  }
  // The bound answers away from lift-off (about a body corner it is not tight: from a gap of
  // 1e-3 to 0.5 here); nearer, the witness is evaluated.
  EXPECT_GT(answered[0], kSamples * 3 / 4 / 11 / 2);
  EXPECT_GT(answered[1], kSamples / 4 / 11 / 2);
  std::printf("the bound answered %d of %d samples about a body corner, %d of %d overhanging\n",
              answered[0], kSamples * 3 / 4, answered[1], kSamples / 4);
}

// Every live mode's guards lead with lift-off (a tie ends the model first) and its phase's
// guards, the order the step evaluates them in without a switch (internal::leading_guards):
// every feature set, phase, corner, held stop, sliding direction and overhang.
template <Features F>
void expect_leading_guards() {
  for (int phase = 0; phase <= static_cast<int>(Phase::kSlideRocking); ++phase) {
    for (const Corner corner : {Corner::kLeft, Corner::kRight}) {
      for (int held = -1; held <= 1; ++held) {
        for (int direction = -1; direction <= 1; direction += 2) {
          for (int overhang = -1; overhang <= 1; ++overhang) {
            Mode mode;
            mode.phase = static_cast<Phase>(phase);
            mode.corner = corner;
            mode.held_stop = static_cast<std::int8_t>(held);
            mode.slide_direction = static_cast<std::int8_t>(direction);
            mode.overhang = static_cast<std::int8_t>(overhang);
            const internal::ActiveGuards guards = internal::active_guards<F>(mode);
            const auto leading = internal::leading_guards(mode.rocking());
            ASSERT_GE(guards.count, internal::kLeadingGuards);
            for (std::size_t i = 0; i < leading.size(); ++i) {
              EXPECT_EQ(guards.ids[i], leading[i]) << "phase " << phase << ", guard " << i;
            }
          }
        }
      }
    }
  }
  Mode ended;
  ended.phase = Phase::kLiftedOff;
  EXPECT_EQ(internal::active_guards<F>(ended).count, 0);
}

TEST(LiftOff, EveryLiveModesGuardsLeadWithLiftOffAndItsPhases) {
  expect_leading_guards<Features{}>();
  expect_leading_guards<Features{false, false, true, false, false}>();
  expect_leading_guards<Features{false, false, true, true, false}>();
  expect_leading_guards<Features{false, false, true, false, true}>();
  expect_leading_guards<Features{true, false, false, false, false}>();
  expect_leading_guards<Features{true, false, true, true, false}>();
  expect_leading_guards<Features{true, true, false, false, false}>();
  expect_leading_guards<Features{true, true, true, false, true}>();
}

// The witness against the simulated motion: C's height above the pivot is h'_i (Eq 6), so the
// normal force is m (d2 h'_i / dt2 + g + v_G''). Central differences of h'_i(theta(t)) along a
// rocking run of the isolated block under horizontal and vertical shaking agree with it.
TEST(LiftOff, RockingWitnessMatchesTheSimulatedMotion) {
  const Scene s = make(paper_isolated(0.1));
  constexpr double kDt = 1e-5;
  std::vector<double> horizontal, vertical;
  for (int i = 0; i <= 40000; ++i) {  // 0.4 s at 1e-5 s
    const double t = i * kDt;
    horizontal.push_back(-6.0 * std::sin(2.0 * M_PI * t / 0.4));
    vertical.push_back(3.0 * std::sin(2.0 * M_PI * t / 0.13));
  }
  const Excitation e = Excitation::record({horizontal.data(), horizontal.size(), kDt},
                                          {vertical.data(), vertical.size(), kDt});
  SolverSettings settings;
  settings.step = kDt;
  Simulator sim;
  ASSERT_TRUE(Simulator::create(s, e, settings, sim).ok());
  RecordingSink sink;
  sim.set_event_sink(&sink);
  Mode mode;
  mode.phase = Phase::kRocking;
  mode.corner = Corner::kLeft;
  State y = State::Zero();
  y[kTheta] = 0.02;
  y[kThetaDot] = 0.5;
  sim.start_from(mode, y);
  const double offset = s.corner1.offset;
  const auto height = [&](const State& state) {
    return offset * std::sin(state[kTheta]) + s.h * std::cos(state[kTheta]);
  };
  std::vector<double> heights, witnesses;
  constexpr int kStride = 50;  // differences over 5e-4 s
  for (int i = 0; i <= 400 * kStride && sink.events.empty(); ++i) {
    if (i % kStride == 0) {
      heights.push_back(height(sim.state()));
      const GroundAcceleration ag = sim.ground(sim.time());
      witnesses.push_back(lift_off_guard(s, sim.mode(), sim.state(), ag, sim.accelerations(),
                                         {std::sin(sim.state()[kTheta]),
                                          std::cos(sim.state()[kTheta])}) +
                          s.g + ag.vertical);  // -b' theta'' + h' theta'^2 = -d2 h' / dt2
    }
    sim.step();
  }
  ASSERT_GE(heights.size(), 300U) << "the block kept rocking about corner 1 for 0.15 s";
  const double h_step = kStride * kDt;
  double worst = 0.0;
  for (std::size_t k = 1; k + 1 < heights.size(); ++k) {
    const double second = (heights[k + 1] - 2.0 * heights[k] + heights[k - 1]) / (h_step * h_step);
    worst = std::fmax(worst, std::fabs(second + witnesses[k]));
  }
  EXPECT_LT(worst, 1e-4) << "m/s2, against |theta''| b' of a few m/s2";
  std::printf("Eq 12 against the motion: %zu points, worst %.3g m/s2\n", heights.size(), worst);
}

// Without vertical motion: a squat block spun fast on the ground unloads its pivot (the
// centripetal term h'_i theta'^2 of Eq 12 beats g): an impulse that throws it hard lifts it off
// at t = 0, from rocking, with g + v_G'' = g.
TEST(LiftOff, ASpinFastEnoughUnloadsThePivot) {
  const Scene s = squat_block();
  // theta'(0+) = -m h I / I_2; Y = m (g + b' theta'' - h' theta'^2) < 0 beyond a few m/s.
  for (const double impulse : {1.0, 8.0}) {
    RecordingSink sink;
    const Simulator sim = testing::run(s, Excitation::none(), 0.05, 1e-4, &sink, impulse);
    const Event* lift = sink.first(EventKind::kLiftOff);
    if (impulse < 2.0) {
      EXPECT_EQ(lift, nullptr);
      continue;
    }
    ASSERT_NE(lift, nullptr);
    EXPECT_EQ(lift->t, 0.0);
    EXPECT_EQ(lift->left, Phase::kRocking);
    EXPECT_EQ(lift->before, s.g);
    EXPECT_EQ(sim.mode().phase, Phase::kLiftedOff);
  }
}

// A strong horizontal pulse under a squat rocking block: the rotation's acceleration unloads
// the pivot (b'_i theta'' of Eq 12) partway through a step, with no vertical motion at all.
TEST(LiftOff, AStrongHorizontalPulseUnloadsTheRockingPivot) {
  const Scene s = squat_block();
  RecordingSink sink;
  const Simulator sim =
      testing::run(s, Excitation::sine_pulse(3.0 * s.g, 0.5), 1.0, 1e-3, &sink);
  const Event* lift = sink.first(EventKind::kLiftOff);
  ASSERT_NE(lift, nullptr);
  EXPECT_EQ(lift->left, Phase::kRocking);
  EXPECT_EQ(lift->before, s.g);
  EXPECT_GT(lift->t, 0.0);
  EXPECT_NE(std::fmod(lift->t, 1e-3), 0.0) << "located inside the step";
  EXPECT_EQ(sim.mode().phase, Phase::kLiftedOff);
  // At the event the witness is 0 (to the location's tolerance, 1e-10 of the step).
  Mode rocking;
  rocking.phase = Phase::kRocking;
  rocking.corner = lift->corner;
  const GroundAcceleration ag = Excitation::sine_pulse(3.0 * s.g, 0.5).at(lift->t);
  const Accelerations a = rocking_flow(s, s.corner(lift->corner), lift->state, ag, false);
  const double witness = lift_off_guard(
      s, rocking, lift->state, ag, a,
      {std::sin(lift->state[kTheta]), std::cos(lift->state[kTheta])});
  EXPECT_NEAR(witness, 0.0, 1e-6);
}

}  // namespace
}  // namespace plinth

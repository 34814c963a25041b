// The solver's one-step methods (steppers.h), the exact full-contact propagator, the fast forms
// of the flows, and "only what the scene needs": a scene runs the same with a feature it never
// uses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "bundled_records.h"
#include "plinth/core/internal/flows.h"
#include "plinth/core/internal/full_contact_propagator.h"
#include "plinth/core/internal/resets.h"
#include "plinth/core/stability.h"
#include "plinth/host/record_io.h"
#include "test_support.h"

namespace plinth {
namespace {

namespace bounded_trig = internal::bounded_trig;
using internal::bounded_sin_cos;
using internal::contact_kinematics;
using internal::ContactKinematics;
using internal::coulomb_impact_reset;
using internal::CoulombImpact;
using internal::FloatSinCos;
using internal::FullContactPropagator;
using internal::kStageAngle;
using internal::lever_arms;
using internal::lever_arms_turned;
using internal::LeverArms;
using internal::Pivot;
using internal::pivot_of;
using internal::rocking_flow;
using internal::sin_cos;
using internal::SinCos;
using internal::slide_rocking_flow;
using internal::slide_rocking_matrices;
using internal::SlideRockingMatrices;
using internal::sliding_consistency;
using testing::make;
using testing::RecordingSink;

SolverSettings with(Stepper stepper, double dt, bool exact = false) {
  SolverSettings s;
  s.stepper = stepper;
  s.step = dt;
  s.exact_full_contact = exact;
  return s;
}

TEST(Steppers, DefaultIsRk4WithLocatedEvents) {
  const SolverSettings s;
  EXPECT_EQ(s.stepper, Stepper::kRk4Located);
  EXPECT_FALSE(s.exact_full_contact);
}

TEST(Steppers, NamesRoundTripAndUnknownOnesAreRefused) {
  for (const Stepper stepper : kAllSteppers) {
    Stepper parsed = Stepper::kRk4Located;
    ASSERT_TRUE(parse_stepper(stepper_name(stepper), parsed)) << stepper_name(stepper);
    EXPECT_EQ(parsed, stepper);
  }
  Stepper out = Stepper::kHeunLocated;
  EXPECT_FALSE(parse_stepper("rk45", out));
  EXPECT_EQ(out, Stepper::kHeunLocated);
}

TEST(Steppers, ValidateNamesTheStepperField) {
  SolverSettings s;
  s.stepper = static_cast<Stepper>(9);
  const Error e = validate(s);
  EXPECT_EQ(e.code, ErrorCode::kOutOfRange);
  EXPECT_STREQ(e.field, "solver.stepper");
  EXPECT_STREQ(e.reason,
               "must be one of rk4_located, rk4_step_end, heun_located, semi_implicit_euler");
  Simulator sim;
  const Scene scene = make(testing::paper_isolated());
  EXPECT_STREQ(Simulator::create(scene, Excitation::none(), s, sim).field, "solver.stepper");
}

// theta and u after 0.16 s of free rocking on the isolated base from theta = 0.05 rad (no event
// before the first impact at 0.18 s): the observed orders are the methods' 4, 2 and 1.
State free_rocking(Stepper stepper, double dt) {
  const Scene s = make(testing::paper_isolated());
  Simulator sim;
  if (!Simulator::create(s, Excitation::none(), with(stepper, dt), sim).ok()) __builtin_trap();
  State y = State::Zero();
  y[kTheta] = 0.05;
  sim.start_from({Phase::kRocking, Corner::kLeft, 0}, y);
  while (sim.time() < 0.16 - 0.5 * dt) sim.step();
  EXPECT_EQ(sim.mode().phase, Phase::kRocking);
  EXPECT_EQ(sim.event_count(), 0);
  return sim.state();
}

TEST(Steppers, ObservedOrdersAreFourTwoAndOne) {
  const State reference = free_rocking(Stepper::kRk4Located, 1e-5);
  struct Expected {
    Stepper stepper;
    double order;
  };
  for (const Expected x :
       {Expected{Stepper::kRk4Located, 4.0}, Expected{Stepper::kRk4StepEnd, 4.0},
        Expected{Stepper::kHeunLocated, 2.0}, Expected{Stepper::kSemiImplicitEuler, 1.0}}) {
    const double coarse = (free_rocking(x.stepper, 4e-3) - reference).norm();
    const double fine = (free_rocking(x.stepper, 2e-3) - reference).norm();
    const double order = std::log2(coarse / fine);
    std::printf("%-20s errors %.2e %.2e, order %.2f\n", stepper_name(x.stepper), coarse, fine,
                order);
    EXPECT_NEAR(order, x.order, 0.3) << stepper_name(x.stepper);
  }
}

// The events without a rocking stop and restart at the same instant (a block set rocking with
// theta'' = 0 that the method's first rounding turns the other way: it is at rest again).
std::vector<Event> without_restarts(const std::vector<Event>& events) {
  std::vector<Event> kept;
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (i + 1 < events.size() && events[i].kind == EventKind::kRockingStop &&
        events[i + 1].kind == EventKind::kRockingStart &&
        std::fabs(events[i + 1].t - events[i].t) < 1e-9) {
      ++i;
      continue;
    }
    kept.push_back(events[i]);
  }
  return kept;
}

// Every stepper, at a small step, gives the default's sequence of events on a run with rocking
// onset, impacts and base stop hits; the event times agree to what its order allows.
TEST(Steppers, SmallStepsReproduceTheDefaultsEvents) {
  SceneParams p = testing::paper_isolated(0.2, 0.5, 0.1);
  p.has_base_stops = true;
  p.base_stops = {0.02, 0.7};
  const Scene s = make(p);
  const Excitation pulse = Excitation::sine_pulse(1.2 * kStandardGravity, 0.5);
  RecordingSink reference;
  (void)testing::run(s, pulse, 1.0, 1e-5, &reference);
  ASSERT_GE(reference.count(EventKind::kImpact), 1);
  ASSERT_GE(reference.count(EventKind::kBaseStopHit), 3);
  ASSERT_NE(reference.first(EventKind::kOverturned), nullptr);
  struct Case {
    Stepper stepper;
    bool exact;
    double dt;
    double time_tolerance;  // s
  };
  const std::vector<Event> expected = without_restarts(reference.events);
  for (const Case c :
       {Case{Stepper::kRk4Located, true, 1e-5, 1e-9}, Case{Stepper::kRk4StepEnd, false, 1e-5, 3e-5},
        Case{Stepper::kHeunLocated, false, 1e-5, 1e-6},
        Case{Stepper::kSemiImplicitEuler, false, 2e-6, 1e-4}}) {
    RecordingSink sink;
    (void)testing::run(s, pulse, 1.0, c.dt, &sink, 0.0, with(c.stepper, c.dt, c.exact));
    const std::vector<Event> events = without_restarts(sink.events);
    ASSERT_EQ(events.size(), expected.size()) << stepper_name(c.stepper);
    for (std::size_t i = 0; i < events.size(); ++i) {
      EXPECT_EQ(events[i].kind, expected[i].kind) << stepper_name(c.stepper) << i;
      EXPECT_NEAR(events[i].t, expected[i].t, c.time_tolerance)
          << stepper_name(c.stepper) << " event " << i;
    }
  }
}

TEST(Steppers, StepEndTakesEveryEventAtAStepsEnd) {
  const Scene s = make(testing::paper_isolated(0.2, 0.5, 0.1));
  const double dt = 1e-3;
  RecordingSink sink;
  (void)testing::run(s, Excitation::sine_pulse(1.2 * kStandardGravity, 0.5), 1.5, dt, &sink, 0.0,
                     with(Stepper::kRk4StepEnd, dt));
  ASSERT_GE(sink.count(EventKind::kImpact), 1);
  for (const Event& e : sink.events) {
    EXPECT_NEAR(e.t / dt, std::round(e.t / dt), 1e-6) << event_name(e.kind) << " at " << e.t;
  }
  // Located, the same run has events between the grid's points.
  RecordingSink located;
  (void)testing::run(s, Excitation::sine_pulse(1.2 * kStandardGravity, 0.5), 1.5, dt, &located);
  int off_grid = 0;
  for (const Event& e : located.events)
    off_grid += std::fabs(e.t / dt - std::round(e.t / dt)) > 1e-3;
  EXPECT_GT(off_grid, 0);
}

// Heun and semi-implicit Euler have their own stability limits, each refused above and stable
// below; semi-implicit Euler's on an undamped base is h omega = 2 (the base alone, m_b).
TEST(Steppers, EachStepperHasItsStabilityLimit) {
  const Scene undamped = make(testing::paper_isolated(0.0, 0.5, 0.0));
  const double omega_base = std::sqrt(undamped.stiffness / (undamped.total_mass - undamped.m));
  EXPECT_NEAR(largest_stable_step(undamped, Stepper::kSemiImplicitEuler), 2.0 / omega_base,
              1e-6 / omega_base);
  EXPECT_EQ(largest_stable_step(undamped, Stepper::kRk4StepEnd), largest_stable_step(undamped));
  SceneParams p = testing::paper_isolated(0.0, 0.05, 0.3);
  p.base.mass = 0.05 * p.block.mass;
  const Scene stiff = make(p);
  for (const Stepper stepper : {Stepper::kHeunLocated, Stepper::kSemiImplicitEuler}) {
    const double limit = largest_stable_step(stiff, stepper);
    ASSERT_GT(limit, 0.0);
    Simulator sim;
    const Error e = Simulator::create(stiff, Excitation::none(), with(stepper, 1.01 * limit), sim);
    EXPECT_STREQ(e.field, "solver.step") << stepper_name(stepper);
    EXPECT_DOUBLE_EQ(e.limit, limit);
    // Just below, a base set moving in sliding (the base alone) stays bounded.
    ASSERT_TRUE(
        Simulator::create(stiff, Excitation::none(), with(stepper, 0.95 * limit), sim).ok());
    State y = State::Zero();
    y[kUDot] = 0.1;
    sim.start_from({Phase::kFullContact}, y);
    double peak = 0.0;
    for (int i = 0; i < 20000; ++i) {
      sim.step();
      peak = std::max(peak, std::fabs(sim.state()[kU]));
    }
    EXPECT_LT(peak, 0.1) << stepper_name(stepper);
  }
}

// ---------------------------------------------------------------------------------------------
// The exact full-contact propagator

// Ground acceleration, piecewise linear between samples 0.01 s apart (a record's form).
std::vector<double> piecewise_linear_input(double amplitude) {
  std::vector<double> a;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 300; ++i) a.push_back(amplitude * unit(rng));
  return a;
}

State full_contact_at(const Scene& s, const Excitation& ex, double t_end,
                      const SolverSettings& st) {
  Simulator sim;
  if (!Simulator::create(s, ex, st, sim).ok()) __builtin_trap();
  sim.start_at_rest();
  while (sim.time() < t_end - 0.5 * st.step) sim.step();
  EXPECT_EQ(sim.mode().phase, Phase::kFullContact);
  return sim.state();
}

TEST(ExactFullContact, IsExactForPiecewiseLinearInputAtAnyStep) {
  const Scene s = make(testing::paper_isolated(0.0, 1.0, 0.1));
  const std::vector<double> a = piecewise_linear_input(2.0);  // below every onset
  const Excitation ex = Excitation::record({a.data(), a.size(), 0.01});
  const State reference = full_contact_at(s, ex, 2.5, with(Stepper::kRk4Located, 1e-5));
  for (const double dt : {1e-2, 5e-3, 1e-3}) {
    for (const Stepper stepper : kAllSteppers) {
      const State exact = full_contact_at(s, ex, 2.5, with(stepper, dt, true));
      EXPECT_NEAR(exact[kU], reference[kU], 1e-12) << dt << " " << stepper_name(stepper);
      EXPECT_NEAR(exact[kUDot], reference[kUDot], 1e-11) << dt << " " << stepper_name(stepper);
    }
  }
  // Not trivially: RK4 itself at 1e-2 s is off by more.
  const State rk4 = full_contact_at(s, ex, 2.5, with(Stepper::kRk4Located, 1e-2));
  EXPECT_GT(std::fabs(rk4[kU] - reference[kU]), 1e-9);
}

TEST(ExactFullContact, PhiIsTheDampedOscillatorsTransition) {
  const Scene s = make(testing::paper_isolated(0.0, 2.0, 0.2));
  const double w = s.omega, xi = s.params.base.damping_ratio, wd = w * std::sqrt(1.0 - xi * xi);
  for (const double h : {1e-4, 1e-2, 0.5}) {
    const FullContactPropagator p = FullContactPropagator::make(s, h);
    const double e = std::exp(-xi * w * h), c = std::cos(wd * h), sn = std::sin(wd * h);
    EXPECT_NEAR(p.phi[0][0], e * (c + xi * w / wd * sn), 1e-14);
    EXPECT_NEAR(p.phi[0][1], e * sn / wd, 1e-14);
    EXPECT_NEAR(p.phi[1][0], -e * w * w / wd * sn, 1e-13);
    EXPECT_NEAR(p.phi[1][1], e * (c - xi * w / wd * sn), 1e-14);
    // A constant input a gives the static response -a / omega^2 in the long run; over one
    // step, (Gamma0 + Gamma1) a is the response from rest to a held constant.
    const double u_step = -(1.0 - e * (c + xi * w / wd * sn)) / (w * w);
    EXPECT_NEAR(p.gamma0[0] + p.gamma1[0], u_step, 1e-14);
  }
}

// The series stops early for short steps (full_contact_propagator.cpp) yet every coefficient
// keeps its relative accuracy, the small ones too (Gamma1's displacement is about -h^2 / 6): the
// same augmented exponential summed to 40 terms in long double is the reference.
TEST(ExactFullContact, ShortStepsKeepEveryCoefficientToRoundings) {
  const Scene s = make(testing::paper_isolated(0.0, 2.0, 0.2));
  for (const double h : {1e-7, 1e-6, 2.5e-4, 1e-3, 1e-2, 0.5}) {
    long double a[4][4] = {};
    a[0][1] = 1.0L;
    a[1][0] = -static_cast<long double>(s.stiffness / s.total_mass);
    a[1][1] = -static_cast<long double>(s.damping / s.total_mass);
    a[1][2] = -1.0L;
    a[2][3] = 1.0L;
    long double sum[4][4] = {}, term[4][4] = {};
    for (int i = 0; i < 4; ++i) sum[i][i] = term[i][i] = 1.0L;
    for (int n = 1; n <= 40; ++n) {
      long double next[4][4] = {};
      for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) {
          for (int k = 0; k < 4; ++k) next[i][j] += term[i][k] * a[k][j] * h / n;
        }
      }
      for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) sum[i][j] += (term[i][j] = next[i][j]);
      }
    }
    const FullContactPropagator p = FullContactPropagator::make(s, h);
    // 4 roundings; 16 where scaling and squaring (|a h| > 1/2) compounds them.
    const double rel = (h < 0.1 ? 4.0 : 16.0) * std::numeric_limits<double>::epsilon();
    for (int i = 0; i < 2; ++i) {
      const double gamma1 = static_cast<double>(sum[i][3] / h);
      const double gamma0 = static_cast<double>(sum[i][2]) - gamma1;
      EXPECT_NEAR(p.phi[i][0], static_cast<double>(sum[i][0]), rel * std::fabs(p.phi[i][0]));
      EXPECT_NEAR(p.phi[i][1], static_cast<double>(sum[i][1]), rel * std::fabs(p.phi[i][1]));
      EXPECT_NEAR(p.gamma1[i], gamma1, rel * std::fabs(gamma1)) << h << " row " << i;
      EXPECT_NEAR(p.gamma0[i], gamma0, rel * std::fabs(gamma0)) << h << " row " << i;
    }
  }
}

// Onset located on the exact solution: with a piecewise-linear input the rocking onset time at
// a step of 5 ms is the fine reference's.
TEST(ExactFullContact, OnsetIsLocatedOnTheExactSolution) {
  const Scene s = make(testing::paper_isolated(0.0, 1.0, 0.1));
  std::vector<double> a;  // a sine sampled every 0.01 s, near the base's resonance
  for (int i = 0; i < 400; ++i) a.push_back(2.5 * std::sin(2.0 * std::numbers::pi * 0.01 * i));
  const Excitation ex = Excitation::record({a.data(), a.size(), 0.01});
  RecordingSink fine;
  (void)testing::run(s, ex, 3.0, 1e-5, &fine);
  const Event* reference = fine.first(EventKind::kRockingStart);
  ASSERT_NE(reference, nullptr);
  for (const Stepper stepper :
       {Stepper::kRk4Located, Stepper::kHeunLocated, Stepper::kSemiImplicitEuler}) {
    RecordingSink sink;
    (void)testing::run(s, ex, 3.0, 5e-3, &sink, 0.0, with(stepper, 5e-3, true));
    const Event* onset = sink.first(EventKind::kRockingStart);
    ASSERT_NE(onset, nullptr);
    EXPECT_NEAR(onset->t, reference->t, 1e-10) << stepper_name(stepper);
  }
}

}  // namespace

// Reaches the simulator's quiet full-contact step (simulator.h befriends it).
struct SimulatorTestPeer {
  static void take_every_step_by_intervals(Simulator& sim) {
    sim.quiet_full_contact_step_fn_ = nullptr;
  }
};

namespace {

// The quiet full-contact step (Simulator::step, exact_full_contact) skips the flow point and the
// guard values the interval keeps; its states and events are the interval's to the last bit, in
// every feature configuration, through onsets, impacts, stops and back to full contact.
TEST(ExactFullContact, QuietStepsAreTheIntervalsToTheLastBit) {
  SceneParams stops = testing::paper_isolated();
  stops.has_base_stops = true;
  stops.base_stops = {0.05, 0.7};
  SceneParams everything = stops;
  everything.has_friction = true;
  everything.friction = {0.3, 0.24};
  everything.has_support = true;
  everything.support = {0.1};
  everything.has_sliding_stops = true;
  SceneParams edge = everything;
  edge.has_sliding_stops = false;
  const host::Record record = testing::brienza();
  int returns = 0;  // back to full contact after leaving it, over all runs
  int events = 0;
  for (const double pga_g : {1.0, 2.0, 2.5}) {
    const Excitation ex = Excitation::record(record.horizontal_signal(), {},
                                             pga_g * kStandardGravity / record.peak_horizontal());
    for (const SceneParams& p : {testing::paper_isolated(), stops, everything, edge}) {
      const Scene s = make(p);
      Simulator quiet;
      Simulator intervals;
      const SolverSettings settings = with(Stepper::kRk4Located, 1e-3, true);
      ASSERT_TRUE(Simulator::create(s, ex, settings, quiet).ok());
      ASSERT_TRUE(Simulator::create(s, ex, settings, intervals).ok());
      SimulatorTestPeer::take_every_step_by_intervals(intervals);
      RecordingSink quiet_events;
      RecordingSink interval_events;
      quiet.set_event_sink(&quiet_events);
      intervals.set_event_sink(&interval_events);
      quiet.start_at_rest();
      intervals.start_at_rest();
      int differing = 0;
      while (quiet.time() < 20.0 && !quiet.mode().terminal()) {
        quiet.step();
        intervals.step();
        differing += quiet.state() != intervals.state() ? 1 : 0;
      }
      EXPECT_EQ(differing, 0) << pga_g;
      EXPECT_EQ(quiet.step_count(), intervals.step_count());
      ASSERT_EQ(quiet_events.events.size(), interval_events.events.size());
      for (std::size_t i = 0; i < quiet_events.events.size(); ++i) {
        EXPECT_EQ(quiet_events.events[i].t, interval_events.events[i].t);
        EXPECT_EQ(quiet_events.events[i].kind, interval_events.events[i].kind);
      }
      events += static_cast<int>(quiet_events.events.size());
      returns += quiet_events.count(EventKind::kRockingStop) +
                 quiet_events.count(EventKind::kSlidingStop);
    }
  }
  EXPECT_GE(returns, 2);
  EXPECT_GE(events, 20);
}

// A whole step goes from t0 = n step to t_end = (n + 1) step (Simulator::step); in double its
// length t_end - t0 is exact (Sterbenz: t0 <= t_end <= 2 t0 from n = 1), so t0 + h is t_end: the
// quiet step and a whole step's interval take the ground at t_end without checking it.
TEST(ExactFullContact, WholeStepsEndAtTheirEndExactly) {
  for (const double rate_hz : {100.0, 200.0, 344.8275862068966, 1000.0}) {
    for (const int steps : {1, 3, 4, 7, 64}) {
      const Time step = 1.0 / rate_hz / steps;
      for (std::int64_t n = 0; n < 2000000; n += (n < 100000 ? 1 : 997)) {
        const Time t0 = static_cast<Time>(n) * step;
        const Time t_end = static_cast<Time>(n + 1) * step;
        ASSERT_EQ(t0 + (t_end - t0), t_end) << rate_hz << " Hz, " << steps << " steps, n " << n;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The fast forms of the flows against straightforward Eigen ones

// sin_cos (flows.h): the table and the angle-addition formulas against libm, over the whole
// range a block turns through and past the table's ends (where it is libm itself).
TEST(FastFlows, SinCosIsWithinTwoRoundingsOfLibm) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double theta = (i % 10 == 0 ? 3.0 : 1.65) * unit(rng);
    const SinCos t = sin_cos(theta);
    worst =
        std::max({worst, std::fabs(t.sin - std::sin(theta)), std::fabs(t.cos - std::cos(theta))});
  }
  std::printf("worst |error| %.2e\n", worst);
  EXPECT_LE(worst, 2.3e-16);  // two roundings of numbers below 1
  const SinCos zero = sin_cos(0.0);
  EXPECT_EQ(zero.sin, 0.0);
  EXPECT_EQ(zero.cos, 1.0);
  EXPECT_EQ(sin_cos(1e-300).sin, 1e-300);
  EXPECT_TRUE(std::isnan(sin_cos(std::nan("")).sin));
}

// bounded_sin_cos (bounded_trig.h, the float build's sin and cos) against libm's double sin and
// cos of the same float argument: the block's angles and a pulse's phase to two roundings of the
// result (float's epsilon is 1.2e-7), and the whole range, near every multiple of pi / 2
// included, to that or 3e-11 absolute (the reduction's error grows with the quadrant).
TEST(FastFlows, BoundedSinCosIsWithinTwoRoundingsOfLibm) {
  constexpr double kTwoRoundings = 2.0 * double{std::numeric_limits<float>::epsilon()};
  // |error| of sin and cos at x, less two roundings of the exact value, in units of `absolute`.
  const auto excess = [&](float x, double absolute) {
    const FloatSinCos t = bounded_sin_cos(x);
    const double s = std::sin(static_cast<double>(x));
    const double c = std::cos(static_cast<double>(x));
    return std::max((std::fabs(static_cast<double>(t.sin) - s) - kTwoRoundings * std::fabs(s)),
                    (std::fabs(static_cast<double>(t.cos) - c) - kTwoRoundings * std::fabs(c))) /
           absolute;
  };
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  // The block's angles and a pulse's phase: two roundings of the result (1e-30: nothing more).
  for (const double range : {1e-3, 0.8, 1.7, 2.0 * std::numbers::pi}) {
    double worst = -1.0;
    for (int i = 0; i < 200000; ++i) {
      worst = std::max(worst, excess(static_cast<float>(range * unit(rng)), 1e-30));
    }
    EXPECT_LE(worst, 0.0) << "range " << range;
  }
  // The whole range, and next to each multiple of pi / 2 (the smallest reduced arguments): two
  // roundings or 3e-11.
  double worst = -1.0;
  for (int i = 0; i < 400000; ++i) {
    const double range = bounded_trig::kRange;
    worst = std::max(worst, excess(static_cast<float>(range * unit(rng)), 3e-11));
  }
  for (int k = -5215; k <= 5215; ++k) {
    const auto x = static_cast<float>(k * std::numbers::pi / 2);
    for (const float y : {std::nextafter(x, -1e9F), x, std::nextafter(x, 1e9F)}) {
      if (std::fabs(y) <= bounded_trig::kRange) worst = std::max(worst, excess(y, 3e-11));
    }
  }
  EXPECT_LE(worst, 1.0);
  EXPECT_EQ(bounded_sin_cos(0.0F).sin, 0.0F);
  EXPECT_EQ(bounded_sin_cos(0.0F).cos, 1.0F);
  EXPECT_EQ(bounded_sin_cos(1e-30F).sin, 1e-30F);
  EXPECT_TRUE(std::isnan(bounded_sin_cos(std::nanf("")).sin));
  EXPECT_TRUE(std::isnan(bounded_sin_cos(std::numeric_limits<float>::infinity()).cos));
  EXPECT_TRUE(std::isnan(bounded_sin_cos(std::nextafter(bounded_trig::kRange, 1e9F)).sin));
  EXPECT_FALSE(std::isnan(bounded_sin_cos(-bounded_trig::kRange).sin));
}

// lever_arms_turned (the rocking kernel's stages) against Eq 9 with libm's sin and cos, over
// the angles a block turns through and every turn a stage makes (|d| <= kStageAngle).
TEST(FastFlows, TurnedLeverArmsAreEq9ToRoundings) {
  const Scene s = make(testing::paper_isolated(0.3));
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double offset = i % 2 == 0 ? s.corner1.offset : s.corner2.offset;
    const double theta0 = 1.6 * unit(rng);
    const double d = kStageAngle * unit(rng);
    const LeverArms at0 = lever_arms(s, offset, SinCos{std::sin(theta0), std::cos(theta0)});
    const LeverArms turned = lever_arms_turned(at0, d);
    const LeverArms exact =
        lever_arms(s, offset, SinCos{std::sin(theta0 + d), std::cos(theta0 + d)});
    worst = std::max({worst, std::fabs(turned.horizontal - exact.horizontal),
                      std::fabs(turned.vertical - exact.vertical)});
  }
  std::printf("worst |error| %.2e m (lever arms up to %.2f m)\n", worst, s.corner1.radius);
  EXPECT_LE(worst, 4.0 * std::numeric_limits<double>::epsilon() * s.corner1.radius);
}

TEST(FastFlows, SlideRockingMatchesAnLuSolveOfTheMatrices) {
  SceneParams p = testing::paper_isolated(0.3);
  p.has_friction = true;
  p.friction = {0.5, 0.4};
  p.has_support = true;
  p.support = {0.1};
  const Scene s = make(p);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 500; ++i) {
    const bool overhanging = i % 2 == 1;
    const bool base_moves = i % 3 != 0;
    State y;
    y << 0.1 * unit(rng), overhanging ? -0.1 - 0.1 * std::fabs(unit(rng)) : 0.09 * unit(rng),
        0.3 * std::fabs(unit(rng)), unit(rng), unit(rng), unit(rng);
    const GroundAcceleration ag{5.0 * unit(rng), 2.0 * unit(rng)};
    const int direction = unit(rng) > 0.0 ? 1 : -1;
    const Pivot pivot = pivot_of(s, Corner::kLeft, overhanging ? -1 : 0, y[kX]);
    // The reference: the matrices of slide_rocking_matrices and a pivoted LU.
    const ContactKinematics k = contact_kinematics(s, pivot.geometry, overhanging, y);
    const SlideRockingMatrices m = slide_rocking_matrices(s, k, direction);
    const Eigen::Vector2d free(k.bias.x() + ag.horizontal, k.bias.y() + ag.vertical + s.g);
    Eigen::Matrix3d mass = m.with_friction;
    Eigen::Vector3d force = -s.m * (k.jx * free.x() + k.jy * free.y());
    force[0] -= (s.total_mass - s.m) * ag.horizontal + s.damping * y[kUDot] + s.stiffness * y[kU];
    force[1] -= s.params.friction.kinetic_coefficient * direction * s.m * k.normal.dot(free);
    if (!base_moves) {
      mass.row(0) << 1.0, 0.0, 0.0;
      mass.col(0) << 1.0, 0.0, 0.0;
      force[0] = 0.0;
    }
    const Eigen::Vector3d expected = mass.partialPivLu().solve(force);
    const Accelerations a =
        slide_rocking_flow(s, pivot.geometry, overhanging, direction, y, ag, base_moves);
    const double scale = 1.0 + expected.cwiseAbs().maxCoeff();
    EXPECT_NEAR(a.u, base_moves ? expected[0] : 0.0, 1e-12 * scale) << i;
    EXPECT_NEAR(a.x, expected[1], 1e-12 * scale) << i;
    EXPECT_NEAR(a.theta, expected[2], 1e-12 * scale) << i;
    EXPECT_NEAR(sliding_consistency(s, pivot, direction, y),
                m.with_friction.determinant() / m.frictionless.determinant(), 1e-12)
        << i;
  }
}

TEST(FastFlows, RockingMatchesA2x2Solve) {
  const Scene s = make(testing::paper_isolated(-0.4));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    State y;
    y << 0.1 * unit(rng), 0.0, 0.3 * unit(rng), unit(rng), 0.0, unit(rng);
    const GroundAcceleration ag{5.0 * unit(rng), 2.0 * unit(rng)};
    const CornerGeometry& c = s.corner(i % 2 == 0 ? Corner::kLeft : Corner::kRight);
    const double sn = std::sin(y[kTheta]), cs = std::cos(y[kTheta]);
    const double bx = c.offset * cs - s.h * sn, hy = c.offset * sn + s.h * cs;
    Eigen::Matrix2d mass;
    mass << s.total_mass, -s.m * hy, -s.m * hy, c.inertia;
    const Eigen::Vector2d force(-s.total_mass * ag.horizontal - s.damping * y[kUDot] -
                                    s.stiffness * y[kU] + s.m * y[kThetaDot] * y[kThetaDot] * bx,
                                s.m * hy * ag.horizontal - s.m * (s.g + ag.vertical) * bx);
    const Eigen::Vector2d expected = mass.partialPivLu().solve(force);
    const Accelerations a = rocking_flow(s, c, y, ag, true);
    EXPECT_NEAR(a.u, expected[0], 1e-12 * (1.0 + std::fabs(expected[0])));
    EXPECT_NEAR(a.theta, expected[1], 1e-12 * (1.0 + std::fabs(expected[1])));
  }
}

// ---------------------------------------------------------------------------------------------
// Only what the scene needs: the solver of a scene with a feature it never engages (stops never
// reached, friction that never lets go, a support edge or sliding stops far away) gives the run
// of the scene without it. Stops only add guards: bit for bit. Friction also makes the impacts
// Coulomb impacts (resets.h), which reduce to Eqs 21-24 when the corner sticks: to roundings,
// which dozens of impacts amplify (up to 2.4e-12 with semi-implicit Euler): within 1e-11.
constexpr double kRoundingsAfterImpacts = 1e-11;

struct RecordRun {
  std::vector<Event> events;
  State state;
};

RecordRun run_on_record(const SceneParams& p, const host::Record& record, double pga_g,
                        Stepper stepper) {
  const Scene s = make(p);
  RecordingSink sink;
  const Excitation ex = Excitation::record(record.horizontal_signal(), {},
                                           pga_g * kStandardGravity / record.peak_horizontal());
  const Simulator sim = testing::run(s, ex, 12.0, 1e-4, &sink, 0.0, with(stepper, 1e-4));
  return {sink.events, sim.state()};
}

// The largest difference of the states (m, rad, m/s, rad/s: all of order 1 here) and of the
// event times relative to the time (s / s).
double largest_difference(const RecordRun& a, const RecordRun& b) {
  double worst = (a.state - b.state).cwiseAbs().maxCoeff();
  for (std::size_t i = 0; i < a.events.size(); ++i) {
    worst =
        std::max({worst, std::fabs(a.events[i].t - b.events[i].t) / std::max(1.0, a.events[i].t),
                  (a.events[i].state - b.events[i].state).cwiseAbs().maxCoeff()});
  }
  return worst;
}

TEST(OnlyWhatTheSceneNeeds, UnusedFeaturesGiveTheSameRun) {
  const host::Record record = testing::brienza();
  struct Base {
    SceneParams params;
    double pga_g;
  };
  for (const Base& base :
       {Base{testing::paper_isolated(), 3.0}, Base{testing::paper_block(), 0.5}}) {
    SceneParams far_stops = base.params;
    far_stops.has_base_stops = true;
    far_stops.base_stops = {10.0, 0.7};  // u_max = 10 m
    SceneParams sticking = base.params;
    sticking.has_friction = true;
    sticking.friction = {10.0, 8.0};  // far above any demand of this input
    SceneParams far_edge = sticking;
    far_edge.has_support = true;
    far_edge.support = {10.0};  // x_hat = 10 m
    SceneParams far_sliding_stops = far_edge;
    far_sliding_stops.has_sliding_stops = true;
    far_sliding_stops.sliding_stops = {0.7};
    for (const Stepper stepper : kAllSteppers) {
      const RecordRun plain = run_on_record(base.params, record, base.pga_g, stepper);
      ASSERT_GE(plain.events.size(), 10u) << "the input must make the block rock";
      if (base.params.has_base) {
        const RecordRun with_stops = run_on_record(far_stops, record, base.pga_g, stepper);
        ASSERT_EQ(with_stops.events.size(), plain.events.size());
        EXPECT_EQ(largest_difference(plain, with_stops), 0.0) << stepper_name(stepper);
      }
      for (const SceneParams* p : {&sticking, &far_edge, &far_sliding_stops}) {
        const RecordRun other = run_on_record(*p, record, base.pga_g, stepper);
        ASSERT_EQ(other.events.size(), plain.events.size()) << stepper_name(stepper);
        for (std::size_t i = 0; i < other.events.size(); ++i) {
          ASSERT_EQ(other.events[i].kind, plain.events[i].kind);
        }
        const double difference = largest_difference(plain, other);
        std::printf("%s, %s: largest difference %.2e\n", base.params.has_base ? "base" : "ground",
                    stepper_name(stepper), difference);
        EXPECT_LE(difference, kRoundingsAfterImpacts) << stepper_name(stepper);
      }
    }
  }
}


// "A scene that cannot slide runs without the sliding machinery": in this model no finite
// friction in the range the solver is tested over (mu_s up to 2, PGA up to 5 g) rules sliding
// out, so only a scene without [friction] (the block held whatever the force) drops it.
//  - Full contact: rocking starts first once mu_s > b_i / h (Eq 39), and the impact at theta = 0
//    of a rocking block needs only |Pt| / Pn < b / h to stick (checked below), but
//  - while rocking, Eq 18's ratio |X| / Y grows without bound as the ground accelerates the block
//    towards lift-off (Y -> 0): a block of slenderness 3 with mu_s = 2 starts sliding out of pure
//    rocking under one-sine pulses of 3 to 5 g.
TEST(OnlyWhatTheSceneNeeds, NoFrictionUpToTwoRulesOutSliding) {
  SceneParams p = testing::paper_block();
  p.has_friction = true;
  p.friction = {2.0, 1.6};
  const Scene s = make(p);
  ASSERT_TRUE(features_of(s).sliding);
  for (const double pga_g : {3.0, 4.0, 5.0}) {
    RecordingSink sink;
    (void)testing::run(s, Excitation::sine_pulse(pga_g * kStandardGravity, 0.5), 1.0, 1e-4, &sink);
    const Event* rocking = sink.first(EventKind::kRockingStart);
    const Event* sliding = sink.first(EventKind::kSlidingStart);
    ASSERT_NE(rocking, nullptr) << pga_g;
    ASSERT_NE(sliding, nullptr) << pga_g << " g: no sliding with mu_s = 2";
    EXPECT_LT(rocking->t, sliding->t);
    EXPECT_EQ(sliding->phase, Phase::kSlideRocking) << "out of pure rocking (Eq 18)";
    EXPECT_EQ(sink.count(EventKind::kImpact), 0) << "not through an impact";
  }
  // The impact's stick ratio, for the record: below b / h, so impacts alone never slide.
  for (const bool on_base : {false, true}) {
    SceneParams q = on_base ? testing::paper_isolated() : testing::paper_block();
    q.has_friction = true;
    q.friction = {100.0, 80.0};
    const Scene t = make(q);
    Mode mode{Phase::kRocking, Corner::kLeft, 0};
    State y = State::Zero();
    y[kThetaDot] = -1.0;
    const CoulombImpact impact = coulomb_impact_reset(t, on_base, mode, y);
    EXPECT_TRUE(impact.sticks);
    EXPECT_LT(std::fabs(impact.tangential_impulse / impact.normal_impulse), t.b / t.h) << on_base;
  }
  // Without [friction] the scene has no sliding machinery at all.
  EXPECT_FALSE(features_of(make(testing::paper_block())).sliding);
}

}  // namespace
}  // namespace plinth

// The whole model (Section 3): sliding, slide-rocking, the support's edge, falling, sliding
// stops, and the paper's printed equations checked against the flows.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "plinth/core/energy.h"
#include "plinth/core/internal/flows.h"
#include "plinth/core/internal/resets.h"
#include "plinth/core/stability.h"
#include "test_support.h"

namespace plinth {
namespace {

using internal::base_stop_reset;
using internal::contact_kinematics;
using internal::ContactKinematics;
using internal::coulomb_impact_reset;
using internal::CoulombImpact;
using internal::lever_arms;
using internal::Pivot;
using internal::pivot_of;
using internal::rocking_impact_reset;
using internal::slide_rocking_flow;
using internal::sliding_stop_hit_reset;
using testing::make;
using testing::RecordingSink;

using testing::with_friction;

// A sampled harmonic ground acceleration A sin(omega t), fine enough that the linear
// interpolation error (~ (omega dt)^2 / 8) stays below 1e-8.
struct Harmonic {
  std::vector<double> samples;
  double dt;
  Harmonic(double amplitude, double period, double duration, double step = 1e-4) : dt(step) {
    const auto n = static_cast<std::size_t>(duration / step) + 1;
    samples.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      samples[i] = amplitude * std::sin(2.0 * std::numbers::pi * static_cast<double>(i) * step / period);
    }
  }
  [[nodiscard]] Excitation excitation() const {
    return Excitation::record({samples.data(), samples.size(), dt});
  }
};

// Frictionless sliding: the block stays still in the inertial frame while the base moves.
TEST(Sliding, FrictionlessBlockStaysStillInTheInertialFrame) {
  const Scene s = make(with_friction(testing::paper_isolated(0.0, 1.0), 0.0, 0.0));
  const double amplitude = 3.0, period = 0.8;
  SolverSettings settings;
  settings.step = 1e-3;
  Simulator sim;
  ASSERT_TRUE(Simulator::create(s, Excitation::sine_pulse(amplitude, period), settings, sim).ok());
  sim.start_at_rest();
  double worst = 0.0;
  double base_peak = 0.0;
  while (sim.time() < 3.0) {
    sim.step();
    base_peak = std::max(base_peak, std::fabs(sim.state()[kU]));
    const double t = std::min(sim.time(), period);
    const double ground_velocity =
        amplitude * period / (2.0 * std::numbers::pi) * (1.0 - std::cos(2.0 * std::numbers::pi * t / period));
    worst = std::max(worst, std::fabs(ground_velocity + sim.state()[kUDot] + sim.state()[kXDot]));
    ASSERT_TRUE(sim.mode().sliding()) << "t = " << sim.time();
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(base_peak, 0.01) << "the base must have moved";
}

// Eq 15: on fixed ground, sliding starts exactly when |u_G''| reaches mu_s (g + v_G'').
TEST(Sliding, OnsetTimeIsEq15Exactly) {
  for (const double sign : {1.0, -1.0}) {
    const Scene s = make(with_friction(testing::paper_block(0.0), 0.2, 0.16));
    const double amplitude = sign * 0.3 * s.g, period = 0.5;
    RecordingSink sink;
    testing::run(s, Excitation::sine_pulse(amplitude, period), 0.3, 1e-3, &sink);
    const Event* onset = sink.first(EventKind::kSlidingStart);
    ASSERT_NE(onset, nullptr);
    EXPECT_NEAR(onset->t, period / (2.0 * std::numbers::pi) * std::asin(0.2 / 0.3), 1e-12);
    EXPECT_EQ(onset->side, sign > 0.0 ? -1 : 1) << "the block lags the ground";
    EXPECT_EQ(sink.first(EventKind::kRockingStart), nullptr) << "mu_s < b/h: no rocking";
  }
}

// Continuous two-way sliding of a block on harmonically moving ground (Den Hartog): with
// mu_s = mu_k = mu and A > 1.86 mu g, the block never sticks, and in the steady state x'
// changes sign where cos(omega t) = -+ pi mu g / (2 A).
TEST(Sliding, SteadyTwoWaySlidingMatchesTheClosedForm) {
  const double mu = 0.2, period = 0.5;
  const Scene s = make(with_friction(testing::paper_block(0.0), mu, mu));
  const double amplitude = 3.0 * mu * s.g;
  const Harmonic ground(amplitude, period, 12.0);
  RecordingSink sink;
  testing::run(s, ground.excitation(), 12.0, 1e-4, &sink);
  const double omega = 2.0 * std::numbers::pi / period;
  const double reversal = std::acos(std::numbers::pi * mu * s.g / (2.0 * amplitude));
  int checked = 0;
  for (const Event& e : sink.events) {
    ASSERT_NE(e.kind, EventKind::kSlidingStop) << "the block must never stick, t = " << e.t;
    if (e.kind != EventKind::kSlidingStart || e.t < 6.0) continue;  // past the transient
    // x' turns positive at phase pi + acos(pi mu g / (2A)) (cos = -pi mu g / (2A) with x''
    // > 0 there), and negative half a period later.
    const double phase = std::fmod(omega * e.t, 2.0 * std::numbers::pi);
    const double expected = e.side > 0 ? std::numbers::pi + reversal : reversal;
    EXPECT_NEAR(std::remainder(phase - expected, 2.0 * std::numbers::pi), 0.0, 1e-6)
        << "t = " << e.t << ", direction " << static_cast<int>(e.side);
    ++checked;
  }
  EXPECT_GE(checked, 20);
}

// Stick-slip: with mu_s > mu_k the block sticks when x' returns to 0 and static friction holds.
TEST(Sliding, SticksWhenStaticFrictionHolds) {
  const Scene s = make(with_friction(testing::paper_block(0.0), 0.25, 0.2));
  RecordingSink sink;
  const Simulator sim =
      testing::run(s, Excitation::sine_pulse(0.4 * s.g, 0.5), 3.0, 1e-3, &sink);
  ASSERT_NE(sink.first(EventKind::kSlidingStop), nullptr);
  EXPECT_EQ(sim.mode().phase, Phase::kFullContact);
  EXPECT_EQ(sim.state()[kXDot], 0.0);
  EXPECT_NE(sim.state()[kX], 0.0);
}

// Eqs 10-12 and 13-14, as printed, hold for the accelerations the slide-rocking flow returns
// (the flow is assembled from the kinematics of C instead).
TEST(SlideRocking, PrintedEquationsHoldForTheFlow) {
  SceneParams p = with_friction(testing::paper_isolated(0.3), 0.5, 0.4);
  p.has_support = true;
  p.support = {0.1};
  const Scene s = make(p);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const bool overhanging = i % 2 == 1;
    const double x = overhanging ? -0.1 - 0.2 * std::fabs(unit(rng)) : 0.09 * unit(rng);
    State y;
    y << 0.1 * unit(rng), x, 0.2 * std::fabs(unit(rng)), unit(rng), unit(rng), unit(rng);
    const GroundAcceleration ag{5.0 * unit(rng), 2.0 * unit(rng)};
    const int direction = unit(rng) > 0.0 ? 1 : -1;
    const Pivot pivot = pivot_of(s, Corner::kLeft, overhanging ? -1 : 0, x);
    ASSERT_EQ(pivot.overhanging, overhanging);
    const Accelerations a = slide_rocking_flow(s, pivot.geometry, overhanging, direction, y, ag, true);
    const double m = s.m, h = s.h, c = s.damping, k = s.stiffness, M = s.total_mass;
    const double th = y[kTheta], td = y[kThetaDot], xd = y[kXDot];
    const double b_hat = pivot.geometry.offset, inertia = pivot.geometry.inertia;
    const double bp = b_hat * std::cos(th) - h * std::sin(th);  // Eq 9
    const double hp = b_hat * std::sin(th) + h * std::cos(th);
    const double base = a.u + ag.horizontal, gv = s.g + ag.vertical;
    const double mu_k = s.params.friction.kinetic_coefficient;
    double r1, r2, r3;
    if (!overhanging) {
      const double y1 = m * gv + m * bp * a.theta - m * hp * td * td;  // Eq 12
      const double f1 = mu_k * direction * y1;                          // Eq 11
      r1 = m * (base + a.x) - m * a.theta * hp - m * td * td * bp + f1;  // Eq 10
      (void)xd;
      r2 = M * base + m * a.x + c * y[kUDot] + k * y[kU] - m * a.theta * hp - m * td * td * bp;
      r3 = inertia * a.theta - m * (base + a.x) * hp + m * gv * bp;
    } else {
      const double y1 = m * gv * std::cos(th) - m * base * std::sin(th) + 2.0 * m * xd * td +
                        m * b_hat * a.theta - m * h * td * td;  // Eq 14
      const double f1 = mu_k * direction * y1;
      r1 = m * base * std::cos(th) + m * a.x + m * gv * std::sin(th) - m * a.theta * h -
           m * td * td * b_hat + f1;  // Eq 13
      r2 = M * base + m * a.x * std::cos(th) + c * y[kUDot] + k * y[kU] - m * a.theta * hp -
           m * td * td * bp - 2.0 * m * xd * td * std::sin(th);
      r3 = inertia * a.theta - m * base * hp - m * a.x * h + m * gv * bp + 2.0 * m * xd * td * b_hat;
    }
    const double scale = m * (s.g + 10.0) * (1.0 + h);
    EXPECT_NEAR(r1, 0.0, 1e-10 * scale) << "Eq 10/13 first, sample " << i;
    EXPECT_NEAR(r2, 0.0, 1e-10 * scale) << "second, sample " << i;
    EXPECT_NEAR(r3, 0.0, 1e-10 * scale) << "third, sample " << i;
  }
}

// Undamped, frictionless, no ground motion: slide-rocking inside and overhanging the support
// conserves energy along the flow (the Coriolis terms of Eq 13 included).
TEST(SlideRocking, FrictionlessFlowConservesEnergy) {
  SceneParams p = with_friction(testing::paper_isolated(0.2, 2.0, 0.0), 0.0, 0.0);
  p.has_support = true;
  p.support = {0.1};
  const Scene s = make(p);
  for (const int overhang : {0, -1}) {
    Mode mode;
    mode.phase = Phase::kSlideRocking;
    mode.corner = Corner::kLeft;
    mode.overhang = static_cast<std::int8_t>(overhang);
    mode.slide_direction = 1;
    State y;
    y << 0.02, overhang != 0 ? -0.15 : 0.0, 0.1, 0.1, 0.05, 0.2;
    const double e0 = mechanical_energy(s, mode, y);
    const double dt = 1e-4;
    auto f = [&](const State& q) {
      const Pivot pv = pivot_of(s, mode, q);
      const Accelerations a = slide_rocking_flow(s, pv.geometry, pv.overhanging, 1, q, {}, true);
      State d;
      d << q[kUDot], q[kXDot], q[kThetaDot], a.u, a.x, a.theta;
      return d;
    };
    for (int i = 0; i < 3000; ++i) {  // 0.3 s, staying in the phase's valid range
      const State k1 = f(y), k2 = f(y + 0.5 * dt * k1), k3 = f(y + 0.5 * dt * k2), k4 = f(y + dt * k3);
      y += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    EXPECT_NEAR(mechanical_energy(s, mode, y), e0, 1e-10 * std::fabs(e0)) << "overhang " << overhang;
  }
}

SceneParams falling_scene(bool sliding_stops) {
  SceneParams p = with_friction(testing::paper_block(0.0), 0.15, 0.12);
  p.has_support = true;
  p.support = {0.1};
  if (sliding_stops) {
    p.has_sliding_stops = true;
    p.sliding_stops = {0.7};
  }
  return p;
}

// A long pulse pushes the block off the support: it falls when C passes the support's edge,
// whether sliding (b_hat = 0) or turning about the support's corner (theta = atan(b_hat / h)),
// and not before. With sliding stops the same input cannot make it fall.
TEST(Falling, LongPulsePushesTheBlockOffTheBase) {
  const Scene s = make(falling_scene(false));
  const Excitation pulse = Excitation::cosine_pulse(0.3 * s.g, 4.0);
  RecordingSink sink;
  const Simulator sim = testing::run(s, pulse, 10.0, 1e-3, &sink);
  const Event* out = sink.first(EventKind::kOutOfBase);
  const Event* fell = sink.first(EventKind::kFell);
  ASSERT_NE(out, nullptr);
  ASSERT_NE(fell, nullptr);
  EXPECT_EQ(sim.mode().phase, Phase::kFell);
  EXPECT_LT(out->t, fell->t);
  EXPECT_EQ(sink.first(EventKind::kOverturned), nullptr);
  // At the event C is right above the support's edge.
  Mode mode;
  mode.phase = Phase::kRocking;
  mode.corner = fell->corner;
  mode.overhang = fell->side;
  const Pivot edge = pivot_of(s, mode, fell->state);
  ASSERT_TRUE(edge.overhanging);
  EXPECT_NEAR(lever_arms(s, edge.geometry, fell->state[kTheta]).horizontal, 0.0, 1e-9);
  EXPECT_GT(std::fabs(fell->state[kX]), s.params.support.clearance);

  const Scene held = make(falling_scene(true));
  RecordingSink stopped;
  const Simulator safe = testing::run(held, pulse, 10.0, 1e-3, &stopped);
  EXPECT_EQ(stopped.first(EventKind::kFell), nullptr);
  EXPECT_NE(stopped.first(EventKind::kSlideStopHit), nullptr);
  EXPECT_NE(safe.mode().phase, Phase::kFell);
  EXPECT_LE(std::fabs(safe.state()[kX]), held.params.support.clearance + 1e-12);
}

// Horizontal momentum of base and block relative to the ground, m_b u' + m v_Cx, N s.
double horizontal_momentum(const Scene& s, const Mode& mode, const State& y) {
  const Pivot pivot = pivot_of(s, mode, y);
  const ContactKinematics k = contact_kinematics(s, pivot.geometry, pivot.overhanging, y);
  return (s.total_mass - s.m) * y[kUDot] + s.m * k.jx.dot(y.tail<3>());
}

// Random sliding (even draw i) and slide-rocking (odd i) states, sliding right: numbers drawn
// uniformly from [-1, 1), the corner and the tilt drawn in the same order every time.
class SlidingDraws {
 public:
  explicit SlidingDraws(std::mt19937::result_type seed) : rng_(seed) {}

  double operator()() { return unit_(rng_); }

  // Mode of draw i: the phase alternates, the corner is drawn.
  Mode mode(int i) {
    Mode m;
    m.phase = i % 2 == 0 ? Phase::kSliding : Phase::kSlideRocking;
    m.corner = unit_(rng_) > 0 ? Corner::kLeft : Corner::kRight;
    m.slide_direction = 1;
    return m;
  }

  // When `mode` rocks: a tilt toward its corner, up to 0.2 rad, and a tilt rate.
  void tilt(const Scene& s, const Mode& mode, State& y) {
    if (!mode.rocking()) return;
    y[kTheta] = s.corner(mode.corner).sign * 0.2 * std::fabs(unit_(rng_));
    y[kThetaDot] = unit_(rng_);
  }

 private:
  std::mt19937 rng_;
  std::uniform_real_distribution<double> unit_{-1.0, 1.0};
};

SceneParams with_sliding_stops(SceneParams p, double restitution) {
  p.has_support = true;
  p.support = {0.1};
  p.has_sliding_stops = true;
  p.sliding_stops = {restitution};
  return p;
}

// Sliding right, toward the right sliding stop.
Mode sliding_right() {
  Mode m;
  m.phase = Phase::kSliding;
  m.slide_direction = 1;
  return m;
}

// At the right sliding stop (x = 0.1, the support clearance of with_sliding_stops), the base
// moving at u' = `u_dot` and the block sliding at x' = `x_dot`.
State at_right_stop(double u_dot, double x_dot) {
  State y = State::Zero();
  y[kX] = 0.1;
  y[kUDot] = u_dot;
  y[kXDot] = x_dot;
  return y;
}

// Sliding stop hit (Eqs 30-32 with restitution, resets.h): x'+ = -eta_s x'-, the horizontal
// momentum kept for every eta_s, energy never grows and is kept at eta_s = 1; in sliding and
// slide-rocking alike.
TEST(SlidingStops, MomentumKeptEnergyNeverGrows) {
  SlidingDraws draw(5);
  for (const double eta : {0.0, 0.3, 0.7, 1.0}) {
    const Scene s =
        make(with_sliding_stops(with_friction(testing::paper_isolated(0.2), 0.3, 0.24), eta));
    for (int i = 0; i < 200; ++i) {
      Mode mode = draw.mode(i);
      State y = State::Zero();
      y[kX] = 0.1;
      y[kUDot] = draw();
      y[kXDot] = std::fabs(draw());
      draw.tilt(s, mode, y);
      const double momentum = horizontal_momentum(s, mode, y);
      const double energy = mechanical_energy(s, mode, y);
      const double x_dot = y[kXDot];
      sliding_stop_hit_reset(s, 1, true, mode, y);
      EXPECT_NEAR(horizontal_momentum(s, mode, y), momentum, 1e-12 * s.total_mass);
      EXPECT_NEAR(y[kXDot], -eta * x_dot, 1e-15);
      EXPECT_EQ(y[kX], 0.1);
      EXPECT_EQ(mode.slide_direction, -1);
      const double after = mechanical_energy(s, mode, y);
      EXPECT_LE(after, energy + 1e-12 * std::fabs(energy));
      if (eta == 1.0) {
        EXPECT_NEAR(after, energy, 1e-12 * std::fabs(energy));
      } else if (x_dot > 1e-3) {
        EXPECT_LT(after, energy);
      }
    }
  }
}

// At eta_s = 0 the stop is plastic: x'+ = 0 and u'+ = u'- + m x'- / (m + m_b), the printed
// Eq 32 with eta_s = 1.
TEST(SlidingStops, PlasticStopIsPrintedEq32WithEtaOne) {
  const Scene s =
      make(with_sliding_stops(with_friction(testing::paper_isolated(0.0), 0.3, 0.24), 0.0));
  Mode mode = sliding_right();
  State y = at_right_stop(-0.4, 0.9);
  sliding_stop_hit_reset(s, 1, true, mode, y);
  EXPECT_NEAR(y[kUDot], -0.4 + s.m / s.total_mass * 0.9, 1e-14);
  EXPECT_EQ(y[kXDot], 0.0);
}

// The printed Eq 32 with eta_s < 1 (x'+ = 0, u'+ = u'- + eta_s m x'- / (m + m_b)) removes
// momentum and adds energy when the base moves against the slide; the map we use does not.
TEST(SlidingStops, PrintedEq32WithEtaBelowOneAddsEnergy) {
  const double eta = 0.5;
  const Scene s =
      make(with_sliding_stops(with_friction(testing::paper_isolated(0.0), 0.3, 0.24), eta));
  Mode mode = sliding_right();
  // The block is still in the ground's frame, the base moves left.
  State y = at_right_stop(-1.0, 1.0);
  const double before = mechanical_energy(s, mode, y);
  State printed = y;
  printed[kUDot] += eta * s.m / s.total_mass * printed[kXDot];
  printed[kXDot] = 0.0;
  Mode stuck = mode;
  stuck.phase = Phase::kFullContact;
  EXPECT_GT(mechanical_energy(s, stuck, printed), before);
  sliding_stop_hit_reset(s, 1, true, mode, y);
  EXPECT_LE(mechanical_energy(s, mode, y), before);
}

// Random pre-impact states for the impact at theta = 0: sliding or not, either corner, inside
// the support or overhanging it.
struct ImpactCase {
  Mode mode;
  State y;
};

ImpactCase random_impact(const Scene& s, std::mt19937& rng, bool sliding) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  ImpactCase c;
  c.mode.phase = sliding ? Phase::kSlideRocking : Phase::kRocking;
  c.mode.corner = unit(rng) > 0 ? Corner::kLeft : Corner::kRight;
  c.y = State::Zero();
  c.y[kU] = 0.1 * unit(rng);
  c.y[kUDot] = unit(rng);
  if (s.params.has_support && unit(rng) > 0.0) {
    c.mode.overhang = static_cast<std::int8_t>(unit(rng) > 0 ? 1 : -1);
    c.y[kX] = c.mode.overhang * (s.params.support.clearance + 0.05 * std::fabs(unit(rng)));
  }
  if (sliding) {
    c.y[kXDot] = 2.0 * unit(rng);
    c.mode.slide_direction = static_cast<std::int8_t>(c.y[kXDot] > 0.0 ? 1 : -1);
  }
  // Returning to theta = 0 about the current corner.
  c.y[kThetaDot] = -s.corner(c.mode.corner).sign * std::fabs(unit(rng));
  return c;
}

// Impacts at theta = 0 with friction (coulomb_impact_reset): energy never grows, the horizontal
// momentum is kept, friction bounds the tangential impulse, and the outcome is consistent
// (sticking: x' = 0; sliding: x' has the sliding direction, |Pt| = mu_k Pn).
TEST(CoulombImpact, EnergyNeverGrowsMomentumKept) {
  std::mt19937 rng(9);
  int slid = 0;
  int stuck = 0;
  for (const double mu : {0.0, 0.2, 0.5, 1.5}) {
    SceneParams p = with_friction(testing::paper_isolated(0.25), mu, 0.8 * mu);
    p.has_support = true;
    p.support = {0.05};
    const Scene s = make(p);
    for (int i = 0; i < 500; ++i) {
      ImpactCase c = random_impact(s, rng, i % 2 == 0);
      const double energy = mechanical_energy(s, c.mode, c.y);
      const double momentum = horizontal_momentum(s, c.mode, c.y);
      const CoulombImpact r = coulomb_impact_reset(s, true, c.mode, c.y);
      EXPECT_LE(mechanical_energy(s, c.mode, c.y), energy + 1e-12 * std::fabs(energy));
      EXPECT_NEAR(horizontal_momentum(s, c.mode, c.y), momentum, 1e-12 * s.total_mass);
      EXPECT_GE(r.normal_impulse, 0.0);
      if (r.sticks) {
        ++stuck;
        EXPECT_EQ(c.mode.phase, Phase::kRocking);
        EXPECT_EQ(c.y[kXDot], 0.0);
        EXPECT_LE(std::fabs(r.tangential_impulse), mu * r.normal_impulse * (1 + 1e-12) + 1e-12);
      } else {
        ++slid;
        EXPECT_EQ(c.mode.phase, Phase::kSlideRocking);
        EXPECT_GT(c.y[kXDot] * c.mode.slide_direction, 0.0);
        EXPECT_NEAR(r.tangential_impulse, -c.mode.slide_direction * 0.8 * mu * r.normal_impulse,
                    1e-9 * r.normal_impulse + 1e-12);
      }
    }
  }
  EXPECT_GT(slid, 100);
  EXPECT_GT(stuck, 100);
}

// Without sliding, and friction enough to hold the new corner, the Coulomb impact is the
// rocking impact of Eqs 21-24 (corrected; resets.h), on the base and held.
TEST(CoulombImpact, WithoutSlidingIsEqs21To24) {
  std::mt19937 rng(3);
  SceneParams p = with_friction(testing::paper_isolated(0.3), 5.0, 4.0);
  p.has_support = true;
  p.support = {0.05};
  const Scene s = make(p);
  for (const bool base_moves : {true, false}) {
    for (int i = 0; i < 200; ++i) {
      ImpactCase c = random_impact(s, rng, false);
      if (!base_moves) c.y[kUDot] = 0.0;
      Mode mode = c.mode;
      State y = c.y;
      const CoulombImpact r = coulomb_impact_reset(s, base_moves, c.mode, c.y);
      rocking_impact_reset(s, base_moves, mode, y);
      ASSERT_TRUE(r.sticks);
      EXPECT_EQ(c.mode.corner, mode.corner);
      EXPECT_EQ(c.mode.phase, Phase::kRocking);
      for (Eigen::Index k = 0; k < 6; ++k) EXPECT_NEAR(c.y[k], y[k], 1e-12) << k;
    }
  }
}

// Section 3.3 keeps x' through an impact during slide-rocking (Eqs 21-22 with x' unchanged). The
// block's kinetic energy has the cross term -m h x' theta', so that map adds energy when the
// block slides fast the way C swings; the Coulomb impact on the same state does not.
TEST(SlideRocking, PrintedImpactKeepingXDotAddsEnergy) {
  const Scene s = make(with_friction(testing::paper_isolated(0.0), 0.4, 0.3));
  Mode mode;
  mode.phase = Phase::kSlideRocking;
  mode.corner = Corner::kLeft;
  mode.slide_direction = -1;
  State y = State::Zero();
  y[kThetaDot] = -0.5;  // returning to theta = 0 about corner 1
  y[kXDot] = -4.0;      // sliding fast the same way C moves
  const double before = mechanical_energy(s, mode, y);
  Mode printed_mode = mode;
  State printed = y;
  rocking_impact_reset(s, true, printed_mode, printed);
  printed_mode.phase = Phase::kSlideRocking;
  EXPECT_GT(mechanical_energy(s, printed_mode, printed), before);
  (void)coulomb_impact_reset(s, true, mode, y);
  EXPECT_LE(mechanical_energy(s, mode, y), before);
}

// Energy never grows across base stops while sliding or slide-rocking (the block keeps its
// absolute velocity while sliding).
TEST(SlidingResets, BaseStopEnergyNeverGrows) {
  SceneParams p = with_friction(testing::paper_isolated(0.25), 0.4, 0.3);
  p.has_base_stops = true;
  p.base_stops = {0.2, 0.7};
  const Scene s = make(p);
  SlidingDraws draw(9);
  for (int i = 0; i < 1000; ++i) {
    Mode mode = draw.mode(i);
    State y = State::Zero();
    y[kU] = 0.2;
    y[kUDot] = 2.0 * std::fabs(draw());
    y[kXDot] = draw();
    draw.tilt(s, mode, y);
    const double before = mechanical_energy(s, mode, y);
    State hit = y;
    base_stop_reset(s, 1, mode, hit);
    EXPECT_LE(mechanical_energy(s, mode, hit), before + 1e-12 * std::fabs(before));
    EXPECT_NEAR(hit[kUDot], -0.7 * y[kUDot], 1e-15);
    if (mode.phase == Phase::kSliding) {
      EXPECT_NEAR(hit[kUDot] + hit[kXDot], y[kUDot] + y[kXDot], 1e-12);
    }
  }
}

}  // namespace
}  // namespace plinth

namespace plinth {
namespace {

// The whole model is mirror-symmetric: (epsilon, input) mirrored gives the response mirrored,
// through sliding, slide-rocking, the support's edge and base stops.
TEST(WholeModel, MirroredSceneAndInputGiveTheMirroredResponse) {
  for (const bool sliding_stops : {false, true}) {
    SceneParams p = testing::paper_isolated(0.3, 1.0);
    p.has_friction = true;
    p.friction = {0.25, 0.2};
    p.has_support = true;
    p.support = {0.05};
    p.has_sliding_stops = sliding_stops;
    p.sliding_stops = {1.0};
    p.has_base_stops = true;
    p.base_stops = {0.06, 0.7};
    SceneParams q = p;
    q.block.eccentricity = -p.block.eccentricity;
    const Scene s = testing::make(p);
    const Scene mirrored = testing::make(q);
    const Excitation pulse = Excitation::sine_pulse(0.9 * kStandardGravity, 0.8);
    const Excitation mirrored_pulse = Excitation::sine_pulse(-0.9 * kStandardGravity, 0.8);
    testing::RecordingSink a;
    testing::RecordingSink b;
    const Simulator sa = testing::run(s, pulse, 4.0, 1e-4, &a);
    const Simulator sb = testing::run(mirrored, mirrored_pulse, 4.0, 1e-4, &b);
    ASSERT_GT(a.count(EventKind::kSlidingStart), 0);
    ASSERT_EQ(a.events.size(), b.events.size());
    for (std::size_t i = 0; i < a.events.size(); ++i) {
      EXPECT_EQ(a.events[i].kind, b.events[i].kind) << "event " << i;
      EXPECT_NEAR(a.events[i].t, b.events[i].t, 1e-9) << "event " << i;
      EXPECT_EQ(a.events[i].side, -b.events[i].side) << "event " << i;
      EXPECT_EQ(a.events[i].phase, b.events[i].phase) << "event " << i;
    }
    EXPECT_EQ(sa.mode().phase, sb.mode().phase);
    for (const StateIndex i : {kU, kX, kTheta, kUDot, kXDot, kThetaDot}) {
      EXPECT_NEAR(sa.state()[i], -sb.state()[i], 1e-8) << "component " << i;
    }
  }
}

}  // namespace
}  // namespace plinth

namespace plinth {
namespace {

// A step too large for a stable integration of a stiff, light, heavily damped base is refused
// with the largest stable step; just below it the run stays bounded.
TEST(StepCheck, RefusesUnstableStepsAndNamesTheLargestStableOne) {
  SceneParams p = testing::paper_isolated(0.0, 0.05, 0.99);
  p.base.mass = 0.01 * p.block.mass;
  p.has_friction = true;
  p.friction = {0.3, 0.24};
  const Scene s = testing::make(p);
  const double limit = largest_stable_step(s);
  // Overdamped base alone: c / m_b = 2 xi (m + m_b) omega / m_b sets the rate.
  EXPECT_LT(limit, 1e-4);
  SolverSettings settings;
  settings.step = 1e-3;
  Simulator sim;
  const Error e = Simulator::create(s, Excitation::none(), settings, sim);
  EXPECT_EQ(e.code, ErrorCode::kOutOfRange);
  EXPECT_STREQ(e.field, "solver.step");
  EXPECT_DOUBLE_EQ(e.limit, limit);
  settings.step = 0.9 * limit;
  ASSERT_TRUE(Simulator::create(s, Excitation::sine_pulse(5.0, 0.3), settings, sim).ok());
  sim.start_at_rest();
  double peak = 0.0;
  while (sim.time() < 1.0) {
    sim.step();
    ASSERT_TRUE(sim.state().allFinite()) << "t = " << sim.time();
    peak = std::max(peak, std::fabs(sim.state()[kU]));
  }
  EXPECT_LT(peak, 0.1);
  // Without a base there is no such limit.
  EXPECT_TRUE(std::isinf(largest_stable_step(testing::make(testing::paper_block()))));
}

}  // namespace
}  // namespace plinth

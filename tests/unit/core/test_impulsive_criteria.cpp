// The paper's impulsive criteria (Section 5.3.1, Eqs 38-41) against the simulation: the
// impulse that starts sliding, the friction that separates sliding from rocking, the curve
// above which a rocking block also slides, and a map of the motion an impulse starts with.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "bisection_support.h"
#include "plinth/core/closed_forms.h"
#include "plinth/core/internal/guards.h"
#include "plinth/host/sweep_impulse.h"
#include "test_support.h"

namespace plinth {
namespace {

using internal::ContactForce;
using internal::sticking_contact_force;
using testing::make;
using testing::paper_isolated;
using testing::RecordingSink;

SceneParams with_friction(SceneParams p, double mu_s) {
  p.has_friction = true;
  p.friction = {mu_s, 0.8 * mu_s};
  return p;
}

Simulator simulator_for(const Scene& s, double dt, EventSink* sink) {
  SolverSettings settings;
  settings.step = dt;
  Simulator sim;
  if (!Simulator::create(s, Excitation::none(), settings, sim).ok()) __builtin_trap();
  sim.set_event_sink(sink);
  return sim;
}

// True when the impulse makes the block slide within one base period (the simulation stops at
// the first sliding event).
bool impulse_starts_sliding(const Scene& s, double impulse) {
  RecordingSink sink;
  Simulator sim = simulator_for(s, 1e-4, &sink);
  sim.start_with_impulse(impulse);
  while (sim.time() < s.params.base.period - 0.5e-4) {
    if (sink.first(EventKind::kSlidingStart) != nullptr) return true;
    sim.step();
  }
  return sink.first(EventKind::kSlidingStart) != nullptr;
}

// Eq 38: the smallest impulse that starts sliding, |I| = mu_s T g / (2 pi a(xi)), by bisection
// on the simulation, for mu_s below b1/h (Eq 39: sliding comes first).
TEST(ImpulsiveCriteria, Eq38SlidingImpulseMatchesBisectionOnSimulation) {
  for (const double epsilon : {0.0, -0.3}) {
    for (const double xi : {0.05, 0.2, 0.4}) {
      for (const double mu_s : {0.1, 0.2}) {
        const Scene s = make(with_friction(paper_isolated(epsilon, 2.0, xi), mu_s));
        ASSERT_LT(mu_s, slide_rocking_friction_limit(s, Corner::kLeft));
        const double predicted = sliding_impulse_threshold(s);
        const double printed_form = mu_s * s.params.base.period * s.g /
                                    (2.0 * std::numbers::pi * peak_acceleration_factor(xi));
        EXPECT_NEAR(printed_form, predicted, 1e-12 * predicted);
        SCOPED_TRACE(::testing::Message()
                     << "epsilon = " << epsilon << ", xi = " << xi << ", mu_s = " << mu_s);
        ASSERT_NO_FATAL_FAILURE(testing::expect_threshold_by_bisection(
            [&](double i) { return impulse_starts_sliding(s, -i); }, predicted, 0.8, 1.25));
      }
    }
  }
}

// Eq 39: the dividing friction is b_i / h, (1 + epsilon) / lambda for corner 1; the thresholds
// of Eqs 37 and 38 are equal there.
TEST(ImpulsiveCriteria, Eq39DividingFrictionIsBiOverH) {
  for (const double epsilon : {0.0, -0.3, 0.4}) {
    const Scene s0 = make(paper_isolated(epsilon));
    const double limit = slide_rocking_friction_limit(s0, Corner::kLeft);
    EXPECT_NEAR(limit, (1.0 + epsilon) / 3.0, 1e-15);
    EXPECT_NEAR(slide_rocking_friction_limit(s0, Corner::kRight), (1.0 - epsilon) / 3.0, 1e-15);
    const Scene s = make(with_friction(paper_isolated(epsilon), limit));
    EXPECT_NEAR(sliding_impulse_threshold(s), rocking_impulse_threshold(s, Corner::kLeft),
                1e-14 * rocking_impulse_threshold(s, Corner::kLeft));
  }
}

// A scene of the block of half-width b = 0.3 m with given epsilon, lambda and I_C.
Scene shaped(double epsilon, double lambda, double xi, bool slender_rod) {
  SceneParams p = paper_isolated(0.0, 2.0, xi);
  p.block.com_height = lambda * p.block.half_width;
  p.block.eccentricity = epsilon * p.block.half_width;
  const double h = p.block.com_height;
  p.block.inertia = slender_rod ? p.block.mass * h * h / 3.0
                                : homogeneous_rectangle_inertia(p.block.mass, 0.3, h);
  return make(p);
}

// Eq 41: the printed form is the general one (Eq 18 with Eqs 12, 19, 40) with I_C = m h^2 / 3,
// the inertia of a slender rod 2h tall; the homogeneous rectangle has m (b^2 + h^2) / 3.
TEST(ImpulsiveCriteria, PrintedEq41IsTheGeneralFormWithARodInertia) {
  for (const double epsilon : {0.0, -0.3, -0.7, 0.25}) {
    for (const double lambda : {1.5, 3.0, 6.0}) {
      for (const double xi : {0.05, 0.2, 0.7}) {
        const Scene rod = shaped(epsilon, lambda, xi, true);
        const double a_xi = peak_acceleration_factor(xi);
        for (const double factor : {1.0, 1.7, 3.0, 10.0}) {
          const double impulse = -factor * rocking_impulse_threshold(rod, Corner::kLeft);
          const double general = rocking_to_sliding_friction(rod, Corner::kLeft, impulse);
          EXPECT_NEAR(printed_eq41(epsilon, lambda, impulse, rod.omega, a_xi, rod.g), general,
                      1e-12 * general)
              << "epsilon = " << epsilon << ", lambda = " << lambda << ", I/I_R = " << factor;
        }
        // At the rocking threshold the curve starts at Eq 39's b1/h, for any I_C.
        const Scene block = shaped(epsilon, lambda, xi, false);
        const double at_onset = rocking_to_sliding_friction(
            block, Corner::kLeft, rocking_impulse_threshold(block, Corner::kLeft));
        EXPECT_NEAR(at_onset, (1.0 + epsilon) / lambda, 1e-12);
      }
    }
  }
  // The paper's block (lambda = 3, homogeneous, I_C / m = (b^2 + h^2) / 3 against the rod's
  // h^2 / 3, 11 % more), xi = 0.2, over |I| from the Eq 37 threshold I_R to 3 I_R: the printed
  // Eq 41 lies below the general form by up to 2.42 % for epsilon = 0 (0.4667 against 0.4783
  // at 3 I_R) and 2.53 % for epsilon = -0.3 (0.3373 against 0.3460); both start at b1/h at I_R
  // and the gap grows with |I| towards 1 - (h^2/3 + b1^2) / (I_C/m + b1^2): 7.7 % (epsilon = 0)
  // and 8.7 % (epsilon = -0.3).
  for (const double epsilon : {0.0, -0.3}) {
    const Scene s = make(paper_isolated(epsilon));
    const double threshold = rocking_impulse_threshold(s, Corner::kLeft);
    const double a_xi = peak_acceleration_factor(0.2);
    double worst = 0.0;
    for (double factor = 1.0; factor <= 3.0 + 1e-9; factor += 0.01) {
      const double impulse = -factor * threshold;
      const double general = rocking_to_sliding_friction(s, Corner::kLeft, impulse);
      const double printed = printed_eq41(epsilon, 3.0, impulse, s.omega, a_xi, s.g);
      EXPECT_LE(printed, general * (1.0 + 1e-12));
      worst = std::max(worst, 1.0 - printed / general);
    }
    std::printf("epsilon %.1f: printed Eq 41 below the general form by up to %.2f %% for "
                "|I| <= 3 I_R\n", epsilon, 100.0 * worst);
    EXPECT_GT(worst, epsilon == 0.0 ? 0.023 : 0.024);
    EXPECT_LT(worst, epsilon == 0.0 ? 0.025 : 0.026);
  }
}

// Eq 41 against the simulation's own C_RS: with no sliding (no friction modelled; the motion
// before any sliding does not depend on mu_s), the largest |X1| / Y1 of Eq 18 in the first
// rocking phase is the mu_s below which the block slide-rocks. Eq 41 evaluates it at
// theta = theta' = 0 with the peak acceleration (Eq 40). Measured (xi = 0.2, |I| from 1.05 to
// 3 I_R): the largest ratio while theta < alpha_1 / 2 (reached at theta < 0.16 alpha_1) agrees
// with the general Eq 41 to 1.6 % (epsilon = 0) and 1.3 % (epsilon = -0.3). A block on its way
// to overturning (here from about 1.4 I_R on) demands more friction again near its critical angle;
// for epsilon = 0 that late demand is the larger one past 2.65 I_R and reaches 0.61 at 3 I_R
// (Eq 41: 0.478), which Eq 41 does not describe.
struct FrictionDemand {
  double early = 0.0;  // largest |X1| / Y1 while theta < alpha_1 / 2
  double late = 0.0;   // largest |X1| / Y1 afterwards, up to the end of the first rocking phase
};

FrictionDemand simulated_friction_demand(const Scene& s, double impulse) {
  RecordingSink sink;
  Simulator sim = simulator_for(s, 1e-4, &sink);
  sim.start_with_impulse(impulse);
  FrictionDemand d;
  const double alpha = s.corner1.critical_angle;
  while (sim.time() < s.params.base.period && !sim.mode().terminal() &&
         sink.count(EventKind::kImpact) == 0 && sink.count(EventKind::kRockingStop) == 0) {
    if (sim.mode().rocking()) {
      const ContactForce f = sticking_contact_force(s, sim.mode(), sim.state(),
                                                    sim.ground(sim.time()), sim.accelerations());
      double& demand = std::fabs(sim.state()[kTheta]) < 0.5 * alpha ? d.early : d.late;
      demand = std::max(demand, std::fabs(f.tangential) / f.normal);
    }
    sim.step();
  }
  return d;
}

TEST(ImpulsiveCriteria, Eq41AgainstTheSimulatedFrictionDemand) {
  for (const double epsilon : {0.0, -0.3}) {
    const Scene s = make(paper_isolated(epsilon, 2.0, 0.2));
    const double i_rock = rocking_impulse_threshold(s, Corner::kLeft);
    double worst = 0.0, late_from = 0.0, late_worst = 0.0;
    for (int k = 0; k <= 39; ++k) {
      const double factor = 1.05 + 0.05 * k;
      const double predicted = rocking_to_sliding_friction(s, Corner::kLeft, factor * i_rock);
      const FrictionDemand d = simulated_friction_demand(s, -factor * i_rock);
      ASSERT_GT(d.early, 0.0) << "the block must rock, I/I_R = " << factor;
      worst = std::max(worst, std::fabs(d.early / predicted - 1.0));
      if (d.late > d.early) {
        if (late_from == 0.0) late_from = factor;
        late_worst = std::max(late_worst, d.late / predicted - 1.0);
      }
    }
    std::printf("epsilon %.1f: simulated C_RS (theta < alpha/2) within %.2f %% of Eq 41 for "
                "|I| = 1.05 .. 3 I_R\n", epsilon, 100.0 * worst);
    if (late_from > 0.0) {
      std::printf("  the late demand near overturning is the larger from %.2f I_R on, up to "
                  "%.1f %% above Eq 41\n", late_from, 100.0 * late_worst);
    }
    EXPECT_LT(worst, 0.02);
  }
}

// The criteria map (Section 5.3.1) for the paper's isolated block, lambda = 3, xi = 0.2,
// T = 2 s, mu_k = 0.8 mu_s, I < 0 (corner 1), against the motion the simulation starts with.
// Grid: 31 values of mu_s (0.05 to 0.8, step 0.025) by 30 of |I| (0.1 to 3 I_R), for
// epsilon = 0 and -0.3: 1860 points, of which 1610 lie far enough from the curves and are
// simulated (about 5 s in a Release build; each run stops once its class is settled).
//
// The closed forms predict: below C_S (Eq 38) and C_R (Eq 37), full contact; mu_s < b1/h
// (C_SR, Eq 39) above C_S, sliding first; mu_s > b1/h above C_R, rocking first, and
// slide-rocking when mu_s lies below C_RS (Eq 41, general I_C). Points within 5 % (in |I| and
// in mu_s) of a curve are skipped. The classifications, simulated and predicted, and the
// neighbourhoods of the curves are lib/host's (sweep_impulse.h: simulate_impulse_start,
// predicted_impulse_start, near_curve), those plinth-sweep --impulse-map writes.
//
// Two things the criteria do not describe; the map measures them, reports them as
// disagreements with the paper's classification, and asserts them on their own terms:
//  - At t = 0+ the base's acceleration jumps to 2 xi omega |I| (the damper's force; the peak
//    |I| omega a(xi) comes later). Where mu_s g <= 2 xi omega |I|, friction cannot hold the
//    block from the first instant: it slides first (Simulator: Eq 15 is checked before Eq 16
//    on entering a phase) and rocks only if Eq 17 holds while sliding. The criteria, built on
//    the later peak, say rocking first there when mu_s > b1/h. These points are predicted as
//    sliding first, and the line mu_s = 2 xi omega |I| / g is kept 5 % away too.
//  - Eq 41 describes the start of rocking (see Eq41AgainstTheSimulatedFrictionDemand). A
//    block on its way to overturning may slide late in its first rocking phase (theta >=
//    alpha_1 / 2) with mu_s above Eq 41. Such late slides count as C_RS disagreements in the
//    reported rate; the assertion classifies them as rocking (the early part, which Eq 41
//    describes, is asserted at every point).
TEST(ImpulsiveCriteria, CriteriaMapMatchesSimulation) {
  using host::ImpulseStart;
  using host::impulse_start_name;
  constexpr int kMuPoints = 31;
  constexpr int kImpulsePoints = 30;
  constexpr double kMargin = 0.05;
  int compared_total = 0;
  int disagreements_total = 0;
  for (const double epsilon : {0.0, -0.3}) {
    int compared = 0, skipped_t0 = 0, disagree_t0 = 0, late_slides = 0, other = 0;
    int crs_compared = 0, crs_agree = 0;
    double early_theta = 0.0, late_theta = 1e300;  // extremes of theta / alpha_1 at sliding
    for (int im = 0; im < kMuPoints; ++im) {
      const double mu_s = 0.05 + 0.75 * im / (kMuPoints - 1);
      const Scene s = make(with_friction(paper_isolated(epsilon, 2.0, 0.2), mu_s));
      const double xi = s.params.base.damping_ratio;
      const double i_rock = rocking_impulse_threshold(s, Corner::kLeft);  // C_R, Eq 37
      // Sliding at t = 0+ (Eq 15 with the damper's jump): mu_s g <= 2 xi omega |I|.
      const auto c_at_once = [&](double i) { return 2.0 * xi * s.omega * i / s.g; };
      for (int ii = 0; ii < kImpulsePoints; ++ii) {
        const double impulse = i_rock * (0.1 + 2.9 * ii / (kImpulsePoints - 1));
        // Within 5 % (in |I| and in mu_s) of C_S, C_R, C_SR or C_RS; else of the line of
        // sliding at t = 0+.
        const host::NearCurve near = host::near_curve(s, impulse, kMargin);
        if (near == host::NearCurve::kCriteria) continue;
        if (near == host::NearCurve::kSlidingAtOnce) {
          ++skipped_t0;
          continue;
        }

        // The paper's classification, and the expected events.
        const ImpulseStart paper = host::predicted_impulse_start(s, impulse);
        const bool at_once = mu_s <= c_at_once(impulse);
        const ImpulseStart predicted = at_once ? ImpulseStart::kSliding : paper;

        const host::SimulatedStart got = host::simulate_impulse_start(s, -impulse, 1e-4);
        // theta / alpha_1 when sliding began (negative: rocking about corner 2).
        const double slide_theta =
            got.corner == Corner::kLeft ? got.slide_angle_ratio : -got.slide_angle_ratio;
        const bool late = got.start == ImpulseStart::kSlideRocking && slide_theta >= 0.5;
        if (late) {
          late_theta = std::min(late_theta, slide_theta);
        } else if (got.start == ImpulseStart::kSlideRocking) {
          early_theta = std::max(early_theta, slide_theta);
        }
        EXPECT_EQ(late ? ImpulseStart::kRocking : got.start, predicted)
            << "epsilon = " << epsilon << ", mu_s = " << mu_s << ", |I| = " << impulse << " ("
            << impulse / i_rock << " I_R): predicted " << impulse_start_name(predicted)
            << ", simulated " << impulse_start_name(got.start) << " (theta / alpha_1 "
            << slide_theta << ")";

        // Against the paper's classification, by the events (both-at-once = slide-rocking).
        ++compared;
        const ImpulseStart literal = got.start;
        if (literal != paper) {
          if (at_once) {
            ++disagree_t0;
          } else if (late && paper == ImpulseStart::kRocking) {
            ++late_slides;
          } else {
            ++other;
          }
        }
        if (paper == ImpulseStart::kRocking || paper == ImpulseStart::kSlideRocking) {
          ++crs_compared;
          crs_agree += literal == paper ? 1 : 0;
        }
      }
    }
    const int disagreements = disagree_t0 + late_slides + other;
    std::printf(
        "epsilon %.1f: %d of %d grid points compared (%d more skipped near the t = 0+ curves); "
        "%d disagree with the paper's classification: %d both onsets at t = 0+, %d late "
        "slides, %d other\n  C_RS: %d of %d rocking-first points agree (%.1f %%); sliding at "
        "theta / alpha_1 <= %.3f (early), >= %.3f (late; 0: none)\n",
        epsilon, compared, kMuPoints * kImpulsePoints, skipped_t0, disagreements, disagree_t0,
        late_slides, other, crs_agree, crs_compared,
        crs_compared > 0 ? 100.0 * crs_agree / crs_compared : 0.0, early_theta,
        late_theta > 1e299 ? 0.0 : late_theta);
    EXPECT_EQ(other, 0);
    compared_total += compared;
    disagreements_total += disagreements;
  }
  std::printf("all: %d points compared, %d disagreements with the paper's classification\n",
              compared_total, disagreements_total);
  EXPECT_GT(compared_total, 1400);
}

}  // namespace
}  // namespace plinth

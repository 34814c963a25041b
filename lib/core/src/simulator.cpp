#include "plinth/core/simulator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include "phase_kernels.h"
#include "plinth/core/flows.h"
#include "plinth/core/guards.h"
#include "plinth/core/resets.h"

// Build-time choices for small targets (lib/core/CMakeLists.txt, docs/microcontroller.md): every
// stepper and flattened intervals by default; a microcontroller keeps the estimator's stepper
// alone and calls what the host inlines, to fit its flash.
#ifndef PLINTH_CORE_RK4_ONLY
#define PLINTH_CORE_RK4_ONLY 0
#endif
#if !defined(PLINTH_CORE_FLATTEN) || PLINTH_CORE_FLATTEN
#define PLINTH_FLATTEN [[gnu::flatten]]
#else
#define PLINTH_FLATTEN
#endif

namespace plinth {

const char* phase_name(Phase phase) {
  switch (phase) {
    case Phase::kFullContact:
      return "full_contact";
    case Phase::kSliding:
      return "sliding";
    case Phase::kRocking:
      return "rocking";
    case Phase::kSlideRocking:
      return "slide_rocking";
    case Phase::kOverturned:
      return "overturned";
    case Phase::kFell:
      return "fell";
  }
  return "unknown";
}

const char* corner_name(Corner corner) { return corner == Corner::kLeft ? "left" : "right"; }

const char* event_name(EventKind kind) {
  switch (kind) {
    case EventKind::kRockingStart:
      return "rocking_start";
    case EventKind::kImpact:
      return "impact";
    case EventKind::kRockingStop:
      return "rocking_stop";
    case EventKind::kBaseStopHit:
      return "base_stop_hit";
    case EventKind::kBaseStopHeld:
      return "base_stop_held";
    case EventKind::kBaseStopReleased:
      return "base_stop_released";
    case EventKind::kOverturned:
      return "overturned";
    case EventKind::kSlidingStart:
      return "sliding_start";
    case EventKind::kSlidingStop:
      return "sliding_stop";
    case EventKind::kSlideStopHit:
      return "slide_stop_hit";
    case EventKind::kOutOfBase:
      return "out_of_base";
    case EventKind::kBackOnBase:
      return "back_on_base";
    case EventKind::kFell:
      return "fell";
  }
  return "unknown";
}

const char* stepper_name(Stepper stepper) {
  switch (stepper) {
    case Stepper::kRk4Located:
      return "rk4_located";
    case Stepper::kRk4StepEnd:
      return "rk4_step_end";
    case Stepper::kHeunLocated:
      return "heun_located";
    case Stepper::kSemiImplicitEuler:
      return "semi_implicit_euler";
  }
  return "unknown";
}

bool parse_stepper(std::string_view name, Stepper& out) {
  for (const Stepper stepper : kAllSteppers) {
    if (name == stepper_name(stepper)) {
      out = stepper;
      return true;
    }
  }
  return false;
}

Error validate(const SolverSettings& st) {
  if (!std::isfinite(st.step) || st.step <= 0.0) {
    return {ErrorCode::kOutOfRange, "solver.step", "must be a finite number greater than zero"};
  }
  bool known_stepper = false;
  for (const Stepper stepper : kAllSteppers) known_stepper = known_stepper || st.stepper == stepper;
  if (!known_stepper) {
    return {ErrorCode::kOutOfRange, "solver.stepper",
            "must be one of rk4_located, rk4_step_end, heun_located, semi_implicit_euler"};
  }
  if (PLINTH_CORE_RK4_ONLY && st.stepper != Stepper::kRk4Located) {
    return {ErrorCode::kOutOfRange, "solver.stepper",
            "must be rk4_located: this build has no other (PLINTH_CORE_RK4_ONLY)"};
  }
  if (!std::isfinite(st.rest_energy_ratio) || st.rest_energy_ratio <= 0.0 ||
      st.rest_energy_ratio >= 1.0) {
    return {ErrorCode::kOutOfRange, "solver.rest_energy_ratio", "must lie in (0, 1)"};
  }
  if (!std::isfinite(st.base_rest_speed) || st.base_rest_speed < 0.0) {
    return {ErrorCode::kOutOfRange, "solver.base_rest_speed", "must be finite and not negative"};
  }
  if (!std::isfinite(st.slide_rest_speed) || st.slide_rest_speed < 0.0) {
    return {ErrorCode::kOutOfRange, "solver.slide_rest_speed", "must be finite and not negative"};
  }
  if (st.max_events_per_step < 1) {
    return {ErrorCode::kOutOfRange, "solver.max_events_per_step", "must be at least 1"};
  }
  if (!std::isfinite(st.event_time_tolerance) || st.event_time_tolerance <= 0.0 ||
      st.event_time_tolerance > 0.1) {
    return {ErrorCode::kOutOfRange, "solver.event_time_tolerance", "must lie in (0, 0.1]"};
  }
  return ok_error();
}

namespace {

// Largest |lambda| of m u'' + c u' + k u = 0, 1/s.
double largest_rate(double mass, double damping, double stiffness) {
  const double a = damping / (2.0 * mass);
  const double w2 = stiffness / mass;
  if (a * a <= w2) return std::sqrt(w2);  // complex pair, |lambda| = sqrt(k/m)
  return a + std::sqrt(a * a - w2);       // overdamped: the fast real root
}

// A 2x2 matrix on (q, q').
struct Matrix2 {
  double a00, a01, a10, a11;
};

Matrix2 product(const Matrix2& x, const Matrix2& y) {
  return {x.a00 * y.a00 + x.a01 * y.a10, x.a00 * y.a01 + x.a01 * y.a11,
          x.a10 * y.a00 + x.a11 * y.a10, x.a10 * y.a01 + x.a11 * y.a11};
}

double spectral_radius(const Matrix2& g) {
  const double half_trace = 0.5 * (g.a00 + g.a11);
  const double det = g.a00 * g.a11 - g.a01 * g.a10;
  const double discriminant = half_trace * half_trace - det;
  if (discriminant < 0.0) return std::sqrt(det);  // complex pair, |mu|^2 = det
  const double root = std::sqrt(discriminant);
  return std::max(std::fabs(half_trace + root), std::fabs(half_trace - root));
}

// The one-step map of `stepper` with step h on m q'' + c q' + k q = 0.
Matrix2 amplification(Stepper stepper, double mass, double damping, double stiffness, double h) {
  const double a = -stiffness / mass;
  const double b = -damping / mass;
  if (stepper == Stepper::kSemiImplicitEuler) {
    return {1.0 + h * h * a, h + h * h * b, h * a, 1.0 + h * b};
  }
  const Matrix2 ha{0.0, h, h * a, h * b};
  const Matrix2 ha2 = product(ha, ha);
  Matrix2 g{1.0 + ha.a00 + 0.5 * ha2.a00, ha.a01 + 0.5 * ha2.a01, ha.a10 + 0.5 * ha2.a10,
            1.0 + ha.a11 + 0.5 * ha2.a11};
  if (stepper == Stepper::kHeunLocated) return g;
  const Matrix2 ha3 = product(ha2, ha);
  const Matrix2 ha4 = product(ha3, ha);
  g.a00 += ha3.a00 / 6.0 + ha4.a00 / 24.0;
  g.a01 += ha3.a01 / 6.0 + ha4.a01 / 24.0;
  g.a10 += ha3.a10 / 6.0 + ha4.a10 / 24.0;
  g.a11 += ha3.a11 / 6.0 + ha4.a11 / 24.0;
  return g;
}

// The largest h whose one-step map grows no mode by more than kStableGrowthPerStep: scanned up
// from far below the system's time scale in steps of 2 %, the first failure then bisected.
double largest_stable_step_of(Stepper stepper, double mass, double damping, double stiffness) {
  const double rate = largest_rate(mass, damping, stiffness);
  const auto stable = [&](double h) {
    return spectral_radius(amplification(stepper, mass, damping, stiffness, h)) <=
           1.0 + kStableGrowthPerStep;
  };
  double low = 1e-4 / rate;
  if (!stable(low)) return 0.0;
  double high = low;
  while (stable(high)) {
    low = high;
    high *= 1.02;
    if (high > 100.0 / rate) return high;
  }
  for (int i = 0; i < 60; ++i) {
    const double middle = 0.5 * (low + high);
    (stable(middle) ? low : high) = middle;
  }
  return low;
}

}  // namespace

double largest_stable_step(const Scene& s) {
  if (!s.has_base()) return std::numeric_limits<double>::infinity();
  constexpr double kRk4StabilityRadius = 2.5;  // below 2.78 (real axis) and 2.83 (imaginary)
  const double base_mass = s.total_mass - s.m;
  const double rate = std::max(largest_rate(s.total_mass, s.damping, s.stiffness),
                               largest_rate(base_mass, s.damping, s.stiffness));
  return kRk4StabilityRadius / rate;
}

double largest_stable_step(const Scene& s, Stepper stepper) {
  if (stepper == Stepper::kRk4Located || stepper == Stepper::kRk4StepEnd || !s.has_base()) {
    return largest_stable_step(s);
  }
  return std::min(largest_stable_step_of(stepper, s.total_mass, s.damping, s.stiffness),
                  largest_stable_step_of(stepper, s.total_mass - s.m, s.damping, s.stiffness));
}

// ---------------------------------------------------------------------------------------------
// The hybrid logic for one set of model features: which guards each mode has, what happens at
// each event. What a scene does not have is compiled out.
template <Features F>
struct Hybrid {
  static bool base_moves(const Mode& mode) {
    if constexpr (!F.base) {
      return false;
    } else {
      return mode.held_stop == 0;
    }
  }

  // The accelerations of `mode` at (y, ag), the same as the phase kernels' (phase_kernels.h).
  static Accelerations accelerations(const Scene& s, const Mode& mode, const State& y,
                                     GroundAcceleration ag) {
    const bool moves = base_moves(mode);
    switch (mode.phase) {
      case Phase::kFullContact:
        return moves ? full_contact_flow(s, y, ag) : Accelerations{};
      case Phase::kSliding:
        if constexpr (F.sliding) return sliding_flow(s, mode.slide_direction, y, ag, moves);
        return {};
      case Phase::kRocking:
        return rocking_flow(s, pivot_of(s, mode, y).geometry, y, ag, moves);
      case Phase::kSlideRocking:
        if constexpr (F.sliding) {
          const Pivot pivot = pivot_of(s, mode, y);
          return slide_rocking_flow(s, pivot.geometry, pivot.overhanging, mode.slide_direction, y,
                                    ag, moves);
        }
        return {};
      case Phase::kOverturned:
      case Phase::kFell:
        return {};
    }
    return {};
  }

  static ActiveGuards guards(const Mode& mode) { return active_guards<F>(mode); }

  static void emit(Simulator& sim, double t, EventKind kind, int side = 0, double before = 0.0,
                   double after = 0.0) {
    Event e;
    e.t = t;
    e.kind = kind;
    e.corner = sim.mode_.corner;
    e.side = static_cast<std::int8_t>(side);
    e.before = before;
    e.after = after;
    e.phase = sim.mode_.phase;
    e.overhang = sim.mode_.overhang;
    e.state = sim.y_;
    sim.emit(e);
  }

  // On entering a mode (at the start or after a reset), the onset conditions that already hold
  // start their phase at once, in the favoured direction: Eq 15/18 (sliding) first, since a
  // block that cannot be held by friction slides and its acceleration drops to what kinetic
  // friction gives it; then Eq 16/17 (rocking) with the accelerations of the new phase. (When
  // both hold at once in full contact, e.g. right after an impulse whose damper force jumps
  // past both thresholds, the block slides, and rocks too only if Eq 17 holds while sliding.)
  static void enter(Simulator& sim, double t) {
    const Scene& s = *sim.scene_;
    const GroundAcceleration ag = sim.excitation_.at(t);
    for (int pass = 0; pass < 2 && !sim.mode_.terminal(); ++pass) {
      const Accelerations acc = accelerations(s, sim.mode_, sim.y_, ag);
      if constexpr (F.sliding) {
        if (!sim.mode_.sliding()) {
          const double left = guard_value(GuardId::kSlidingOnsetLeft, s, sim.mode_, sim.y_, ag, acc);
          const double right =
              guard_value(GuardId::kSlidingOnsetRight, s, sim.mode_, sim.y_, ag, acc);
          if (left >= 0.0 || right >= 0.0) {
            start_sliding(sim, t, left >= right ? -1 : 1);
            continue;
          }
        }
      }
      if (!sim.mode_.rocking()) {
        const double left = guard_value(GuardId::kRockingOnsetLeft, s, sim.mode_, sim.y_, ag, acc);
        const double right = guard_value(GuardId::kRockingOnsetRight, s, sim.mode_, sim.y_, ag, acc);
        if (left >= 0.0 || right >= 0.0) {
          start_rocking(sim, t, left >= right ? Corner::kLeft : Corner::kRight);
          continue;
        }
      }
      return;
    }
  }

  static void start_rocking(Simulator& sim, double t, Corner corner) {
    rocking_onset_reset(corner, sim.mode_, sim.y_);
    emit(sim, t, EventKind::kRockingStart);
  }

  static void start_sliding(Simulator& sim, double t, int direction) {
    sliding_onset_reset(direction, sim.mode_);
    emit(sim, t, EventKind::kSlidingStart, direction);
  }

  static void stop_rocking(Simulator& sim, double t, double theta_dot_before) {
    rocking_stop_reset(*sim.scene_, base_moves(sim.mode_), sim.mode_, sim.y_);
    emit(sim, t, EventKind::kRockingStop, 0, theta_dot_before);
  }

  // The slowest rebound from a stop (or impact at theta = 0) the solver follows, m/s (rad/s):
  // `rest_speed`, and with events taken at step ends also k |a| dt, a the acceleration back
  // towards the stop. A hit seen up to a step late has gained up to |a| dt, so with restitution
  // eta rebounds settle near eta |a| dt / (1 - eta) instead of dying out (the Zeno sequence the
  // located methods resolve and settle): k = eta / (1 - eta), within [4, 32] steps.
  static constexpr double kStepEndRestStepsMin = 4.0;
  static constexpr double kStepEndRestStepsMax = 32.0;
  // `acceleration()` gives a (computed only for step-end methods).
  template <class Acceleration>
  static double rest_speed(const Simulator& sim, double rest_speed, Acceleration acceleration,
                           double restitution) {
    if (!sim.events_at_step_ends_) return rest_speed;
    const double steps =
        restitution < 1.0 ? restitution / (1.0 - restitution) : kStepEndRestStepsMax;
    return std::max(rest_speed, std::clamp(steps, kStepEndRestStepsMin, kStepEndRestStepsMax) *
                                    std::fabs(acceleration()) * sim.settings_.step);
  }

  // Impact at theta = 0 (Eqs 21-24; with friction, the Coulomb impact of resets.h), or the end
  // of rocking when it leaves less rocking energy than the rest criterion's fraction of the new
  // pivot's overturning barrier.
  static void rocking_impact(Simulator& sim, double t) {
    const Scene& s = *sim.scene_;
    const double before = sim.y_[kThetaDot];
    const bool was_sliding = sim.mode_.sliding();
    Mode mode = sim.mode_;
    State y = sim.y_;
    if constexpr (F.sliding) {
      (void)coulomb_impact_reset(s, base_moves(mode), mode, y);
    } else {
      rocking_impact_reset(s, base_moves(mode), mode, y);
    }
    const CornerGeometry to = pivot_of(s, mode, y).geometry;
    const double after = y[kThetaDot];
    const double barrier = s.m * s.g * (to.radius - s.h);
    sim.mode_ = mode;
    sim.y_ = y;
    // Taken at step ends, impacts closer than a few steps apart are chatter (see rest_speed).
    const double slowest =
        rest_speed(
            sim, 0.0, [&] { return accelerations(s, mode, y, sim.excitation_.at(t)).theta; },
            before != 0.0 ? std::fabs(after / before) : 0.0);
    if (after * before <= 0.0 || std::fabs(after) < slowest ||
        0.5 * to.inertia * after * after < sim.settings_.rest_energy_ratio * barrier) {
      stop_rocking(sim, t, before);
    } else {
      emit(sim, t, EventKind::kImpact, 0, before, after);
    }
    if (was_sliding != sim.mode_.sliding()) {
      if (sim.mode_.sliding()) {
        emit(sim, t, EventKind::kSlidingStart, sim.mode_.slide_direction);
      } else {
        emit(sim, t, EventKind::kSlidingStop);
      }
    }
    enter(sim, t);
  }

  // x' reached 0: the block sticks if static friction can hold it (Eq 15 or 18 not met in the
  // sticking phase), otherwise it slides back the other way.
  static void sliding_stopped(Simulator& sim, double t) {
    const Scene& s = *sim.scene_;
    sliding_stop_reset(sim.mode_, sim.y_);
    const GroundAcceleration ag = sim.excitation_.at(t);
    const Accelerations acc = accelerations(s, sim.mode_, sim.y_, ag);
    const ContactForce f = sticking_contact_force(s, sim.mode_, sim.y_, ag, acc);
    const int direction = f.tangential > 0.0 ? -1 : 1;
    // Strictly: with mu_s = 0 and no force at all the block stays put rather than "sliding" at
    // zero speed, re-stopping every step.
    if (sliding_onset_guard(s, sim.mode_, sim.y_, direction, f) > 0.0) {
      sliding_onset_reset(direction, sim.mode_);
      emit(sim, t, EventKind::kSlidingStart, direction);
      return;
    }
    emit(sim, t, EventKind::kSlidingStop);
    enter(sim, t);
  }

  // |x| reached x_hat (Eqs 30-32 with restitution, resets.h): the block rebounds from the stop,
  // or sticks against it once the rebound is slower than settings.slide_rest_speed (this ends
  // the Zeno sequence of ever smaller rebounds of a block pressed against the stop).
  static void sliding_stop_hit(Simulator& sim, double t, int side) {
    const Scene& s = *sim.scene_;
    const double before = sim.y_[kXDot];
    const double rebound = s.params.sliding_stops.restitution * std::fabs(before);
    const double slowest =
        rest_speed(sim, sim.settings_.slide_rest_speed,
                   [&] { return accelerations(s, sim.mode_, sim.y_, sim.excitation_.at(t)).x; },
                   s.params.sliding_stops.restitution);
    if (rebound < slowest) {
      coordinate_impulse_reset(s, sim.mode_, base_moves(sim.mode_), kXDot, 0.0, sim.y_);
      sim.y_[kX] = side * s.params.support.clearance;
      sliding_stop_reset(sim.mode_, sim.y_);
      emit(sim, t, EventKind::kSlideStopHit, side, before, sim.y_[kUDot]);
      enter(sim, t);
      return;
    }
    sliding_stop_hit_reset(s, side, base_moves(sim.mode_), sim.mode_, sim.y_);
    emit(sim, t, EventKind::kSlideStopHit, side, before, sim.y_[kUDot]);
  }

  static void base_stop_hit(Simulator& sim, double t, int side) {
    const Scene& s = *sim.scene_;
    const double before = sim.y_[kUDot];
    base_stop_reset(s, side, sim.mode_, sim.y_);
    emit(sim, t, EventKind::kBaseStopHit, side, before, sim.y_[kUDot]);
    if (sim.mode_.sliding()) keep_sliding_consistent(sim, t);
    const double slowest =
        rest_speed(sim, sim.settings_.base_rest_speed,
                   [&] { return accelerations(s, sim.mode_, sim.y_, sim.excitation_.at(t)).u; },
                   s.params.base_stops.restitution);
    if (std::fabs(sim.y_[kUDot]) < slowest) hold_if_pushed(sim, t, side);
  }

  // An impulse on the base changes x' while sliding: the phase follows its new sign.
  static void keep_sliding_consistent(Simulator& sim, double t) {
    const double x_dot = sim.y_[kXDot];
    if (x_dot * sim.mode_.slide_direction > 0.0) return;
    if (x_dot == 0.0) {
      sliding_stopped(sim, t);
      return;
    }
    sim.mode_.slide_direction = static_cast<std::int8_t>(x_dot > 0.0 ? 1 : -1);
    emit(sim, t, EventKind::kSlidingStart, sim.mode_.slide_direction);
  }

  // The base's rebound is too slow to matter: if the stop pushes back, the base rests on it.
  static void hold_if_pushed(Simulator& sim, double t, int side) {
    const Scene& s = *sim.scene_;
    Mode held = sim.mode_;
    held.held_stop = static_cast<std::int8_t>(side);
    const GroundAcceleration ag = sim.excitation_.at(t);
    const double reaction =
        base_stop_reaction(s, held, sim.y_, ag, accelerations(s, held, sim.y_, ag));
    if (side * reaction > 0.0) return;  // the stop would have to pull: the base moves away
    base_stop_hold_reset(s, side, sim.mode_, sim.y_);
    emit(sim, t, EventKind::kBaseStopHeld, side);
    enter(sim, t);
  }

  static void release_base(Simulator& sim, double t) {
    const int side = sim.mode_.held_stop;
    sim.mode_.held_stop = 0;
    emit(sim, t, EventKind::kBaseStopReleased, side);
    enter(sim, t);
  }

  // |theta| passed the pivot's critical angle: C is over the pivot. About the support's corner
  // that is C passing the support's edge, so the block falls off the base; about its own corner
  // it overturns.
  static void overturn(Simulator& sim, double t) {
    const Pivot pivot = pivot_of(*sim.scene_, sim.mode_, sim.y_);
    sim.y_[kTheta] = pivot.geometry.sign * pivot.geometry.critical_angle;
    if (pivot.overhanging) {
      sim.mode_.phase = Phase::kFell;
      emit(sim, t, EventKind::kFell, sim.mode_.overhang);
      return;
    }
    sim.mode_.phase = Phase::kOverturned;
    emit(sim, t, EventKind::kOverturned);
  }

  static void apply(Simulator& sim, GuardId id, double t) {
    ++sim.event_count_;
    const double x_hat = sim.scene_->params.support.clearance;
    switch (id) {
      case GuardId::kRockingOnsetLeft:
        start_rocking(sim, t, Corner::kLeft);
        enter(sim, t);
        return;
      case GuardId::kRockingOnsetRight:
        start_rocking(sim, t, Corner::kRight);
        enter(sim, t);
        return;
      case GuardId::kRockingImpact:
        rocking_impact(sim, t);
        return;
      case GuardId::kOverturning:
        overturn(sim, t);
        return;
      case GuardId::kSlidingOnsetLeft:
        start_sliding(sim, t, -1);
        enter(sim, t);
        return;
      case GuardId::kSlidingOnsetRight:
        start_sliding(sim, t, 1);
        enter(sim, t);
        return;
      case GuardId::kSlidingStop:
        sliding_stopped(sim, t);
        return;
      case GuardId::kSlidingInconsistent: {
        const double before = sim.y_[kXDot];
        tangential_impact_reset(*sim.scene_, sim.mode_, sim.y_);
        emit(sim, t, EventKind::kSlidingStop, 0, before);
        enter(sim, t);
        return;
      }
      case GuardId::kOutOfBaseLeft:
      case GuardId::kOutOfBaseRight: {
        const int side = id == GuardId::kOutOfBaseLeft ? -1 : 1;
        sim.y_[kX] = side * x_hat;
        sim.mode_.overhang = static_cast<std::int8_t>(side);
        emit(sim, t, EventKind::kOutOfBase, side);
        if (!sim.mode_.rocking()) enter(sim, t);
        return;
      }
      case GuardId::kBackOnBase: {
        const int side = sim.mode_.overhang;
        sim.y_[kX] = side * x_hat;
        sim.mode_.overhang = 0;
        emit(sim, t, EventKind::kBackOnBase, side);
        return;
      }
      case GuardId::kFall:
        sim.mode_.phase = Phase::kFell;
        emit(sim, t, EventKind::kFell, sim.mode_.overhang);
        return;
      case GuardId::kSlidingStopLeft:
        sliding_stop_hit(sim, t, -1);
        return;
      case GuardId::kSlidingStopRight:
        sliding_stop_hit(sim, t, 1);
        return;
      case GuardId::kBaseStopRight:
        base_stop_hit(sim, t, +1);
        return;
      case GuardId::kBaseStopLeft:
        base_stop_hit(sim, t, -1);
        return;
      case GuardId::kBaseStopRelease:
        release_base(sim, t);
        return;
    }
  }

  // Chatter within one step (Zeno): bring rocking to rest, stop sliding, and hold a base that
  // sits on a stop.
  static void settle(Simulator& sim, double t) {
    if (sim.mode_.rocking()) stop_rocking(sim, t, sim.y_[kThetaDot]);
    if constexpr (F.sliding) {
      // Stick-slip chatter: the block sticks for the rest of the step; the next step's guards
      // start it sliding again if friction cannot hold it.
      if (sim.mode_.sliding()) {
        sliding_stop_reset(sim.mode_, sim.y_);
        emit(sim, t, EventKind::kSlidingStop);
      }
    }
    if constexpr (F.base_stops) {
      const double u_max = sim.scene_->params.base_stops.max_displacement;
      if (sim.mode_.held_stop == 0 && std::fabs(sim.y_[kU]) >= u_max * (1.0 - 1e-9)) {
        hold_if_pushed(sim, t, sim.y_[kU] > 0.0 ? +1 : -1);
      }
    }
    ++sim.chatter_steps_;
  }

  // A quiet step of full contact, propagated exactly (full_contact_propagator.h). Full contact's
  // guards (active_guards<F>: rocking onsets Eq 16, sliding onsets Eq 15, base stops Eq 28) are
  // taken at the step's end only: when every one is strictly negative there the interval would
  // see no crossing whatever their values at the start, so its state is this one to the last bit
  // (the same expressions) and nothing else needs keeping: no flow point, no guard values. Only
  // the end's horizontal ground acceleration is kept, as the next step's start. Otherwise (a
  // guard at or past 0, or not a number) returns false, nothing changed, and the step's interval
  // runs (ExactFullContact in phase_kernels.h).
  static bool quiet_full_contact_step(Simulator& sim, double t0, double t_end) {
    if constexpr (!F.base) {
      return false;
    } else {
      const Mode& mode = sim.mode_;
      const double h = t_end - t0;
      State& y = sim.y_;
      // x and theta at rest, as every reset into full contact leaves them (a state given to
      // start_from may not: the interval advances it).
      if (mode.held_stop != 0 || mode.overhang != 0 || y[kXDot] != 0.0 || y[kThetaDot] != 0.0 ||
          t0 + h != t_end) {
        return false;
      }
      const Scene& s = *sim.scene_;
      const double a0 = sim.quiet_ground_step_ == sim.step_count_
                            ? sim.quiet_ground_horizontal_
                            : kernels::Base::ground(sim.excitation_, t0).horizontal;
      const GroundAcceleration a1 = kernels::Base::ground(sim.excitation_, t_end);
      double u = y[kU];
      double u_dot = y[kUDot];
      sim.propagator_.advance(u, u_dot, a0, a1.horizontal);
      const Accelerations acc{full_contact_base_acceleration(s, u, u_dot, a1.horizontal), 0.0,
                              0.0};
      if (!(rocking_onset_guard(s, s.corner1.sign, s.corner1.onset_ratio, acc, a1) < 0.0 &&
            rocking_onset_guard(s, s.corner2.sign, s.corner2.onset_ratio, acc, a1) < 0.0)) {
        return false;
      }
      if constexpr (F.sliding) {
        // Eq 15 (x stays: sliding_onset_guard's test of the sliding stops holds as it did).
        const ContactForce f = sticking_contact_force(s, mode, y, a1, acc, SinCos{});
        if (!(sliding_onset_guard(s, mode, y, -1, f, SinCos{}) < 0.0 &&
              sliding_onset_guard(s, mode, y, 1, f, SinCos{}) < 0.0)) {
          return false;
        }
      }
      if constexpr (F.base_stops) {
        if (!(std::fabs(u) - s.params.base_stops.max_displacement < 0.0)) return false;
      }
      y[kU] = u;
      y[kUDot] = u_dot;
      sim.cache_valid_ = false;
      sim.quiet_ground_horizontal_ = a1.horizontal;
      sim.quiet_ground_step_ = sim.step_count_ + 1;
      return true;
    }
  }

  static Accelerations current(const Simulator& sim, double t, const State& y) {
    return accelerations(*sim.scene_, sim.mode_, y, sim.excitation_.at(t));
  }

  template <class Method>
  static void bind_intervals(Simulator& sim, bool exact_full_contact);

  static void bind(Simulator& sim, const SolverSettings& settings) {
    sim.apply_fn_ = &apply;
    sim.settle_fn_ = &settle;
    sim.guards_fn_ = &guards;
    sim.enter_fn_ = &enter;
    sim.acc_fn_ = &current;
    sim.full_contact_fn_ =
        settings.exact_full_contact && F.base ? &quiet_full_contact_step : nullptr;
    switch (settings.stepper) {
      case Stepper::kRk4Located:
        bind_intervals<methods::Rk4>(sim, settings.exact_full_contact);
        return;
#if !PLINTH_CORE_RK4_ONLY
      case Stepper::kRk4StepEnd:
        bind_intervals<methods::Rk4StepEnd>(sim, settings.exact_full_contact);
        return;
      case Stepper::kHeunLocated:
        bind_intervals<methods::Heun>(sim, settings.exact_full_contact);
        return;
      case Stepper::kSemiImplicitEuler:
        bind_intervals<methods::SemiImplicitEuler>(sim, settings.exact_full_contact);
        return;
#else
      default:  // validate() refused the others: not compiled in
        return;
#endif
    }
  }
};

// ---------------------------------------------------------------------------------------------
// One interval of a step in a fixed mode: the stepper `Method` on the phase's `Kernel`, guards
// at both ends, the first crossing located (or, for a step-end method, taken at the end), its
// reset applied.
template <class Method, class Kernel>
struct Interval {
  static State advance(const Kernel& k, double t, const State& y, const FlowPoint& start,
                       double h, const GroundAcceleration* end_ground = nullptr) {
    if constexpr (Kernel::kExact) {
      return k.advance(t, y, start, h, end_ground);
    } else {
      return Method::advance(k, t, y, state_derivative(y, start.acc), h, end_ground);
    }
  }

  static void evaluate(const Scene& s, const Mode& mode, const ActiveGuards& guards,
                       const State& y, const FlowPoint& p, GuardValues& out) {
    for (int i = 0; i < guards.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      out[k] = step_guard_value(guards.ids[k], s, mode, y, p);
    }
  }

  // evaluate at the interval's end, and whether any guard may have crossed since the start:
  // negative or zero there and not negative now (both zero: resting on the surface). The
  // step-end methods need a strict start; first_event sorts that out.
  static bool evaluate_and_check(const Scene& s, const Mode& mode, const ActiveGuards& guards,
                                 const State& y, const FlowPoint& p, const GuardValues& start,
                                 GuardValues& out) {
    bool any = false;
    for (int i = 0; i < guards.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double b = step_guard_value(guards.ids[k], s, mode, y, p);
      const double a = start[k];
      out[k] = b;
      any = any || (a <= 0.0 && b >= 0.0 && (a < 0.0 || b > 0.0));
    }
    return any;
  }

  static double guard_at(const Simulator& sim, const Kernel& k, const Mode& mode, GuardId id,
                         double t, const State& y) {
    const FlowPoint p = k.point(y, k.ground(t));
    return guard_value(id, *sim.scene_, mode, y, p.ground, p.acc, p.trig);
  }

  // Time tau in (a, b] at which guard `id` reaches 0 on the method's solution from (t0, y0):
  // the witness tau -> g(t0 + tau, advance(y0, tau)) is bracketed by g(a) < 0 <= g(b) and its
  // root found by the Illinois variant of regula falsi, with a bisection whenever an update
  // fails to halve the bracket. Returns the bracket's upper end, where the guard holds.
  [[gnu::noinline]] static double locate(const Simulator& sim, const Kernel& k,
                                         const Mode& mode, GuardId id, double t0,
                                         const State& y0, const FlowPoint& start, double a,
                                         double fa, double b, double fb) {
    const double tolerance = sim.settings_.event_time_tolerance * sim.settings_.step;
    int last_side = 0;
    bool bisect = false;
    for (int iteration = 0; iteration < 200 && b - a > tolerance; ++iteration) {
      const double width = b - a;
      double c = bisect ? 0.5 * (a + b) : (a * fb - b * fa) / (fb - fa);
      if (!(c > a && c < b)) c = 0.5 * (a + b);
      const double fc = guard_at(sim, k, mode, id, t0 + c, advance(k, t0, y0, start, c));
      if (fc >= 0.0) {
        b = c;
        fb = fc;
        if (last_side == 1) fa *= 0.5;
        last_side = 1;
      } else {
        a = c;
        fa = fc;
        if (last_side == -1) fb *= 0.5;
        last_side = -1;
      }
      bisect = (b - a) > 0.5 * width;
    }
    return b;
  }

  // Crossing time of a guard that is negative or exactly zero at the start and non-negative
  // at the end. Exactly zero means a reset has just put the state on the guard's surface
  // (theta = 0 after an impact, u = +-u_max after a stop hit): the motion leaves the surface
  // and may come back within the same step, so the step is probed for the excursion below 0
  // and the return is located from there. An excursion too small to see is taken as an event
  // at the end of the interval.
  static double first_crossing(const Simulator& sim, const Kernel& k, const Mode& mode,
                               GuardId id, double t0, const State& y0, const FlowPoint& start,
                               double h, double g_start, double g_end) {
    if (g_start < 0.0) return locate(sim, k, mode, id, t0, y0, start, 0.0, g_start, h, g_end);
    for (const double fraction : {0.0625, 0.25, 0.5, 0.75}) {
      const double tau = fraction * h;
      const double g = guard_at(sim, k, mode, id, t0 + tau, advance(k, t0, y0, start, tau));
      if (g < 0.0) return locate(sim, k, mode, id, t0, y0, start, tau, g, h, g_end);
    }
    return h;
  }

  // The guard that crossed first, and when (tau from t0); tau is infinite when none did.
  struct Crossing {
    GuardId id = GuardId::kRockingImpact;
    double tau = std::numeric_limits<double>::infinity();
  };

  // Out of line: the step's hot path only checks that no guard changed sign (any_crossing).
  [[gnu::noinline]] static Crossing first_event(const Simulator& sim, const Kernel& k,
                                                const Mode& mode, const ActiveGuards& guards,
                                                double t0, const State& y0,
                                                const FlowPoint& start, double h,
                                                const GuardValues& g_start,
                                                const GuardValues& g_end) {
    Crossing first;
    for (int i = 0; i < guards.count; ++i) {
      const auto j = static_cast<std::size_t>(i);
      const double a = g_start[j];
      const double b = g_end[j];
      if constexpr (Method::kLocated) {
        if (a > 0.0 || b < 0.0 || (a == 0.0 && b == 0.0)) continue;
        const double tau = first_crossing(sim, k, mode, guards.ids[j], t0, y0, start, h, a, b);
        if (tau < first.tau) first = {guards.ids[j], tau};
      } else {
        // No location: the crossing seen at the step's end; the guards are ranked by where
        // their straight line between the ends crosses zero.
        if (!(a < 0.0 && b >= 0.0)) continue;
        const double tau = h * (a / (a - b));
        if (tau < first.tau) first = {guards.ids[j], tau};
      }
    }
    return first;
  }

  PLINTH_FLATTEN static bool run(Simulator& sim, double& t0, double t_end, bool guards_live,
                                 bool full_step) {
    const Scene& s = *sim.scene_;
    const Mode mode = sim.mode_;
    const State& y0 = sim.y_;  // replaced only once y1 (or the event's state) is complete
    const double h = t_end - t0;
    Kernel k({s, sim.excitation_, sim.propagator_, full_step ? h : 0.0, mode, y0});
    static constexpr ActiveGuards kNone{};
    const ActiveGuards& guards = guards_live ? sim.active_guards_ : kNone;
    // The start: kept from the end of the last step when it had no event.
    const std::size_t next = 1 - sim.current_;
    FlowPoint& start = sim.points_[sim.current_];
    GuardValues& g_start = sim.guard_values_[sim.current_];
    if (!sim.cache_valid_) {
      start = k.point(y0, k.ground(t0));
      evaluate(s, mode, guards, y0, start, g_start);
    }
    const GroundAcceleration end_ground = k.ground(t_end);
    const State y1 = advance(k, t0, y0, start, h, t0 + h == t_end ? &end_ground : nullptr);
    FlowPoint& end = sim.points_[next];
    GuardValues& g_end = sim.guard_values_[next];
    end = k.point(y1, end_ground);
    const Crossing first =
        evaluate_and_check(s, mode, guards, y1, end, g_start, g_end)
            ? first_event(sim, k, mode, guards, t0, y0, start, h, g_start, g_end)
            : Crossing{};
    if (!std::isfinite(first.tau)) {
      sim.y_ = y1;
      sim.current_ = next;
      sim.cache_valid_ = guards_live;
      t0 = t_end;
      return false;
    }
    sim.cache_valid_ = false;
    if constexpr (Method::kLocated) {
      sim.y_ = advance(k, t0, y0, start, first.tau);
      t0 += first.tau;
    } else {
      sim.y_ = y1;
      t0 = t_end;
    }
    sim.apply_fn_(sim, first.id, t0);
    return true;
  }
};

template <Features F>
template <class Method>
void Hybrid<F>::bind_intervals(Simulator& sim, bool exact_full_contact) {
  auto& fns = sim.interval_fns_;
  constexpr auto at = [](Phase p) { return static_cast<std::size_t>(p); };
  if constexpr (F.base) {
    fns[at(Phase::kFullContact)] = exact_full_contact
                                       ? &Interval<Method, kernels::ExactFullContact>::run
                                       : &Interval<Method, kernels::FullContact>::run;
  } else {
    (void)exact_full_contact;  // nothing moves in full contact on the ground
    fns[at(Phase::kFullContact)] = &Interval<Method, kernels::FullContact>::run;
  }
  fns[at(Phase::kRocking)] = &Interval<Method, kernels::Rocking>::run;
  if constexpr (F.sliding) {
    fns[at(Phase::kSliding)] = &Interval<Method, kernels::Sliding>::run;
    fns[at(Phase::kSlideRocking)] = &Interval<Method, kernels::SlideRocking>::run;
  } else {
    fns[at(Phase::kSliding)] = &Interval<Method, kernels::Frozen>::run;
    fns[at(Phase::kSlideRocking)] = &Interval<Method, kernels::Frozen>::run;
  }
}

namespace {

// Binds the hybrid logic compiled for exactly the features the scene has.
template <bool kBase, bool kBaseStops>
void bind_for_friction(Simulator& sim, const Features& f, const SolverSettings& settings) {
  if (!f.sliding) {
    Hybrid<Features{kBase, kBaseStops, false, false, false}>::bind(sim, settings);
  } else if (f.support_edge) {
    Hybrid<Features{kBase, kBaseStops, true, true, false}>::bind(sim, settings);
  } else if (f.sliding_stops) {
    Hybrid<Features{kBase, kBaseStops, true, false, true}>::bind(sim, settings);
  } else {
    Hybrid<Features{kBase, kBaseStops, true, false, false}>::bind(sim, settings);
  }
}

}  // namespace

Error Simulator::create(const Scene& scene, const Excitation& excitation,
                        const SolverSettings& settings, Simulator& out) {
  PLINTH_TRY(validate(settings));
  if (const double limit = largest_stable_step(scene, settings.stepper); settings.step > limit) {
    return {ErrorCode::kOutOfRange, "solver.step",
            "is too large for a stable integration of this scene's base (stiff or light base)",
            limit};
  }
  Simulator sim;
  sim.scene_ = &scene;
  sim.excitation_ = excitation;
  sim.settings_ = settings;
  sim.events_at_step_ends_ = settings.stepper == Stepper::kRk4StepEnd;
  if (settings.exact_full_contact) {
    sim.propagator_ = FullContactPropagator::make(scene, settings.step);
  }
  const Features f = features_of(scene);
  if (!f.base) {
    bind_for_friction<false, false>(sim, f, settings);
  } else if (!f.base_stops) {
    bind_for_friction<true, false>(sim, f, settings);
  } else {
    bind_for_friction<true, true>(sim, f, settings);
  }
  out = sim;
  return ok_error();
}

void Simulator::start_from(const Mode& mode, const State& state) {
  step_count_ = 0;
  cache_valid_ = false;
  quiet_ground_step_ = -1;
  chatter_steps_ = 0;
  event_count_ = 0;
  mode_ = mode;
  y_ = state;
  enter_fn_(*this, 0.0);
  refresh_guards();
}

void Simulator::start_at_rest() { start_from(Mode{}, State::Zero()); }

void Simulator::start_with_impulse(double impulse) {
  State y = State::Zero();
  Mode mode;
  if (scene_->has_base()) {
    y[kUDot] = impulse;  // the base keeps its absolute velocity; the ground's jumps by -I
    start_from(mode, y);
    return;
  }
  start_from(mode, y);
  if (impulse == 0.0) return;
  // On the ground, the block moves at +I relative to it and is caught by the corner ahead:
  // angular momentum about that corner, -m h I = I_i theta'(0+).
  const Corner corner = impulse > 0.0 ? Corner::kRight : Corner::kLeft;
  mode_.phase = Phase::kRocking;
  mode_.corner = corner;
  y_[kThetaDot] = -scene_->m * scene_->h * impulse / scene_->corner(corner).inertia;
  refresh_guards();
  Event e;
  e.t = 0.0;
  e.kind = EventKind::kRockingStart;
  e.corner = corner;
  e.phase = mode_.phase;
  e.state = y_;
  emit(e);
}

// One step by intervals: the stepper in the current mode, then event after event.
void Simulator::step_intervals() {
  if (mode_.terminal()) return;
  const double t_end = static_cast<double>(step_count_ + 1) * settings_.step;
  double t0 = time();
  if (interval_fns_[static_cast<std::size_t>(mode_.phase)](*this, t0, t_end, true, true)) {
    finish_step(t0, t_end);
  }
  ++step_count_;
}

// The rest of a step after its first event, at t0: the new mode to t_end, event after event;
// past max_events_per_step, chatter is settled and the step ends without guards.
void Simulator::finish_step(double t0, double t_end) {
  int events = 0;
  bool guards_live = true;
  do {
    if (mode_.terminal()) return;
    refresh_guards();
    if (++events >= settings_.max_events_per_step) {
      settle_fn_(*this, t0);
      refresh_guards();
      guards_live = false;
    }
  } while (t_end - t0 > 0.0 &&
           interval_fns_[static_cast<std::size_t>(mode_.phase)](*this, t0, t_end, guards_live,
                                                                false));
}

Accelerations Simulator::accelerations() const { return acc_fn_(*this, time(), y_); }

}  // namespace plinth

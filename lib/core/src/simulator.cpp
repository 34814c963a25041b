#include "plinth/core/simulator.h"

#include <array>
#include <cmath>
#include <limits>

#include "plinth/core/energy.h"
#include "plinth/core/flows.h"
#include "plinth/core/guards.h"
#include "plinth/core/resets.h"

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

Error validate(const SolverSettings& st) {
  if (!std::isfinite(st.step) || st.step <= 0.0) {
    return {ErrorCode::kOutOfRange, "solver.step", "must be a finite number greater than zero"};
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

}  // namespace

double largest_stable_step(const Scene& s) {
  if (!s.has_base()) return std::numeric_limits<double>::infinity();
  constexpr double kRk4StabilityRadius = 2.5;  // below 2.78 (real axis) and 2.83 (imaginary)
  const double base_mass = s.total_mass - s.m;
  const double rate = std::max(largest_rate(s.total_mass, s.damping, s.stiffness),
                               largest_rate(base_mass, s.damping, s.stiffness));
  return kRk4StabilityRadius / rate;
}

// The solver for one set of model features: what a scene does not have is compiled out.
template <Features F>
struct Stepper {
  static bool base_moves(const Mode& mode) {
    if constexpr (!F.base) {
      return false;
    } else {
      return mode.held_stop == 0;
    }
  }

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

  static State derivative(const Simulator& sim, const Mode& mode, double t, const State& y) {
    const Accelerations a = accelerations(*sim.scene_, mode, y, sim.excitation_.at(t));
    State d;
    d << y[kUDot], y[kXDot], y[kThetaDot], a.u, a.x, a.theta;
    return d;
  }

  // One classical Runge-Kutta step of size h from (t, y) in `mode`.
  static State rk4(const Simulator& sim, const Mode& mode, double t, const State& y, double h) {
    const State k1 = derivative(sim, mode, t, y);
    const State k2 = derivative(sim, mode, t + 0.5 * h, y + 0.5 * h * k1);
    const State k3 = derivative(sim, mode, t + 0.5 * h, y + 0.5 * h * k2);
    const State k4 = derivative(sim, mode, t + h, y + h * k3);
    return y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }

  static void evaluate_guards(const Simulator& sim, const Mode& mode, const ActiveGuards& guards,
                              double t, const State& y, GuardValues& out) {
    const GroundAcceleration ag = sim.excitation_.at(t);
    const Accelerations acc = accelerations(*sim.scene_, mode, y, ag);
    for (int i = 0; i < guards.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      out[k] = guard_value(guards.ids[k], *sim.scene_, mode, y, ag, acc);
    }
  }

  static double guard_at(const Simulator& sim, const Mode& mode, GuardId id, double t,
                         const State& y) {
    const GroundAcceleration ag = sim.excitation_.at(t);
    return guard_value(id, *sim.scene_, mode, y, ag, accelerations(*sim.scene_, mode, y, ag));
  }

  // Time tau in (a, b] at which guard `id` reaches 0 on the RK4 solution from (t0, y0):
  // the witness tau -> g(t0 + tau, rk4(y0, tau)) is bracketed by g(a) < 0 <= g(b) and its root
  // found by the Illinois variant of regula falsi, with a bisection whenever an update fails
  // to halve the bracket. Returns the bracket's upper end, where the guard holds.
  static double locate(const Simulator& sim, const Mode& mode, GuardId id, double t0,
                       const State& y0, double a, double fa, double b, double fb) {
    const double tolerance = sim.settings_.event_time_tolerance * sim.settings_.step;
    int last_side = 0;
    bool bisect = false;
    for (int iteration = 0; iteration < 200 && b - a > tolerance; ++iteration) {
      const double width = b - a;
      double c = bisect ? 0.5 * (a + b) : (a * fb - b * fa) / (fb - fa);
      if (!(c > a && c < b)) c = 0.5 * (a + b);
      const double fc = guard_at(sim, mode, id, t0 + c, rk4(sim, mode, t0, y0, c));
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
  static double first_crossing(const Simulator& sim, const Mode& mode, GuardId id, double t0,
                               const State& y0, double h, double g_start, double g_end) {
    if (g_start < 0.0) return locate(sim, mode, id, t0, y0, 0.0, g_start, h, g_end);
    for (const double fraction : {0.0625, 0.25, 0.5, 0.75}) {
      const double tau = fraction * h;
      const double g = guard_at(sim, mode, id, t0 + tau, rk4(sim, mode, t0, y0, tau));
      if (g < 0.0) return locate(sim, mode, id, t0, y0, tau, g, h, g_end);
    }
    return h;
  }

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
    if (after * before <= 0.0 ||
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
    if (rebound < sim.settings_.slide_rest_speed) {
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
    if (std::fabs(sim.y_[kUDot]) < sim.settings_.base_rest_speed) hold_if_pushed(sim, t, side);
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

  static void step(Simulator& sim) {
    if (sim.mode_.terminal()) return;
    const double dt = sim.settings_.step;
    const double t_end = static_cast<double>(sim.step_count_ + 1) * dt;
    double t0 = sim.time();
    int events = 0;
    bool guards_live = true;
    for (;;) {
      const double h = t_end - t0;
      if (h <= 0.0) break;
      const Mode mode = sim.mode_;
      const State y0 = sim.y_;
      const State y1 = rk4(sim, mode, t0, y0, h);
      const ActiveGuards guards = guards_live ? active_guards<F>(mode) : ActiveGuards{};
      // The guards at the interval's start: from the cache when the last step ended here in
      // this mode with no event; one flow evaluation serves every guard.
      GuardValues start;
      if (sim.guard_cache_valid_ && events == 0) {
        start = sim.guard_cache_;
      } else {
        evaluate_guards(sim, mode, guards, t0, y0, start);
      }
      GuardValues end;
      evaluate_guards(sim, mode, guards, t_end, y1, end);
      GuardId first = GuardId::kRockingImpact;
      double first_tau = std::numeric_limits<double>::infinity();
      for (int i = 0; i < guards.count; ++i) {
        const auto k = static_cast<std::size_t>(i);
        const double g_start = start[k];
        const double g_end = end[k];
        if (g_start > 0.0 || g_end < 0.0 || (g_start == 0.0 && g_end == 0.0)) continue;
        const double tau = first_crossing(sim, mode, guards.ids[k], t0, y0, h, g_start, g_end);
        if (tau < first_tau) {
          first_tau = tau;
          first = guards.ids[k];
        }
      }
      if (!std::isfinite(first_tau)) {
        sim.y_ = y1;
        sim.guard_cache_ = end;
        sim.guard_cache_valid_ = guards_live;
        break;
      }
      sim.guard_cache_valid_ = false;
      t0 += first_tau;
      sim.y_ = rk4(sim, mode, t0 - first_tau, y0, first_tau);
      apply(sim, first, t0);
      if (sim.mode_.terminal()) break;
      if (++events >= sim.settings_.max_events_per_step) {
        settle(sim, t0);
        guards_live = false;
      }
    }
    ++sim.step_count_;
  }

  static void bind(Simulator& sim) {
    sim.step_fn_ = &step;
    sim.enter_fn_ = &enter;
    sim.acc_fn_ = &current;
  }

  static Accelerations current(const Simulator& sim, double t, const State& y) {
    return accelerations(*sim.scene_, sim.mode_, y, sim.excitation_.at(t));
  }
};

namespace {

// Binds the solver compiled for exactly the features the scene has.
template <bool kBase, bool kBaseStops>
void bind_for_friction(Simulator& sim, const Features& f) {
  if (!f.sliding) {
    Stepper<Features{kBase, kBaseStops, false, false, false}>::bind(sim);
  } else if (f.support_edge) {
    Stepper<Features{kBase, kBaseStops, true, true, false}>::bind(sim);
  } else if (f.sliding_stops) {
    Stepper<Features{kBase, kBaseStops, true, false, true}>::bind(sim);
  } else {
    Stepper<Features{kBase, kBaseStops, true, false, false}>::bind(sim);
  }
}

}  // namespace

Error Simulator::create(const Scene& scene, const Excitation& excitation,
                        const SolverSettings& settings, Simulator& out) {
  if (Error e = validate(settings); !e.ok()) return e;
  if (const double limit = largest_stable_step(scene); settings.step > limit) {
    return {ErrorCode::kOutOfRange, "solver.step",
            "is too large for a stable integration of this scene's base (stiff or light base)",
            limit};
  }
  Simulator sim;
  sim.scene_ = &scene;
  sim.excitation_ = excitation;
  sim.settings_ = settings;
  const Features f = features_of(scene);
  if (!f.base) {
    bind_for_friction<false, false>(sim, f);
  } else if (!f.base_stops) {
    bind_for_friction<true, false>(sim, f);
  } else {
    bind_for_friction<true, true>(sim, f);
  }
  out = sim;
  return ok_error();
}

void Simulator::start_from(const Mode& mode, const State& state) {
  step_count_ = 0;
  guard_cache_valid_ = false;
  chatter_steps_ = 0;
  mode_ = mode;
  y_ = state;
  enter_fn_(*this, 0.0);
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
  Event e;
  e.t = 0.0;
  e.kind = EventKind::kRockingStart;
  e.corner = corner;
  e.phase = mode_.phase;
  e.state = y_;
  emit(e);
}

void Simulator::step() { step_fn_(*this); }

Accelerations Simulator::accelerations() const { return acc_fn_(*this, time(), y_); }

}  // namespace plinth

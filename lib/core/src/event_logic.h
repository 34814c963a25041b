// Private to plinth_core: the hybrid system's discrete part for one set of Features (which
// guards each mode has, the reset at each event, chatter), bound to a Simulator by create.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "build_options.h"
#include "phase_kernels.h"
#include "plinth/core/events.h"
#include "plinth/core/internal/flows.h"
#include "plinth/core/internal/guards.h"
#include "plinth/core/internal/resets.h"
#include "plinth/core/internal/steppers.h"
#include "plinth/core/real.h"
#include "plinth/core/simulator.h"
#include "step_interval.h"

namespace plinth::internal {

// The hybrid logic for one set of model features: which guards each mode has, what happens at
// each event. What a scene does not have is compiled out.
template <Features F>
struct EventLogic {
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
      case Phase::kLiftedOff:
        return {};
    }
    return {};
  }

  static ActiveGuards guards_of(const Mode& mode) { return active_guards<F>(mode); }

  static void emit_event(Simulator& sim, Time t, EventKind kind, int side = 0,
                         Real before = Real(0), Real after = Real(0)) {
    sim.emit_event(t, kind, side, before, after);
  }

  // On entering a mode (at the start or after a reset), the onset conditions that already hold
  // start their phase at once, in the favoured direction: Eq 15/18 (sliding) first, since a
  // block that cannot be held by friction slides and its acceleration drops to what kinetic
  // friction gives it; then Eq 16/17 (rocking) with the accelerations of the new phase. (When
  // both hold at once in full contact, e.g. right after an impulse whose damper force jumps
  // past both thresholds, the block slides, and rocks too only if Eq 17 holds while sliding.)
  static void start_phases_that_hold(Simulator& sim, Time t) {
    const Scene& s = *sim.scene_;
    const GroundAcceleration ag = sim.excitation_.at(t);
    if (sim.lift_off(t)) return;
    for (int pass = 0; pass < 2 && !sim.mode_.terminal(); ++pass) {
      const Accelerations acc = accelerations(s, sim.mode_, sim.y_, ag);
      if constexpr (F.sliding) {
        if (!sim.mode_.sliding()) {
          const Real left = guard_value(GuardId::kSlidingOnsetLeft, s, sim.mode_, sim.y_, ag, acc);
          const Real right =
              guard_value(GuardId::kSlidingOnsetRight, s, sim.mode_, sim.y_, ag, acc);
          if (left >= Real(0) || right >= Real(0)) {
            start_sliding(sim, t, left >= right ? -1 : 1);
            continue;
          }
        }
      }
      if (!sim.mode_.rocking()) {
        const Real left = guard_value(GuardId::kRockingOnsetLeft, s, sim.mode_, sim.y_, ag, acc);
        const Real right = guard_value(GuardId::kRockingOnsetRight, s, sim.mode_, sim.y_, ag, acc);
        if (left >= Real(0) || right >= Real(0)) {
          start_rocking(sim, t, left >= right ? Corner::kLeft : Corner::kRight);
          continue;
        }
      }
      return;
    }
  }

  static void start_rocking(Simulator& sim, Time t, Corner corner) {
    rocking_onset_reset(corner, sim.mode_, sim.y_);
    emit_event(sim, t, EventKind::kRockingStart);
  }

  static void start_sliding(Simulator& sim, Time t, int direction) {
    sliding_onset_reset(direction, sim.mode_);
    emit_event(sim, t, EventKind::kSlidingStart, direction);
  }

  static void stop_rocking(Simulator& sim, Time t, Real theta_dot_before) {
    rocking_stop_reset(*sim.scene_, base_moves(sim.mode_), sim.mode_, sim.y_);
    emit_event(sim, t, EventKind::kRockingStop, 0, theta_dot_before);
  }

  // The slowest rebound from a stop (or impact at theta = 0) the solver follows, m/s (rad/s):
  // `rest_speed`, and with events taken at step ends also k |a| dt, a the acceleration back
  // towards the stop. A hit seen up to a step late has gained up to |a| dt, so with restitution
  // eta rebounds settle near eta |a| dt / (1 - eta) instead of dying out (the Zeno sequence the
  // located methods resolve and settle): k = eta / (1 - eta), within [4, 32] steps.
  static constexpr Real kStepEndRestStepsMin = 4.0;
  static constexpr Real kStepEndRestStepsMax = 32.0;
  // `acceleration()` gives a (computed only for step-end methods).
  template <class Acceleration>
  static Real slowest_rebound(const Simulator& sim, Real rest_speed, Acceleration acceleration,
                              Real restitution) {
    if (!sim.events_at_step_ends_) return rest_speed;
    const Real steps =
        restitution < Real(1) ? restitution / (Real(1) - restitution) : kStepEndRestStepsMax;
    return std::max(rest_speed, std::clamp(steps, kStepEndRestStepsMin, kStepEndRestStepsMax) *
                                    std::fabs(acceleration()) *
                                    static_cast<Real>(sim.settings_.step));
  }

  // Impact at theta = 0 (Eqs 21-24; with friction, the Coulomb impact of resets.h), or the end
  // of rocking when it leaves less rocking energy than the rest criterion's fraction of the new
  // pivot's overturning barrier.
  static void rocking_impact(Simulator& sim, Time t) {
    const Scene& s = *sim.scene_;
    const Real before = sim.y_[kThetaDot];
    const bool was_sliding = sim.mode_.sliding();
    Mode mode = sim.mode_;
    State y = sim.y_;
    if constexpr (F.sliding) {
      (void)coulomb_impact_reset(s, base_moves(mode), mode, y);
    } else {
      rocking_impact_reset(s, base_moves(mode), mode, y);
    }
    const CornerGeometry to = pivot_of(s, mode, y).geometry;
    const Real after = y[kThetaDot];
    const Real barrier = s.m * s.g * (to.radius - s.h);
    sim.mode_ = mode;
    sim.y_ = y;
    // Taken at step ends, impacts closer than a few steps apart are chatter (see slowest_rebound).
    const Real slowest = slowest_rebound(
        sim, Real(0), [&] { return accelerations(s, mode, y, sim.excitation_.at(t)).theta; },
        before != Real(0) ? std::fabs(after / before) : Real(0));
    if (after * before <= Real(0) || std::fabs(after) < slowest ||
        Real(0.5) * to.inertia * after * after < sim.settings_.rest_energy_ratio * barrier) {
      stop_rocking(sim, t, before);
    } else {
      emit_event(sim, t, EventKind::kImpact, 0, before, after);
    }
    if (was_sliding != sim.mode_.sliding()) {
      if (sim.mode_.sliding()) {
        emit_event(sim, t, EventKind::kSlidingStart, sim.mode_.slide_direction);
      } else {
        emit_event(sim, t, EventKind::kSlidingStop);
      }
    }
    start_phases_that_hold(sim, t);
  }

  // x' reached 0: the block sticks if static friction can hold it (Eq 15 or 18 not met in the
  // sticking phase), otherwise it slides back the other way.
  static void sliding_stopped(Simulator& sim, Time t) {
    const Scene& s = *sim.scene_;
    sliding_stop_reset(sim.mode_, sim.y_);
    const GroundAcceleration ag = sim.excitation_.at(t);
    const Accelerations acc = accelerations(s, sim.mode_, sim.y_, ag);
    const ContactForce f = sticking_contact_force(s, sim.mode_, sim.y_, ag, acc);
    const int direction = f.tangential > Real(0) ? -1 : 1;
    // Strictly: with mu_s = 0 and no force at all the block stays put rather than "sliding" at
    // zero speed, re-stopping every step.
    if (sliding_onset_guard(s, sim.mode_, sim.y_, direction, f) > Real(0)) {
      sliding_onset_reset(direction, sim.mode_);
      emit_event(sim, t, EventKind::kSlidingStart, direction);
      return;
    }
    emit_event(sim, t, EventKind::kSlidingStop);
    start_phases_that_hold(sim, t);
  }

  // |x| reached x_hat (Eqs 30-32 with restitution, resets.h): the block rebounds from the stop,
  // or sticks against it once the rebound is slower than settings.slide_rest_speed (this ends
  // the Zeno sequence of ever smaller rebounds of a block pressed against the stop).
  static void sliding_stop_hit(Simulator& sim, Time t, int side) {
    const Scene& s = *sim.scene_;
    const Real before = sim.y_[kXDot];
    const Real rebound = s.params.sliding_stops.restitution * std::fabs(before);
    const Real slowest = slowest_rebound(
        sim, sim.settings_.slide_rest_speed,
        [&] { return accelerations(s, sim.mode_, sim.y_, sim.excitation_.at(t)).x; },
        s.params.sliding_stops.restitution);
    if (rebound < slowest) {
      coordinate_impulse_reset(s, sim.mode_, base_moves(sim.mode_), kXDot, Real(0), sim.y_);
      sim.y_[kX] = static_cast<Real>(side) * s.params.support.clearance;
      sliding_stop_reset(sim.mode_, sim.y_);
      emit_event(sim, t, EventKind::kSlideStopHit, side, before, sim.y_[kUDot]);
      start_phases_that_hold(sim, t);
      return;
    }
    sliding_stop_hit_reset(s, side, base_moves(sim.mode_), sim.mode_, sim.y_);
    emit_event(sim, t, EventKind::kSlideStopHit, side, before, sim.y_[kUDot]);
  }

  static void base_stop_hit(Simulator& sim, Time t, int side) {
    const Scene& s = *sim.scene_;
    const Real before = sim.y_[kUDot];
    base_stop_reset(s, side, sim.mode_, sim.y_);
    emit_event(sim, t, EventKind::kBaseStopHit, side, before, sim.y_[kUDot]);
    if (sim.mode_.sliding()) keep_sliding_consistent(sim, t);
    const Real slowest = slowest_rebound(
        sim, sim.settings_.base_rest_speed,
        [&] { return accelerations(s, sim.mode_, sim.y_, sim.excitation_.at(t)).u; },
        s.params.base_stops.restitution);
    if (std::fabs(sim.y_[kUDot]) < slowest) hold_if_pushed(sim, t, side);
  }

  // An impulse on the base changes x' while sliding: the phase follows its new sign.
  static void keep_sliding_consistent(Simulator& sim, Time t) {
    const Real x_dot = sim.y_[kXDot];
    if (x_dot * sim.mode_.slide_direction > Real(0)) return;
    if (x_dot == Real(0)) {
      sliding_stopped(sim, t);
      return;
    }
    sim.mode_.slide_direction = static_cast<std::int8_t>(x_dot > Real(0) ? 1 : -1);
    emit_event(sim, t, EventKind::kSlidingStart, sim.mode_.slide_direction);
  }

  // The base's rebound is too slow to matter: if the stop pushes back, the base rests on it.
  static void hold_if_pushed(Simulator& sim, Time t, int side) {
    const Scene& s = *sim.scene_;
    Mode held = sim.mode_;
    held.held_stop = static_cast<std::int8_t>(side);
    const GroundAcceleration ag = sim.excitation_.at(t);
    const Real reaction =
        base_stop_reaction(s, held, sim.y_, ag, accelerations(s, held, sim.y_, ag));
    if (static_cast<Real>(side) * reaction > Real(0))
      return;  // the stop would have to pull: the base moves away
    base_stop_hold_reset(s, side, sim.mode_, sim.y_);
    emit_event(sim, t, EventKind::kBaseStopHeld, side);
    start_phases_that_hold(sim, t);
  }

  static void release_base(Simulator& sim, Time t) {
    const int side = sim.mode_.held_stop;
    sim.mode_.held_stop = 0;
    emit_event(sim, t, EventKind::kBaseStopReleased, side);
    start_phases_that_hold(sim, t);
  }

  // |theta| passed the pivot's critical angle: C is over the pivot. About the support's corner
  // that is C passing the support's edge, so the block falls off the base; about its own corner
  // it overturns.
  static void overturn(Simulator& sim, Time t) {
    const Pivot pivot = pivot_of(*sim.scene_, sim.mode_, sim.y_);
    sim.y_[kTheta] = pivot.geometry.sign * pivot.geometry.critical_angle;
    if (pivot.overhanging) {
      sim.mode_.phase = Phase::kFell;
      emit_event(sim, t, EventKind::kFell, sim.mode_.overhang);
      return;
    }
    sim.mode_.phase = Phase::kOverturned;
    emit_event(sim, t, EventKind::kOverturned);
  }

  static void apply_reset(Simulator& sim, GuardId id, Time t) {
    ++sim.event_count_;
    if (id == GuardId::kLiftOff) {
      (void)sim.lift_off(t, true);
      return;
    }
    apply_mode_reset(sim, id, t);
    (void)sim.lift_off(t);
  }

  static void apply_mode_reset(Simulator& sim, GuardId id, Time t) {
    switch (id) {
      case GuardId::kRockingOnsetLeft:
        start_rocking(sim, t, Corner::kLeft);
        start_phases_that_hold(sim, t);
        return;
      case GuardId::kRockingOnsetRight:
        start_rocking(sim, t, Corner::kRight);
        start_phases_that_hold(sim, t);
        return;
      case GuardId::kRockingImpact:
        rocking_impact(sim, t);
        return;
      case GuardId::kOverturning:
        overturn(sim, t);
        return;
      default:
        break;
    }
    // Only the guards active_guards<F> gives can cross: the others' resets are compiled out.
    if constexpr (F.sliding) apply_sliding_reset(sim, id, t);
    if constexpr (F.base_stops) apply_base_stop_reset(sim, id, t);
  }

  static void apply_sliding_reset(Simulator& sim, GuardId id, Time t) {
    switch (id) {
      case GuardId::kSlidingOnsetLeft:
        start_sliding(sim, t, -1);
        start_phases_that_hold(sim, t);
        return;
      case GuardId::kSlidingOnsetRight:
        start_sliding(sim, t, 1);
        start_phases_that_hold(sim, t);
        return;
      case GuardId::kSlidingStop:
        sliding_stopped(sim, t);
        return;
      case GuardId::kSlidingInconsistent: {
        const Real before = sim.y_[kXDot];
        tangential_impact_reset(*sim.scene_, sim.mode_, sim.y_);
        emit_event(sim, t, EventKind::kSlidingStop, 0, before);
        start_phases_that_hold(sim, t);
        return;
      }
      default:
        break;
    }
    if constexpr (F.support_edge) apply_support_edge_reset(sim, id, t);
    if constexpr (F.sliding_stops) {
      if (id == GuardId::kSlidingStopLeft) sliding_stop_hit(sim, t, -1);
      if (id == GuardId::kSlidingStopRight) sliding_stop_hit(sim, t, 1);
    }
  }

  static void apply_support_edge_reset(Simulator& sim, GuardId id, Time t) {
    const Real x_hat = sim.scene_->params.support.clearance;
    switch (id) {
      case GuardId::kOutOfBaseLeft:
      case GuardId::kOutOfBaseRight: {
        const int side = id == GuardId::kOutOfBaseLeft ? -1 : 1;
        sim.y_[kX] = static_cast<Real>(side) * x_hat;
        sim.mode_.overhang = static_cast<std::int8_t>(side);
        emit_event(sim, t, EventKind::kOutOfBase, side);
        if (!sim.mode_.rocking()) start_phases_that_hold(sim, t);
        return;
      }
      case GuardId::kBackOnBase: {
        const int side = sim.mode_.overhang;
        sim.y_[kX] = static_cast<Real>(side) * x_hat;
        sim.mode_.overhang = 0;
        emit_event(sim, t, EventKind::kBackOnBase, side);
        return;
      }
      case GuardId::kFall:
        sim.mode_.phase = Phase::kFell;
        emit_event(sim, t, EventKind::kFell, sim.mode_.overhang);
        return;
      default:
        return;
    }
  }

  static void apply_base_stop_reset(Simulator& sim, GuardId id, Time t) {
    switch (id) {
      case GuardId::kBaseStopRight:
        base_stop_hit(sim, t, +1);
        return;
      case GuardId::kBaseStopLeft:
        base_stop_hit(sim, t, -1);
        return;
      case GuardId::kBaseStopRelease:
        release_base(sim, t);
        return;
      default:
        return;
    }
  }

  // Chatter within one step (Zeno): bring rocking to rest, stop sliding, and hold a base that
  // sits on a stop.
  static void settle_chatter(Simulator& sim, Time t) {
    if (sim.mode_.rocking()) stop_rocking(sim, t, sim.y_[kThetaDot]);
    if constexpr (F.sliding) {
      // Stick-slip chatter: the block sticks for the rest of the step; the next step's guards
      // start it sliding again if friction cannot hold it.
      if (sim.mode_.sliding()) {
        sliding_stop_reset(sim.mode_, sim.y_);
        emit_event(sim, t, EventKind::kSlidingStop);
      }
    }
    if constexpr (F.base_stops) {
      const Real u_max = sim.scene_->params.base_stops.max_displacement;
      if (sim.mode_.held_stop == 0 &&
          std::fabs(sim.y_[kU]) >= u_max * (Real(1) - real_tolerance::kAtStop)) {
        hold_if_pushed(sim, t, sim.y_[kU] > Real(0) ? +1 : -1);
      }
    }
    (void)sim.lift_off(t);
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
  static bool quiet_full_contact_step(Simulator& sim, Time t_end) {
    if constexpr (!F.base) {
      return false;
    } else {
      const Mode& mode = sim.mode_;
      State& y = sim.y_;
      // x and theta at rest, as every reset into full contact leaves them (a state given to
      // start_from may not: the interval advances it).
      if (mode.held_stop != 0 || mode.overhang != 0 || y[kXDot] != Real(0) ||
          y[kThetaDot] != Real(0)) {
        return false;
      }
      const Scene& s = *sim.scene_;
      const Real a0 = sim.quiet_ground_step_ == sim.step_count_
                          ? sim.quiet_ground_horizontal_
                          : kernels::Base::ground(sim.excitation_, sim.time()).horizontal;
      const GroundAcceleration a1 = kernels::Base::ground(sim.excitation_, t_end);
      Real u = y[kU];
      Real u_dot = y[kUDot];
      sim.propagator_.advance(u, u_dot, a0, a1.horizontal);
      const Accelerations acc{full_contact_base_acceleration(s, u, u_dot, a1.horizontal), Real(0),
                              Real(0)};
      if (!(rocking_onset_guard(s, s.corner1.sign, s.corner1.onset_ratio, acc, a1) < Real(0) &&
            rocking_onset_guard(s, s.corner2.sign, s.corner2.onset_ratio, acc, a1) < Real(0))) {
        return false;
      }
      if constexpr (F.sliding) {
        // Eq 15 (x stays: sliding_onset_guard's test of the sliding stops holds as it did).
        const ContactForce f = sticking_contact_force(s, mode, y, a1, acc, SinCos{});
        if (!(sliding_onset_guard(s, mode, y, -1, f, SinCos{}) < Real(0) &&
              sliding_onset_guard(s, mode, y, 1, f, SinCos{}) < Real(0))) {
          return false;
        }
      }
      if constexpr (F.base_stops) {
        if (!(std::fabs(u) - s.params.base_stops.max_displacement < Real(0))) return false;
      }
      y[kU] = u;
      y[kUDot] = u_dot;
      sim.cache_valid_ = false;
      sim.quiet_ground_horizontal_ = a1.horizontal;
      sim.quiet_ground_step_ = sim.step_count_ + 1;
      return true;
    }
  }

  static Accelerations current_accelerations(const Simulator& sim, Time t, const State& y,
                                             GroundAcceleration* ground) {
    const GroundAcceleration ag = sim.excitation_.at(t);
    if (ground != nullptr) *ground = ag;
    return accelerations(*sim.scene_, sim.mode_, y, ag);
  }

  // Binds the logic and the stepper's intervals for each phase to `sim` (Simulator::create).
  static void bind_to(Simulator& sim, const SolverSettings& settings) {
    sim.apply_reset_fn_ = &apply_reset;
    sim.settle_chatter_fn_ = &settle_chatter;
    sim.guards_fn_ = &guards_of;
    sim.start_phases_fn_ = &start_phases_that_hold;
    sim.accelerations_fn_ = &current_accelerations;
    sim.quiet_full_contact_step_fn_ =
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

  // The interval of Method on Kernel: flattened, or through kernels::Erased.
  template <class Method, class Kernel>
  static constexpr Simulator::IntervalFn interval() {
    if constexpr (PLINTH_CORE_ONE_INTERVAL) {
      return &StepInterval<Method, Kernel>::erased_interval;
    } else {
      return &StepInterval<Method, Kernel>::advance_interval;
    }
  }

  template <class Method>
  static void bind_intervals(Simulator& sim, bool exact_full_contact) {
    auto& fns = sim.interval_fns_;
    constexpr auto at = [](Phase p) { return static_cast<std::size_t>(p); };
    if constexpr (F.base) {
      fns[at(Phase::kFullContact)] = exact_full_contact
                                         ? interval<Method, kernels::ExactFullContact>()
                                         : interval<Method, kernels::FullContact>();
    } else {
      (void)exact_full_contact;  // nothing moves in full contact on the ground
      fns[at(Phase::kFullContact)] = interval<Method, kernels::FullContact>();
    }
    fns[at(Phase::kRocking)] = interval<Method, kernels::Rocking>();
    if constexpr (F.sliding) {
      fns[at(Phase::kSliding)] = interval<Method, kernels::Sliding>();
      fns[at(Phase::kSlideRocking)] = interval<Method, kernels::SlideRocking>();
    } else {
      fns[at(Phase::kSliding)] = interval<Method, kernels::Frozen>();
      fns[at(Phase::kSlideRocking)] = interval<Method, kernels::Frozen>();
    }
  }
};

}  // namespace plinth::internal

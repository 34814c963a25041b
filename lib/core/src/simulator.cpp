// The simulator's set-up and the step's frame: the event logic (event_logic.h) and the steppers'
// intervals (step_interval.h) compiled for the scene's features are bound here, once, by
// feature_sets.cpp.
#include "plinth/core/simulator.h"

#include <cmath>
#include <cstddef>

#include "build_options.h"
#include "event_logic.h"
#include "feature_sets.h"
#include "plinth/core/stability.h"

namespace plinth {

Error validate(const SolverSettings& st) {
  if (!std::isfinite(st.step) || st.step <= 0.0) {
    return {ErrorCode::kOutOfRange, "solver.step", "must be a finite number greater than zero"};
  }
  if (kStepperNames.name(st.stepper, nullptr) == nullptr) {
    static constexpr auto kOneOfSteppers = joined_names<kStepperNames>("must be one of ");
    return {ErrorCode::kOutOfRange, "solver.stepper", kOneOfSteppers.data()};
  }
  if (PLINTH_CORE_RK4_ONLY && st.stepper != Stepper::kRk4Located) {
    return {ErrorCode::kOutOfRange, "solver.stepper",
            "must be rk4_located: this build has no other (PLINTH_CORE_RK4_ONLY)"};
  }
  if (!std::isfinite(st.rest_energy_ratio) || st.rest_energy_ratio <= Real(0) ||
      st.rest_energy_ratio >= Real(1)) {
    return {ErrorCode::kOutOfRange, "solver.rest_energy_ratio", "must lie in (0, 1)"};
  }
  if (!std::isfinite(st.base_rest_speed) || st.base_rest_speed < Real(0)) {
    return {ErrorCode::kOutOfRange, "solver.base_rest_speed", "must be finite and not negative"};
  }
  if (!std::isfinite(st.slide_rest_speed) || st.slide_rest_speed < Real(0)) {
    return {ErrorCode::kOutOfRange, "solver.slide_rest_speed", "must be finite and not negative"};
  }
  if (st.max_events_per_step < 1) {
    return {ErrorCode::kOutOfRange, "solver.max_events_per_step", "must be at least 1"};
  }
  if (!std::isfinite(st.event_time_tolerance) || st.event_time_tolerance <= Real(0) ||
      st.event_time_tolerance > Real(0.1)) {
    return {ErrorCode::kOutOfRange, "solver.event_time_tolerance", "must lie in (0, 0.1]"};
  }
  return ok_error();
}

Error Simulator::create(const Scene& scene, const Excitation& excitation,
                        const SolverSettings& settings, Simulator& out) {
  PLINTH_TRY(validate(settings));
  if (const auto limit = static_cast<Time>(largest_stable_step(scene, settings.stepper));
      settings.step > limit) {
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
    sim.propagator_ =
        internal::FullContactPropagator::make(scene, static_cast<Real>(settings.step));
  }
  PLINTH_TRY(validate_feature_set(scene));
  internal::bind_event_logic(sim, features_of(scene), settings);
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
  start_phases_fn_(*this, Real(0));
  refresh_guards();
}

void Simulator::start_at_rest() { start_from(Mode{}, State::Zero()); }

void Simulator::start_with_impulse(Real impulse) {
  State y = State::Zero();
  Mode mode;
  if (scene_->has_base()) {
    y[kUDot] = impulse;  // the base keeps its absolute velocity; the ground's jumps by -I
    start_from(mode, y);
    return;
  }
  start_from(mode, y);
  if (impulse == Real(0)) return;
  // On the ground, the block moves at +I relative to it and is caught by the corner ahead:
  // angular momentum about that corner, -m h I = I_i theta'(0+).
  const Corner corner = impulse > Real(0) ? Corner::kRight : Corner::kLeft;
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
  emit_event(e);
  (void)lift_off(0.0);  // a spin fast enough to unload the pivot (Eq 12)
}

// One step by intervals: the stepper in the current mode, then event after event.
void Simulator::step_intervals(Time t_end) {
  if (mode_.terminal()) return;
  Time t0 = time();
  if (interval_fns_[static_cast<std::size_t>(mode_.phase)](*this, t0, t_end, true, true)) {
    finish_step(t0, t_end);
  }
  ++step_count_;
}

// The rest of a step after its first event, at t0: the new mode to t_end, event after event;
// past max_events_per_step, chatter is settled and the step ends without guards.
void Simulator::finish_step(Time t0, Time t_end) {
  int events = 0;
  bool guards_live = true;
  do {
    if (mode_.terminal()) return;
    refresh_guards();
    if (++events >= settings_.max_events_per_step) {
      settle_chatter_fn_(*this, t0);
      refresh_guards();
      guards_live = false;
    }
  } while (t_end - t0 > 0.0 && interval_fns_[static_cast<std::size_t>(mode_.phase)](
                                   *this, t0, t_end, guards_live, false));
}

Accelerations Simulator::accelerations() const {
  return accelerations_fn_(*this, time(), y_, nullptr);
}

bool Simulator::lift_off(Time t, bool located) {
  if (mode_.terminal()) return false;
  GroundAcceleration ag;  // through the bound function: the excitation's code stays there
  const Accelerations acc = accelerations_fn_(*this, t, y_, &ag);
  if (!located &&
      internal::lift_off_guard(*scene_, mode_, y_, ag, acc, internal::sin_cos(y_[kTheta])) <
          Real(0)) {
    return false;
  }
  const Phase left = mode_.phase;
  mode_.phase = Phase::kLiftedOff;
  emit_event(t, EventKind::kLiftOff, 0, scene_->g + ag.vertical, Real(0), left);
  return true;
}

void Simulator::emit_event(Time t, EventKind kind, int side, Real before, Real after,
                           Phase left) {
  if (sink_ == nullptr) return;
  Event e;
  e.t = t;
  e.kind = kind;
  e.corner = mode_.corner;
  e.side = static_cast<std::int8_t>(side);
  e.before = before;
  e.after = after;
  e.phase = mode_.phase;
  e.overhang = mode_.overhang;
  e.left = left;
  e.state = y_;
  sink_->on_event(e);
}

}  // namespace plinth

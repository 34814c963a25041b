// The fixed-step hybrid solver: a one-step method (stepper.h; RK4 by default) on the current
// phase's equations, every event located inside the step, the reset applied there, and the
// step finished in the new phase so the time grid stays fixed. The flows, guards, resets and
// steppers it is made of are internal (internal/*.h); the largest stable step: stability.h.
#pragma once

#include <array>
#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/events.h"
#include "plinth/core/excitation.h"
#include "plinth/core/internal/flows.h"
#include "plinth/core/internal/full_contact_propagator.h"
#include "plinth/core/internal/guards.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"
#include "plinth/core/stepper.h"

namespace plinth {
namespace internal {
template <Features F>
struct EventLogic;
template <class Method, class Kernel>
struct StepInterval;
}  // namespace internal

struct SolverSettings {
  Time step = Real(1e-4);  // s, the fixed time step
  // The one-step method and how events are taken (stepper.h). docs/accuracy.md measures them.
  Stepper stepper = Stepper::kRk4Located;
  // Full contact (Eq 1, linear) propagated exactly over each step with the ground acceleration
  // linear within it (internal/full_contact_propagator.h), whatever the stepper; its guards (Eqs
  // 15, 16, 28) are evaluated, and located, on that exact solution.
  bool exact_full_contact = false;
  // Rest criterion: rocking ends at an impact that leaves less rocking energy than this
  // fraction of the energy needed to overturn, I theta'^2 / 2 < ratio m g (r_i - h).
  Real rest_energy_ratio = Real(1e-6);
  // The base is held at a stop when it rebounds slower than this while the stop pushes, m/s.
  // (rk4_step_end: or slower than a few steps of its acceleration; event_logic.h, slowest_rebound.)
  Real base_rest_speed = Real(1e-5);
  // The block sticks against a sliding stop instead of rebounding slower than this, m/s (the
  // same addition for rk4_step_end).
  Real slide_rest_speed = Real(1e-5);
  // Events located within one step before the remaining ones are treated as chatter (Zeno):
  // rocking is brought to rest, sliding stopped and the base held, and the step finishes
  // without further events.
  int max_events_per_step = 64;
  // Events are located in time to within this fraction of the step: 1e-10 in double, 64
  // roundings in float (real.h, real_tolerance::kEventTime).
  Real event_time_tolerance = real_tolerance::kEventTime;
};

// Checks the settings; the Error names the field at fault.
[[nodiscard]] Error validate(const SolverSettings& settings);

// Refuses a scene whose feature set (Features) this build leaves out (PLINTH_CORE_FEATURE_SETS;
// every set by default), naming the set; Simulator::create does the same.
[[nodiscard]] Error validate_feature_set(const Scene& scene);

class Simulator {
 public:
  Simulator() = default;

  // `scene` and the signals `excitation` refers to must outlive the simulator. Fails on
  // invalid settings (the Error names the field), and on a step too large for a stable
  // integration of the scene (field "solver.step", `limit` = largest_stable_step for the
  // stepper). The stepper and the features of the scene select the code once, here.
  [[nodiscard]] static Error create(const Scene& scene, const Excitation& excitation,
                                    const SolverSettings& settings, Simulator& out);

  // t = 0, at rest, full contact (sliding or rocking starts at once if Eq 15 or 16 holds).
  void start_at_rest();
  // Impulse I, the initial condition of Eq 34: the ground's velocity jumps by -I, m/s. On a
  // base, u'(0+) = I; on the ground, the block turns about the corner the jump throws it on,
  // with theta'(0+) = -m h I / I_i (angular momentum about that corner).
  void start_with_impulse(Real impulse);
  // Starts from an arbitrary mode and state at time 0 (tests and estimators).
  void start_from(const Mode& mode, const State& state);

  // Advances one step (no-op once a terminal phase is reached). A quiet step of exactly
  // propagated full contact is taken here, without a call to the step's intervals.
  void step() {
    const Time t_end = static_cast<Time>(step_count_ + 1) * settings_.step;
    if (mode_.phase == Phase::kFullContact && quiet_full_contact_step_fn_ != nullptr &&
        quiet_full_contact_step_fn_(*this, t_end)) {
      ++step_count_;
      return;
    }
    step_intervals(t_end);
  }

  void set_event_sink(EventSink* sink) { sink_ = sink; }

  [[nodiscard]] Time time() const { return static_cast<Time>(step_count_) * settings_.step; }
  [[nodiscard]] std::int64_t step_count() const { return step_count_; }
  [[nodiscard]] const State& state() const { return y_; }
  [[nodiscard]] const Mode& mode() const { return mode_; }
  [[nodiscard]] const Scene& scene() const { return *scene_; }
  [[nodiscard]] const SolverSettings& settings() const { return settings_; }
  [[nodiscard]] GroundAcceleration ground(Time t) const { return excitation_.at(t); }
  // Accelerations of the current mode at the current time and state.
  [[nodiscard]] Accelerations accelerations() const;
  // Number of steps whose events were cut short as chatter (see max_events_per_step).
  [[nodiscard]] std::int64_t chatter_steps() const { return chatter_steps_; }
  // Number of events located (or taken at step ends) since the start, resets applied.
  [[nodiscard]] std::int64_t event_count() const { return event_count_; }

 private:
  template <Features F>
  friend struct internal::EventLogic;
  template <class Method, class Kernel>
  friend struct internal::StepInterval;
  friend struct SimulatorTestPeer;  // tests: turns the quiet full-contact step off to compare

  void emit_event(const Event& event) {
    if (sink_ != nullptr) sink_->on_event(event);
  }
  // The event `kind` at t, of the current mode and state: one copy out of line for every
  // feature set's event logic (the Cortex-M image's flash), built only when a sink listens.
  void emit_event(Time t, EventKind kind, int side, Real before, Real after,
                  Phase left = Phase::kFullContact);
  // The guards of the current mode, after it changed.
  void refresh_guards() { active_guards_ = guards_fn_(mode_); }
  void step_intervals(Time t_end);
  // Lift-off (guards.h, kLiftOff): the run ends in Phase::kLiftedOff at t, the state that of the
  // lift-off, with the event. `located`: the guard's crossing was located at t; otherwise (after
  // a reset or at a start, where a guard already past 0 would never cross) only when the mode
  // has no normal force left there (the ground already falling faster than gravity, a jump of
  // theta' that unloads the pivot). True when it lifted off. One copy for every feature set.
  bool lift_off(Time t, bool located = false);
  [[gnu::noinline]] void finish_step(Time t0, Time t_end);

  // Advances in the current mode from t0 towards t_end (one interval of a step, StepInterval in
  // step_interval.h). On an event it applies the reset, sets t0 to the event's time and returns
  // true.
  // `full_step`: the interval is the whole step (no event before it in this step).
  using IntervalFn = bool (*)(Simulator&, Time& t0, Time t_end, bool guards_live, bool full_step);

  const Scene* scene_ = nullptr;
  Excitation excitation_;
  SolverSettings settings_;
  EventSink* sink_ = nullptr;
  // Bound once by create: the stepper's interval for each non-terminal Phase, and the event
  // logic (guards, resets) compiled for the scene's features (EventLogic, event_logic.h).
  std::array<IntervalFn, 4> interval_fns_{};
  void (*apply_reset_fn_)(Simulator&, internal::GuardId, Time t) = nullptr;
  void (*settle_chatter_fn_)(Simulator&, Time t) = nullptr;
  internal::ActiveGuards (*guards_fn_)(const Mode&) = nullptr;
  void (*start_phases_fn_)(Simulator&, Time t) = nullptr;  // whose onset already holds
  // The current mode's accelerations at (t, y); the ground's there into *ground when given.
  Accelerations (*accelerations_fn_)(const Simulator&, Time t, const State&,
                                     GroundAcceleration* ground) = nullptr;
  // exact_full_contact: a quiet whole step of full contact, from time() to t_end (false: take
  // the interval).
  bool (*quiet_full_contact_step_fn_)(Simulator&, Time t_end) = nullptr;
  // u_G'' at the end of the last quiet full-contact step, the start of step number
  // quiet_ground_step_, m/s2.
  Real quiet_ground_horizontal_ = 0.0;
  std::int64_t quiet_ground_step_ = -1;
  internal::FullContactPropagator propagator_;  // for exact_full_contact, over one step
  bool events_at_step_ends_ = false;  // the stepper takes events at step ends (rest speeds)
  Mode mode_;
  State y_ = State::Zero();
  internal::ActiveGuards active_guards_;
  // The flow point and guard values at the start of the interval (points_[current_]) and at its
  // end (the other one, which becomes current when the step had no event: the next step starts
  // at the same time, state and mode, and this is its first stage). cache_valid_: the current
  // one holds the current time, state and mode.
  std::array<internal::FlowPoint, 2> points_{};
  std::array<internal::GuardValues, 2> guard_values_{};
  std::size_t current_ = 0;
  bool cache_valid_ = false;
  std::int64_t step_count_ = 0;
  std::int64_t chatter_steps_ = 0;
  std::int64_t event_count_ = 0;
};

}  // namespace plinth

// The fixed-step hybrid solver: RK4 on the current phase's equations, every event located
// inside the step, the reset applied there, and the step finished in the new phase so the
// time grid stays fixed.
#pragma once

#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/events.h"
#include "plinth/core/excitation.h"
#include "plinth/core/guards.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth {

struct SolverSettings {
  double step = 1e-4;  // s, the fixed time step of RK4
  // Rest criterion: rocking ends at an impact that leaves less rocking energy than this
  // fraction of the energy needed to overturn, I theta'^2 / 2 < ratio m g (r_i - h).
  double rest_energy_ratio = 1e-6;
  // The base is held at a stop when it rebounds slower than this while the stop pushes, m/s.
  double base_rest_speed = 1e-5;
  // The block sticks against a sliding stop instead of rebounding slower than this, m/s.
  double slide_rest_speed = 1e-5;
  // Events located within one step before the remaining ones are treated as chatter (Zeno):
  // rocking is brought to rest, sliding stopped and the base held, and the step finishes
  // without further events.
  int max_events_per_step = 64;
  // Events are located in time to within this fraction of the step.
  double event_time_tolerance = 1e-10;
};

// Checks the settings; the Error names the field at fault.
[[nodiscard]] Error validate(const SolverSettings& settings);

// The largest step RK4 integrates the scene's base stably, s: 2.5 / |lambda|max over the base's
// linear dynamics m_eff u'' + c u' + k u = 0, with m_eff = m + m_b (full contact) and m_b alone
// (the block sliding or rocking lets the base move without it, at most). RK4's stability region
// reaches 2.78 on the real axis and 2.83 on the imaginary one. Infinity without a base.
[[nodiscard]] double largest_stable_step(const Scene& scene);

class Simulator {
 public:
  Simulator() = default;

  // `scene` and the signals `excitation` refers to must outlive the simulator. Fails on
  // invalid settings (the Error names the field), and on a step too large for a stable
  // integration of the scene (field "solver.step", `limit` = largest_stable_step).
  [[nodiscard]] static Error create(const Scene& scene, const Excitation& excitation,
                                    const SolverSettings& settings, Simulator& out);

  // t = 0, at rest, full contact (sliding or rocking starts at once if Eq 15 or 16 holds).
  void start_at_rest();
  // Impulse I, the initial condition of Eq 34: the ground's velocity jumps by -I, m/s. On a
  // base, u'(0+) = I; on the ground, the block turns about the corner the jump throws it on,
  // with theta'(0+) = -m h I / I_i (angular momentum about that corner).
  void start_with_impulse(double impulse);
  // Starts from an arbitrary mode and state at time 0 (tests and estimators).
  void start_from(const Mode& mode, const State& state);

  // Advances one step (no-op once a terminal phase is reached).
  void step();

  void set_event_sink(EventSink* sink) { sink_ = sink; }

  [[nodiscard]] double time() const { return static_cast<double>(step_count_) * settings_.step; }
  [[nodiscard]] std::int64_t step_count() const { return step_count_; }
  [[nodiscard]] const State& state() const { return y_; }
  [[nodiscard]] const Mode& mode() const { return mode_; }
  [[nodiscard]] const Scene& scene() const { return *scene_; }
  [[nodiscard]] const SolverSettings& settings() const { return settings_; }
  [[nodiscard]] GroundAcceleration ground(double t) const { return excitation_.at(t); }
  // Accelerations of the current mode at the current time and state.
  [[nodiscard]] Accelerations accelerations() const;
  // Number of steps whose events were cut short as chatter (see max_events_per_step).
  [[nodiscard]] std::int64_t chatter_steps() const { return chatter_steps_; }

 private:
  template <Features F>
  friend struct Stepper;

  void emit(const Event& event) {
    if (sink_ != nullptr) sink_->on_event(event);
  }

  const Scene* scene_ = nullptr;
  Excitation excitation_;
  SolverSettings settings_;
  EventSink* sink_ = nullptr;
  void (*step_fn_)(Simulator&) = nullptr;
  void (*enter_fn_)(Simulator&, double) = nullptr;  // starts phases whose onset already holds
  Accelerations (*acc_fn_)(const Simulator&, double, const State&) = nullptr;
  Mode mode_;
  State y_ = State::Zero();
  // Guard values at the end of the last step, valid when it had no event (the next step's
  // start is the same time, state and mode).
  GuardValues guard_cache_{};
  bool guard_cache_valid_ = false;
  std::int64_t step_count_ = 0;
  std::int64_t chatter_steps_ = 0;
};

}  // namespace plinth

// Internal to plinth_core (tests may include it). The one-step methods behind Stepper
// (stepper.h). Each advances the state of one phase's flow over h from (t, y), given the
// derivative k1 at (t, y) (the last point of the previous step or interval, FlowPoint); the same
// map with h < step is the solution on which events are located.
#pragma once

#include "plinth/core/excitation.h"
#include "plinth/core/real.h"
#include "plinth/core/state.h"

namespace plinth::internal {

// A flow as the methods see it: `ground(t)` and `derivative(ground, y)` = dy/dt.
namespace methods {

struct Rk4 {
  static constexpr bool kLocated = true;
  static constexpr int kStages = 4;  // flow evaluations per step, the end point's included

  // `end_ground`, when given, is the ground at t + h (shared with the step's end point).
  template <class Flow>
  [[nodiscard]] static State advance(const Flow& f, Time t, const State& y, const State& k1, Real h,
                                     const GroundAcceleration* end_ground = nullptr) {
    const GroundAcceleration middle = f.ground(t + static_cast<Time>(Real(0.5) * h));
    const State k2 = f.derivative(middle, y + Real(0.5) * h * k1);
    const State k3 = f.derivative(middle, y + Real(0.5) * h * k2);
    const State k4 = f.derivative(
        end_ground != nullptr ? *end_ground : f.ground(t + static_cast<Time>(h)), y + h * k3);
    return y + (h / Real(6)) * (k1 + Real(2) * k2 + Real(2) * k3 + k4);
  }
};

struct Rk4StepEnd : Rk4 {
  static constexpr bool kLocated = false;
};

struct Heun {
  static constexpr bool kLocated = true;
  static constexpr int kStages = 2;

  template <class Flow>
  [[nodiscard]] static State advance(const Flow& f, Time t, const State& y, const State& k1, Real h,
                                     const GroundAcceleration* end_ground = nullptr) {
    const State k2 = f.derivative(
        end_ground != nullptr ? *end_ground : f.ground(t + static_cast<Time>(h)), y + h * k1);
    return y + (Real(0.5) * h) * (k1 + k2);
  }
};

// Velocities first with the accelerations at the start, then positions with the new
// velocities: v1 = v0 + h a(t, q0, v0), q1 = q0 + h v1.
struct SemiImplicitEuler {
  static constexpr bool kLocated = true;
  static constexpr int kStages = 1;

  template <class Flow>
  [[nodiscard]] static State advance(const Flow& /*f*/, Time /*t*/, const State& y, const State& k1,
                                     Real h, const GroundAcceleration* /*end_ground*/ = nullptr) {
    State next;
    next.tail<3>() = y.tail<3>() + h * k1.tail<3>();
    next.head<3>() = y.head<3>() + h * next.tail<3>();
    return next;
  }
};

}  // namespace methods
}  // namespace plinth::internal

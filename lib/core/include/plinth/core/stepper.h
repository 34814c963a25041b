// The one-step methods the solver offers, chosen once in SolverSettings (simulator.h); their
// formulas are internal (internal/steppers.h). docs/accuracy.md measures them.
#pragma once

#include <cstdint>
#include <string_view>

#include "plinth/core/name_table.h"

namespace plinth {

enum class Stepper : std::uint8_t {
  kRk4Located,         // classical Runge-Kutta (4th order), events located inside the step
  kRk4StepEnd,         // the same, guards checked at step ends only, resets applied there
  kHeunLocated,        // Heun's method (explicit trapezoid, 2nd order), events located
  kSemiImplicitEuler,  // semi-implicit (symplectic) Euler (1st order), events located
};

// Every stepper and its name, in the order above.
inline constexpr NameTable<Stepper, 4> kStepperNames{{{
    {Stepper::kRk4Located, "rk4_located"},
    {Stepper::kRk4StepEnd, "rk4_step_end"},
    {Stepper::kHeunLocated, "heun_located"},
    {Stepper::kSemiImplicitEuler, "semi_implicit_euler"},
}}};

inline constexpr auto kAllSteppers = kStepperNames.values();

[[nodiscard]] constexpr const char* stepper_name(Stepper stepper) {
  return kStepperNames.name(stepper);
}
// The stepper named `name`; false, `out` untouched, when there is none.
[[nodiscard]] constexpr bool parse_stepper(std::string_view name, Stepper& out) {
  return kStepperNames.parse(name, out);
}

}  // namespace plinth

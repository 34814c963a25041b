// The largest step each stepper integrates a scene's isolated base with, stably: the bound
// Simulator::create and Estimator::create check the step against (Error "solver.step", `limit`).
#pragma once

#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/stepper.h"

namespace plinth {

// The largest step RK4 integrates the scene's base stably, s: 2.5 / |lambda|max over the base's
// linear dynamics m_eff u'' + c u' + k u = 0, with m_eff = m + m_b (full contact) and m_b alone
// (the block sliding or rocking lets the base move without it, at most). RK4's stability region
// reaches 2.78 on the real axis and 2.83 on the imaginary one. Infinity without a base.
[[nodiscard]] Real largest_stable_step(const Scene& scene);

// The same for `stepper`: RK4 (either way of taking events) as above; Heun and semi-implicit
// Euler, the largest step whose one-step map on those two linear systems grows no mode by more
// than kStableGrowthPerStep per step (Heun's stability region misses the imaginary axis: an
// undamped base grows by (h omega)^4 / 8 per step at any step). 0 for those two in a build
// with rk4_located alone (PLINTH_CORE_RK4_ONLY).
[[nodiscard]] Real largest_stable_step(const Scene& scene, Stepper stepper);
inline constexpr Real kStableGrowthPerStep = Real(1e-8);

}  // namespace plinth

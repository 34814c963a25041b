// The overturning / falling risk of the block, in [0, 1], from the estimator's mode and state.
//
// Each part is a physical margin used up, 0 at rest in full contact, 1 at collapse:
//  - overturning: rocking about a body corner, the rocking energy against the energy that
//    carries C over the pivot, E / E_crit with E = I_p theta'^2 / 2 + m g (h'_p - h) and
//    E_crit = m g (r_p - h) (energy.h). E >= E_crit means C passes over the pivot unless the
//    base's motion takes energy away, so the ratio reaches 1 before the overturn itself.
//  - falling: rocking about the support's corner (the block overhangs the support), the same
//    energy ratio about that corner; sliding towards the support's edge, the distance kinetic
//    friction needs to stop the block, x'^2 / (2 mu_k g), against what is left before C passes
//    the edge; overhanging at rest, the part of C's distance to the edge already used.
//  - base stops: the amplitude the base's free oscillation would reach from (u, u'),
//    sqrt(u^2 + (u'/omega)^2), against u_max, times base_stop_weight (hitting the stops is not
//    a collapse, but it kicks the block: the paper's Fig. 8).
// The total is the worst part. Overturned or fell: 1. Lifted off (outside the model): 0, no
// margin being known; the box reports the state itself (alarm policy, outside_model).
#pragma once

#include "plinth/core/error.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth {

struct RiskSettings {
  // Risk given to the base reaching its stops, dimensionless, in [0, 1].
  Real base_stop_weight = 0.5;
};

[[nodiscard]] Error validate(const RiskSettings& settings);

struct Risk {
  Real overturning = 0.0;  // each in [0, 1]
  Real falling = 0.0;
  Real base_stops = 0.0;
  Real total = 0.0;  // the largest of the three
};

[[nodiscard]] Risk overturning_risk(const Scene& scene, const Mode& mode, const State& y,
                                    const RiskSettings& settings = {});

}  // namespace plinth

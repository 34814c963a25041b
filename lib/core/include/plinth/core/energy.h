// Mechanical energy of the block and base, relative to the ground, J.
#pragma once

#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth {

// T + V in the ground's frame (Eqs 2 and 7): kinetic energy of base and block, spring
// energy k u^2 / 2 and the block's potential energy m g (h'_i - h).
[[nodiscard]] Real mechanical_energy(const Scene& s, const Mode& mode, const State& y);

// Energy of the rocking motion alone: I_i theta'^2 / 2 + m g (h'_i - h).
[[nodiscard]] Real rocking_energy(const Scene& s, const Mode& mode, const State& y);

// Potential energy the block must gain to pass the critical angle of `corner` from rest:
// m g (r_i - h).
[[nodiscard]] Real overturning_energy(const Scene& s, Corner corner);

}  // namespace plinth

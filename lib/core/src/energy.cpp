#include "plinth/core/energy.h"

#include "plinth/core/flows.h"

namespace plinth {

double mechanical_energy(const Scene& s, const Mode& mode, const State& y) {
  const double u_dot = y[kUDot];
  double energy = 0.5 * s.total_mass * u_dot * u_dot + 0.5 * s.stiffness * y[kU] * y[kU];
  if (mode.rocking()) {
    const CornerGeometry& c = s.corner(mode.corner);
    const LeverArms arm = lever_arms(s, c, y[kTheta]);
    // Block kinetic energy (Eq 7) with u_C' = u' - h'_i theta', v_C' = b'_i theta'.
    energy += -s.m * arm.vertical * u_dot * y[kThetaDot];
    energy += rocking_energy(s, mode, y);
  }
  return energy;
}

double rocking_energy(const Scene& s, const Mode& mode, const State& y) {
  if (!mode.rocking()) return 0.0;
  const CornerGeometry& c = s.corner(mode.corner);
  const LeverArms arm = lever_arms(s, c, y[kTheta]);
  return 0.5 * c.inertia * y[kThetaDot] * y[kThetaDot] + s.m * s.g * (arm.vertical - s.h);
}

double overturning_energy(const Scene& s, Corner corner) {
  return s.m * s.g * (s.corner(corner).radius - s.h);
}

}  // namespace plinth

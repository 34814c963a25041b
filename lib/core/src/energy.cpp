#include "plinth/core/energy.h"

#include "plinth/core/internal/flows.h"

namespace plinth {

using internal::contact_kinematics;
using internal::ContactKinematics;
using internal::lever_arms;
using internal::LeverArms;
using internal::Pivot;
using internal::pivot_of;

Real mechanical_energy(const Scene& s, const Mode& mode, const State& y) {
  // Eqs 2 and 7: T = m |v_C|^2 / 2 + m_b u'^2 / 2 + I_C theta'^2 / 2, v_C = J q'
  // (internal/flows.h), V = k u^2 / 2 + m g (h'_i - h).
  const Pivot pivot = pivot_of(s, mode, y);
  const ContactKinematics k = contact_kinematics(s, pivot.geometry, pivot.overhanging, y);
  const Vector3r rates(y[kUDot], y[kXDot], y[kThetaDot]);
  const Vector2r v(k.jx.dot(rates), k.jy.dot(rates));
  const Real kinetic = Real(0.5) * s.m * v.squaredNorm() +
                       Real(0.5) * (s.total_mass - s.m) * y[kUDot] * y[kUDot] +
                       Real(0.5) * s.inertia_c * y[kThetaDot] * y[kThetaDot];
  const LeverArms arm = lever_arms(s, pivot.geometry, y[kTheta]);
  return kinetic + Real(0.5) * s.stiffness * y[kU] * y[kU] + s.m * s.g * (arm.vertical - s.h);
}

Real rocking_energy(const Scene& s, const Mode& mode, const State& y) {
  if (!mode.rocking()) return 0.0;
  const CornerGeometry c = pivot_of(s, mode, y).geometry;
  const LeverArms arm = lever_arms(s, c, y[kTheta]);
  return Real(0.5) * c.inertia * y[kThetaDot] * y[kThetaDot] + s.m * s.g * (arm.vertical - s.h);
}

Real overturning_energy(const Scene& s, Corner corner) {
  return s.m * s.g * (s.corner(corner).radius - s.h);
}

}  // namespace plinth

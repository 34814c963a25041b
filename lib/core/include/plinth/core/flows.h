// Continuous dynamics: the equations of motion of each phase, solved for the accelerations.
#pragma once

#include <Eigen/Dense>
#include <cmath>

#include "plinth/core/excitation.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth {

// Full contact, Eq 1: (m + m_b)(u'' + u_G'') + c u' + k u = 0.
[[nodiscard]] inline Accelerations full_contact_flow(const Scene& s, const State& y,
                                                     GroundAcceleration ag) {
  return {-ag.horizontal - (s.damping * y[kUDot] + s.stiffness * y[kU]) / s.total_mass, 0.0, 0.0};
}

// Position of C relative to the rocking corner after a rotation theta, Eq 9:
// b'_i = b_i cos(theta) - h sin(theta), h'_i = b_i sin(theta) + h cos(theta), with the signed
// offset of CornerGeometry standing for b_1 (corner 1) or -b_2 (corner 2).
struct LeverArms {
  double horizontal = 0.0;  // b'_i, m
  double vertical = 0.0;    // h'_i, m
};

[[nodiscard]] inline LeverArms lever_arms(const Scene& s, const CornerGeometry& c, double theta) {
  const double sin_t = std::sin(theta);
  const double cos_t = std::cos(theta);
  return {c.offset * cos_t - s.h * sin_t, c.offset * sin_t + s.h * cos_t};
}

// Rocking about a corner of the body with the base coupled, Eq 8:
//   (m + m_b)(u'' + u_G'') + c u' + k u - m theta'' h'_i - m theta'^2 b'_i = 0
//   I_i theta'' - m (u'' + u_G'') h'_i + m (g + v_G'') b'_i = 0
// With the base fixed (no base, or held at a stop) u'' = 0 and only the second equation holds.
[[nodiscard]] inline Accelerations rocking_flow(const Scene& s, const CornerGeometry& c,
                                                const State& y, GroundAcceleration ag,
                                                bool base_moves) {
  const LeverArms arm = lever_arms(s, c, y[kTheta]);
  const double gravity_moment = s.m * (s.g + ag.vertical) * arm.horizontal;
  if (!base_moves) {
    return {0.0, 0.0, (s.m * ag.horizontal * arm.vertical - gravity_moment) / c.inertia};
  }
  const double coupling = s.m * arm.vertical;  // m h'_i
  Eigen::Matrix2d mass_matrix;
  mass_matrix << s.total_mass, -coupling, -coupling, c.inertia;
  const Eigen::Vector2d forces(
      -s.total_mass * ag.horizontal - s.damping * y[kUDot] - s.stiffness * y[kU] +
          s.m * y[kThetaDot] * y[kThetaDot] * arm.horizontal,
      coupling * ag.horizontal - gravity_moment);
  const Eigen::Vector2d acc = mass_matrix.inverse() * forces;
  return {acc[0], 0.0, acc[1]};
}

// Horizontal force the stops must exert on the base to hold it still (u' = u'' = 0), N; the
// left-hand side of Eq 1 or Eq 8_1 with u'' = 0. Positive pushes the base towards +u.
[[nodiscard]] inline double base_stop_reaction(const Scene& s, const Mode& mode, const State& y,
                                               GroundAcceleration ag, const Accelerations& acc) {
  double reaction = s.total_mass * ag.horizontal + s.stiffness * y[kU];
  if (mode.rocking()) {
    const LeverArms arm = lever_arms(s, s.corner(mode.corner), y[kTheta]);
    reaction -= s.m * (acc.theta * arm.vertical + y[kThetaDot] * y[kThetaDot] * arm.horizontal);
  }
  return reaction;
}

}  // namespace plinth

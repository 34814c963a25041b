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

// The pivot of rocking about `corner`: the body's own corner, or, when the block overhangs the
// support's edge on that side (mode.overhang), the support's corner, at b_hat_1 = b_1 + y,
// y = x + x_hat (corner 1), or b_hat_2 = b_2 - (x - x_hat) (corner 2) from C's vertical (Eq 16).
struct Pivot {
  CornerGeometry geometry;
  bool overhanging = false;
};

[[nodiscard]] inline Pivot pivot_of(const Scene& s, Corner corner, int overhang, double x) {
  const CornerGeometry& body = s.corner(corner);
  if (overhang == 0 || overhang != (corner == Corner::kLeft ? -1 : 1)) return {body, false};
  const double x_hat = s.params.support.clearance;
  const double b_hat = corner == Corner::kLeft ? s.b1 + (x + x_hat) : s.b2 - (x - x_hat);
  return {corner_geometry(s, b_hat, body.sign), true};
}

[[nodiscard]] inline Pivot pivot_of(const Scene& s, const Mode& mode, const State& y) {
  return pivot_of(s, mode.corner, mode.overhang, y[kX]);
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

// Sliding, Eqs 4-5: m (u'' + u_G'' + x'') + F = 0, (m + m_b)(u'' + u_G'') + m x'' + c u' + k u = 0,
// F = mu_k sign(x') m (g + v_G''). `direction` is sign(x'), fixed for the phase.
[[nodiscard]] inline Accelerations sliding_flow(const Scene& s, int direction, const State& y,
                                                GroundAcceleration ag, bool base_moves) {
  const double friction = s.params.friction.kinetic_coefficient * direction * s.m * (s.g + ag.vertical);
  double base = 0.0;  // u'' + u_G''
  if (base_moves) {
    base = (friction - s.damping * y[kUDot] - s.stiffness * y[kU]) / (s.total_mass - s.m);
  } else {
    base = ag.horizontal;
  }
  return {base_moves ? base - ag.horizontal : 0.0, -friction / s.m - base, 0.0};
}

// Kinematics of C about a pivot, for slide-rocking: C's acceleration is J q'' + bias, q = (u, x,
// theta); `normal` and `tangent` are the contact's directions.
//  - About a body corner (Eqs 10-12) the pivot slides with x on the base.
//  - Overhanging (Eqs 13-14) the pivot is the support's corner, fixed on the base, and the block
//    slides over it along its bottom face, so b_hat = offset changes with x (Coriolis terms).
struct ContactKinematics {
  Eigen::Vector3d jx, jy;   // rows of J, horizontal and vertical
  Eigen::Vector2d bias;     // J' q', m/s2
  Eigen::Vector2d normal;   // unit normal of the contact (up the block's face when overhanging)
  Eigen::Vector2d tangent;  // unit direction of x
};

[[nodiscard]] inline ContactKinematics contact_kinematics(const Scene& s, const CornerGeometry& c,
                                                          bool overhanging, const State& y) {
  const double sin_t = std::sin(y[kTheta]);
  const double cos_t = std::cos(y[kTheta]);
  const double bx = c.offset * cos_t - s.h * sin_t;  // b'_i, Eq 9
  const double hy = c.offset * sin_t + s.h * cos_t;  // h'_i, Eq 9
  const double w = y[kThetaDot];
  ContactKinematics k;
  if (overhanging) {
    const double coriolis = 2.0 * y[kXDot] * w;
    k.jx << 1.0, cos_t, -hy;
    k.jy << 0.0, sin_t, bx;
    k.bias << -coriolis * sin_t - bx * w * w, coriolis * cos_t - hy * w * w;
    k.normal << -sin_t, cos_t;
    k.tangent << cos_t, sin_t;
  } else {
    k.jx << 1.0, 1.0, -hy;
    k.jy << 0.0, 0.0, bx;
    k.bias << -bx * w * w, -hy * w * w;
    k.normal << 0.0, 1.0;
    k.tangent << 1.0, 0.0;
  }
  return k;
}

// Contact force of the base (or the support's corner) on the block, in the contact's frame.
struct ContactForce {
  double tangential = 0.0;  // X_i along x (Eq 19 inside, Eq 20 overhanging), N
  double normal = 0.0;      // Y_i (Eq 12 inside, Eq 14 overhanging), N
};

// The block's equation m (a_C + a_G + g) = R, projected on the contact's directions.
[[nodiscard]] inline ContactForce contact_force(const Scene& s, const ContactKinematics& k,
                                                const Accelerations& acc, GroundAcceleration ag) {
  const Eigen::Vector3d qdd(acc.u, acc.x, acc.theta);
  const Eigen::Vector2d specific(k.jx.dot(qdd) + k.bias.x() + ag.horizontal,
                                 k.jy.dot(qdd) + k.bias.y() + ag.vertical + s.g);
  return {s.m * k.tangent.dot(specific), s.m * k.normal.dot(specific)};
}

// Mass matrix of the slide-rocking Lagrange equations without friction, and with the friction
// coupling of sliding in `direction` (the x row gains mu_k s m n.J, Y being linear in q'').
struct SlideRockingMatrices {
  Eigen::Matrix3d frictionless;
  Eigen::Matrix3d with_friction;
};

[[nodiscard]] inline SlideRockingMatrices slide_rocking_matrices(const Scene& s,
                                                                const ContactKinematics& k,
                                                                int direction) {
  SlideRockingMatrices m;
  m.frictionless = s.m * (k.jx * k.jx.transpose() + k.jy * k.jy.transpose());
  m.frictionless(0, 0) += s.total_mass - s.m;
  m.frictionless(2, 2) += s.inertia_c;
  const double mu = s.params.friction.kinetic_coefficient * direction;
  const Eigen::Vector3d normal_row = k.normal.x() * k.jx + k.normal.y() * k.jy;
  m.with_friction = m.frictionless;
  m.with_friction.row(1) += mu * s.m * normal_row.transpose();
  return m;
}

// Near Painlevé's singularity the normal force and the accelerations grow without bound, beyond
// what any fixed step resolves: below this consistency ratio the contact is taken as stuck.
inline constexpr double kPainleveMargin = 0.05;

// det(with friction) / det(frictionless) of slide-rocking in `direction`. Where it is not
// positive, Coulomb friction makes the equations inconsistent (Painlevé's paradox: the normal
// force of the solution is negative, and it grows without bound as the ratio nears 0): high
// friction with the block well tilted. The contact then sticks (a tangential impact,
// kSlidingInconsistent in guards.h).
[[nodiscard]] inline double sliding_consistency(const Scene& s, const Pivot& pivot,
                                                int direction, const State& y) {
  const ContactKinematics k = contact_kinematics(s, pivot.geometry, pivot.overhanging, y);
  const SlideRockingMatrices m = slide_rocking_matrices(s, k, direction);
  return m.with_friction.determinant() / m.frictionless.determinant();
}

// Slide-rocking, Eqs 10-12 (about a body corner) or Eqs 13-14 (overhanging the support): the
// Lagrange equations M(q) q'' = f with the kinetic friction -mu_k sign(x') Y on x, Y being linear
// in q''. Assembled from the kinematics of C; tests/unit/test_sliding.cpp checks every printed
// equation's residual on the result.
[[nodiscard]] inline Accelerations slide_rocking_flow(const Scene& s, const CornerGeometry& c,
                                                      bool overhanging, int direction,
                                                      const State& y, GroundAcceleration ag,
                                                      bool base_moves) {
  const ContactKinematics k = contact_kinematics(s, c, overhanging, y);
  const Eigen::Vector2d free(k.bias.x() + ag.horizontal, k.bias.y() + ag.vertical + s.g);
  Eigen::Matrix3d mass = slide_rocking_matrices(s, k, direction).with_friction;
  Eigen::Vector3d force = -s.m * (k.jx * free.x() + k.jy * free.y());
  force[0] -= (s.total_mass - s.m) * ag.horizontal + s.damping * y[kUDot] + s.stiffness * y[kU];
  // Friction on x: -mu_k s Y, Y = m n.(J q'' + free); its q'' part is in the mass matrix.
  const double mu = s.params.friction.kinetic_coefficient * direction;
  force[1] -= mu * s.m * k.normal.dot(free);
  if (!base_moves) {
    mass.row(0) << 1.0, 0.0, 0.0;
    mass.col(0) << 1.0, 0.0, 0.0;
    force[0] = 0.0;
  }
  const Eigen::Vector3d qdd = mass.partialPivLu().solve(force);
  return {base_moves ? qdd[0] : 0.0, qdd[1], qdd[2]};
}

// Horizontal force the stops must exert on the base to hold it still (u' = u'' = 0), N: the
// base's own equation, m_b u_G'' + k u + (the block's horizontal force on the base), where the
// block's force is m times its absolute horizontal acceleration. Positive pushes towards +u.
[[nodiscard]] inline double base_stop_reaction(const Scene& s, const Mode& mode, const State& y,
                                               GroundAcceleration ag, const Accelerations& acc) {
  const Pivot pivot = pivot_of(s, mode, y);
  const ContactKinematics k = contact_kinematics(s, pivot.geometry, pivot.overhanging, y);
  const double block = k.jx.dot(Eigen::Vector3d(acc.u, acc.x, acc.theta)) + k.bias.x() + ag.horizontal;
  return (s.total_mass - s.m) * ag.horizontal + s.stiffness * y[kU] + s.m * block;
}

}  // namespace plinth

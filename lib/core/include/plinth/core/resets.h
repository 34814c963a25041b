// Reset maps of the hybrid system: the state just after each event.
#pragma once

#include "plinth/core/flows.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth {

[[nodiscard]] constexpr Corner opposite(Corner c) {
  return c == Corner::kLeft ? Corner::kRight : Corner::kLeft;
}

// theta'+ / theta'- of an impact at theta = 0 that moves the pivot to corner `to` (Eq 23).
//
// Derivation (docs/model.md, "Impact at theta = 0"): the block's angular momentum about the
// new corner and the horizontal momentum of block and base are conserved,
//   J theta'- - m h U-  = I_to theta'+ - m h U+           (Eq 21, corrected)
//   M U- - m h theta'-  = M U+ - m h theta'+              (Eq 22, corrected)
// with U the base velocity, M = m + m_b and J = I_C + m h^2 - m b_1 b_2 = I_1 - 2 m b b_1 =
// I_2 - 2 m b b_2. Hence theta'+/theta'- = (M J - m^2 h^2) / (M I_to - m^2 h^2), which is
// the printed Eq 23 (with r_1 sin(alpha_1) = b_1). The printed Eq 21 has b_2 where 2 b b_1 /
// b_1 = 2b belongs, and Eqs 21-22 carry +m h u' where Eqs 6-8 give -m h u' (the velocity of C
// is u' - h'_1 theta'); with that sign Eq 24 changes sign, see rocking_impact_reset.
// Without a moving base (no base, or base held at a stop) U+ = U- and the ratio is J / I_to;
// for a symmetric homogeneous block it is Housner's 1 - 1.5 sin^2(alpha).
[[nodiscard]] inline double impact_velocity_ratio(const Scene& s, const CornerGeometry& from,
                                                   const CornerGeometry& to, bool base_moves) {
  // J = I_C + m (h^2 + p_from p_to), the pivots' signed offsets p (= I_C + m(h^2 - b1 b2)).
  const double inertia_through = s.inertia_c + s.m * (s.h * s.h + from.offset * to.offset);
  if (!base_moves) return inertia_through / to.inertia;
  const double mh_squared = s.m * s.h * s.m * s.h;
  return (s.total_mass * inertia_through - mh_squared) / (s.total_mass * to.inertia - mh_squared);
}

// The same between the body's own corners.
[[nodiscard]] inline double impact_velocity_ratio(const Scene& s, Corner to, bool base_moves) {
  return impact_velocity_ratio(s, s.corner(opposite(to)), s.corner(to), base_moves);
}

// Eq 22 solved for U+: the base picks up the horizontal momentum the block loses.
// U+ = U- + (m h / (m + m_b)) (theta'+ - theta'-)   (Eq 24 with the sign of Eqs 6-8).
inline void transfer_rocking_momentum(const Scene& s, double theta_dot_before,
                                      double theta_dot_after, State& y) {
  y[kUDot] += s.m * s.h / s.total_mass * (theta_dot_after - theta_dot_before);
}

// Impact at theta = 0: the block goes on rocking about the opposite corner (Eqs 21-24). The
// sliding velocity x' is not changed by the impact (Section 3.3).
inline void rocking_impact_reset(const Scene& s, bool base_moves, Mode& mode, State& y) {
  const Corner to = opposite(mode.corner);
  const double before = y[kThetaDot];
  const double ratio = impact_velocity_ratio(s, pivot_of(s, mode.corner, mode.overhang, y[kX]).geometry,
                                             pivot_of(s, to, mode.overhang, y[kX]).geometry,
                                             base_moves);
  const double after = ratio * before;
  if (base_moves) transfer_rocking_momentum(s, before, after, y);
  y[kTheta] = 0.0;
  y[kThetaDot] = after;
  mode.corner = to;
}

// End of rocking (rest criterion): a perfectly plastic impact, theta' -> 0, with the
// horizontal momentum of Eq 22 kept. Slide-rocking goes on sliding (Section 3.2.3).
inline void rocking_stop_reset(const Scene& s, bool base_moves, Mode& mode, State& y) {
  if (base_moves) transfer_rocking_momentum(s, y[kThetaDot], 0.0, y);
  y[kTheta] = 0.0;
  y[kThetaDot] = 0.0;
  mode.phase = mode.phase == Phase::kSlideRocking ? Phase::kSliding : Phase::kFullContact;
}

// Eq 15 or Eq 18 met: the block starts sliding in `direction` (sign of x').
inline void sliding_onset_reset(int direction, Mode& mode) {
  mode.phase = mode.rocking() ? Phase::kSlideRocking : Phase::kSliding;
  mode.slide_direction = static_cast<std::int8_t>(direction);
}

// x' = 0 and static friction holds: the block sticks (full contact or pure rocking).
inline void sliding_stop_reset(Mode& mode, State& y) {
  y[kXDot] = 0.0;
  mode.phase = mode.rocking() ? Phase::kRocking : Phase::kFullContact;
  mode.slide_direction = 0;
}

// Sliding stop hit, Eqs 30-32: the block's sliding momentum m x'- vanishes, a fraction eta_s of
// it goes to the base: u'+ = u'- + eta_s m x'- / (m + m_b) (Eq 32). Without a moving base the
// ground takes it. With eta_s = 1 horizontal momentum is conserved; with eta_s < 1 the printed
// model removes (1 - eta_s) m x'- of momentum, which can add energy when the base moves
// against the slide (docs/model.md, "Sliding stops").
inline void sliding_stop_hit_reset(const Scene& s, int side, bool base_moves, Mode& mode,
                                   State& y) {
  if (base_moves) {
    y[kUDot] += s.params.sliding_stops.restitution * s.m / s.total_mass * y[kXDot];
  }
  y[kX] = side * s.params.support.clearance;
  sliding_stop_reset(mode, y);
}

// Rocking onset (Eq 16, or Eq 17 while sliding): the block starts turning about `corner` from
// theta = 0; a sliding block goes on sliding (slide-rocking).
inline void rocking_onset_reset(Corner corner, Mode& mode, State& y) {
  mode.phase = mode.sliding() ? Phase::kSlideRocking : Phase::kRocking;
  mode.corner = corner;
  y[kTheta] = 0.0;
  y[kThetaDot] = 0.0;
}

// Velocity change of an impulse on the base alone, per unit change of u', through the phase's
// mass matrix (Eqs 1, 4, 8, 10, 13 without friction, whose force stays finite): the block keeps
// what the constraints of its phase let it keep.
[[nodiscard]] inline Eigen::Vector3d base_impulse_response(const Scene& s, const Mode& mode,
                                                          const State& y) {
  const Pivot pivot = pivot_of(s, mode, y);
  const ContactKinematics k = contact_kinematics(s, pivot.geometry, pivot.overhanging, y);
  Eigen::Matrix3d mass = s.m * (k.jx * k.jx.transpose() + k.jy * k.jy.transpose());
  mass(0, 0) += s.total_mass - s.m;
  mass(2, 2) += s.inertia_c;
  // Degrees of freedom the phase holds fixed: x unless sliding, theta unless rocking.
  for (const Eigen::Index i : {Eigen::Index{1}, Eigen::Index{2}}) {
    const bool free = i == 1 ? mode.sliding() : mode.rocking();
    if (!free) {
      mass.row(i).setZero();
      mass.col(i).setZero();
      mass(i, i) = 1.0;
    }
  }
  const Eigen::Vector3d response = mass.partialPivLu().solve(Eigen::Vector3d::UnitX());
  return response / response[0];
}

// Painlevé's paradox (flows.h, sliding_consistency): the sliding contact sticks at once. An
// impulse along x alone brings x' to 0 through the frictionless mass matrix of the phase
// (a plastic tangential impact: it never adds energy); the block goes on rocking.
inline void tangential_impact_reset(const Scene& s, Mode& mode, State& y) {
  const Pivot pivot = pivot_of(s, mode, y);
  const ContactKinematics k = contact_kinematics(s, pivot.geometry, pivot.overhanging, y);
  Eigen::Matrix3d mass = slide_rocking_matrices(s, k, 0).frictionless;
  if (mode.held_stop != 0 || !s.has_base()) {  // u is held: only x and theta respond
    mass.row(0) << 1.0, 0.0, 0.0;
    mass.col(0) << 1.0, 0.0, 0.0;
  }
  const Eigen::Vector3d response = mass.partialPivLu().solve(Eigen::Vector3d::UnitY());
  const double impulse = -y[kXDot] / response[1];
  y[kUDot] += response[0] * impulse;
  y[kThetaDot] += response[2] * impulse;
  y[kXDot] = 0.0;
  mode.phase = Phase::kRocking;
  mode.slide_direction = 0;
}

inline void apply_base_impulse(const Scene& s, const Mode& mode, double u_dot_after, State& y) {
  const Eigen::Vector3d response = base_impulse_response(s, mode, y);
  const double change = u_dot_after - y[kUDot];
  y[kXDot] += response[1] * change;
  y[kThetaDot] += response[2] * change;
  y[kUDot] = u_dot_after;
}

// Base hits a stop, Eq 29: u'+ = -eta_i u'-.
// The printed Eq 29 says nothing of theta' (or x'). Keeping theta' unchanged while u' reverses
// can create energy (the kinetic energy has the cross term -m h'_i u' theta'). The stop's
// impulse P acts on u alone; through the mass matrix of Eq 8 it changes
//   delta u' = I_i P / D,  delta theta' = m h'_i P / D   =>  delta theta' = (m h'_i / I_i) delta u'
// which is Eq 29 for u' and never adds energy for eta_i <= 1 (tests/unit/test_isolated.cpp).
// While sliding, the block's absolute velocity is kept (x' changes by -delta u').
inline void base_stop_reset(const Scene& s, int side, const Mode& mode, State& y) {
  apply_base_impulse(s, mode, -s.params.base_stops.restitution * y[kUDot], y);
  y[kU] = side * s.params.base_stops.max_displacement;
}

// The base's rebounds died out against stop `side`: it rests there (u' = 0) while the stop
// pushes (guard kBaseStopRelease). The same impulse rule as base_stop_reset with eta_i = 0.
inline void base_stop_hold_reset(const Scene& s, int side, Mode& mode, State& y) {
  apply_base_impulse(s, mode, 0.0, y);
  y[kU] = side * s.params.base_stops.max_displacement;
  mode.held_stop = static_cast<std::int8_t>(side);
}

}  // namespace plinth

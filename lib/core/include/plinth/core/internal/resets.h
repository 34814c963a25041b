// Internal to plinth_core (tests may include it). Reset maps of the hybrid system: the state
// just after each event.
#pragma once

#include <cmath>

#include "plinth/core/internal/flows.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth::internal {

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
[[nodiscard]] inline Real impact_velocity_ratio(const Scene& s, const CornerGeometry& from,
                                                const CornerGeometry& to, bool base_moves) {
  // J = I_C + m (h^2 + p_from p_to), the pivots' signed offsets p (= I_C + m(h^2 - b1 b2)).
  const Real inertia_through = s.inertia_c + s.m * (s.h * s.h + from.offset * to.offset);
  if (!base_moves) return inertia_through / to.inertia;
  const Real mh_squared = s.m * s.h * s.m * s.h;
  return (s.total_mass * inertia_through - mh_squared) / (s.total_mass * to.inertia - mh_squared);
}

// The same between the body's own corners.
[[nodiscard]] inline Real impact_velocity_ratio(const Scene& s, Corner to, bool base_moves) {
  return impact_velocity_ratio(s, s.corner(opposite(to)), s.corner(to), base_moves);
}

// Eq 22 solved for U+: the base picks up the horizontal momentum the block loses.
// U+ = U- + (m h / (m + m_b)) (theta'+ - theta'-)   (Eq 24 with the sign of Eqs 6-8).
inline void transfer_rocking_momentum(const Scene& s, Real theta_dot_before, Real theta_dot_after,
                                      State& y) {
  y[kUDot] += s.m * s.h / s.total_mass * (theta_dot_after - theta_dot_before);
}

// Impact at theta = 0 of a block that does not slide (Eqs 21-24): it goes on rocking about the
// opposite corner. A scene that can slide uses coulomb_impact_reset, which reduces to this when
// friction holds the new corner.
inline void rocking_impact_reset(const Scene& s, bool base_moves, Mode& mode, State& y) {
  const Corner to = opposite(mode.corner);
  const Real before = y[kThetaDot];
  const Real ratio =
      impact_velocity_ratio(s, pivot_of(s, mode.corner, mode.overhang, y[kX]).geometry,
                            pivot_of(s, to, mode.overhang, y[kX]).geometry, base_moves);
  const Real after = ratio * before;
  if (base_moves) transfer_rocking_momentum(s, before, after, y);
  y[kTheta] = 0.0;
  y[kThetaDot] = after;
  mode.corner = to;
}

// ---------------------------------------------------------------------------------------------
// Impulses along one coordinate
//
// The kinetic energy is T = q'^T M q' / 2 with q = (u, x, theta) and M the frictionless mass
// matrix of the mode (flows.h, slide_rocking_matrices). A stop, or a contact that sticks, acts
// through an impulse P along one coordinate i alone: M dq' = P e_i. Setting q'_i+ = -eta q'_i-
// with 0 <= eta <= 1 changes the energy by
//   dT = -(1 - eta^2) q'_i-^2 / (2 (M^-1)_ii) <= 0,
// and the generalized momenta of the other coordinates (the horizontal momentum p_u when
// i != u) are kept. Every velocity jump below except the impact at theta = 0 is one of these.

// M with the coordinates the mode holds fixed replaced by identity rows and columns: u when the
// base cannot move (no base, or held at a stop), x unless sliding, theta unless rocking.
[[nodiscard]] inline Matrix3r constrained_mass_matrix(const Scene& s, const Mode& mode,
                                                      const State& y, bool base_moves) {
  const Pivot pivot = pivot_of(s, mode, y);
  const ContactKinematics k = contact_kinematics(s, pivot.geometry, pivot.overhanging, y);
  Matrix3r mass = slide_rocking_matrices(s, k, 0).frictionless;
  const bool free[3] = {base_moves, mode.sliding(), mode.rocking()};
  for (Eigen::Index i = 0; i < 3; ++i) {
    if (free[i]) continue;
    mass.row(i).setZero();
    mass.col(i).setZero();
    mass(i, i) = 1.0;
  }
  return mass;
}

// An impulse along coordinate `i` (kUDot, kXDot or kThetaDot) that sets its velocity to
// `velocity_after`; the mode's other free coordinates respond through M.
inline void coordinate_impulse_reset(const Scene& s, const Mode& mode, bool base_moves,
                                     StateIndex i, Real velocity_after, State& y) {
  const Eigen::Index coordinate = i - kUDot;
  const Vector3r response = constrained_mass_matrix(s, mode, y, base_moves)
                                .partialPivLu()
                                .solve(Vector3r::Unit(coordinate));
  const Real impulse = (velocity_after - y[i]) / response[coordinate];
  y.tail<3>() += impulse * response;
  y[i] = velocity_after;  // exactly, whatever the rounding
}

// End of rocking (rest criterion): a perfectly plastic impulse on theta, theta' -> 0, the
// horizontal momentum kept (Eq 22; in pure rocking this is Eq 24 with theta'+ = 0).
// Slide-rocking goes on sliding (Section 3.2.3).
inline void rocking_stop_reset(const Scene& s, bool base_moves, Mode& mode, State& y) {
  coordinate_impulse_reset(s, mode, base_moves, kThetaDot, Real(0), y);
  y[kTheta] = 0.0;
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

// Sliding stop hit (Eqs 30-32), as an impact between block and base with restitution eta_s on
// the sliding velocity: x'+ = -eta_s x'-, through the phase's mass matrix (the base, and the
// rocking of a slide-rocking block, respond).
//
// The printed Eqs 31-32 stop the block (x'+ = 0) and give the base u'+ = u'- + eta_s m x'-/(m+m_b):
// with eta_s < 1 the momentum (1 - eta_s) m x'- goes nowhere (the stops are on the base, which
// only the visco-elastic device holds, and it carries no impulse), and energy can grow when the
// base moves against the slide (tests/unit/core/test_sliding.cpp, SlidingStops). Here the horizontal
// momentum is kept for every eta_s and energy never grows; eta_s keeps the meaning it has for
// the base stops (Eq 29). At eta_s = 0 this is the printed Eq 32 with eta_s = 1 exactly.
// Afterwards the block slides away from the stop (or, if x'+ = 0, the caller makes it stick).
inline void sliding_stop_hit_reset(const Scene& s, int side, bool base_moves, Mode& mode,
                                   State& y) {
  coordinate_impulse_reset(s, mode, base_moves, kXDot,
                           -s.params.sliding_stops.restitution * y[kXDot], y);
  y[kX] = static_cast<Real>(side) * s.params.support.clearance;
  mode.slide_direction = static_cast<std::int8_t>(-side);
}

// Rocking onset (Eq 16, or Eq 17 while sliding): the block starts turning about `corner` from
// theta = 0; a sliding block goes on sliding (slide-rocking).
inline void rocking_onset_reset(Corner corner, Mode& mode, State& y) {
  mode.phase = mode.sliding() ? Phase::kSlideRocking : Phase::kRocking;
  mode.corner = corner;
  y[kTheta] = 0.0;
  y[kThetaDot] = 0.0;
}

// Painlevé's paradox (flows.h, sliding_consistency): the sliding contact sticks at once, a
// plastic impulse on x (a tangential impact: it never adds energy); the block goes on rocking.
inline void tangential_impact_reset(const Scene& s, Mode& mode, State& y) {
  coordinate_impulse_reset(s, mode, mode.held_stop == 0 && s.has_base(), kXDot, Real(0), y);
  mode.phase = Phase::kRocking;
  mode.slide_direction = 0;
}

// Base hits a stop, Eq 29: u'+ = -eta_i u'-.
// The printed Eq 29 says nothing of theta' (or x'). Keeping theta' unchanged while u' reverses
// can create energy (the kinetic energy has the cross term -m h'_i u' theta'). The stop's
// impulse acts on u alone; through the mass matrix of Eq 8 it changes
//   delta u' = I_i P / D,  delta theta' = m h'_i P / D   =>  delta theta' = (m h'_i / I_i) delta u'
// which is Eq 29 for u' and never adds energy for eta_i <= 1 (tests/unit/core/test_isolated.cpp).
// While sliding, the block's absolute velocity is kept (x' changes by -delta u').
inline void base_stop_reset(const Scene& s, int side, const Mode& mode, State& y) {
  coordinate_impulse_reset(s, mode, true, kUDot, -s.params.base_stops.restitution * y[kUDot], y);
  y[kU] = static_cast<Real>(side) * s.params.base_stops.max_displacement;
}

// The base's rebounds died out against stop `side`: it rests there (u' = 0) while the stop
// pushes (guard kBaseStopRelease). The same impulse rule as base_stop_reset with eta_i = 0.
inline void base_stop_hold_reset(const Scene& s, int side, Mode& mode, State& y) {
  coordinate_impulse_reset(s, mode, true, kUDot, Real(0), y);
  y[kU] = static_cast<Real>(side) * s.params.base_stops.max_displacement;
  mode.held_stop = static_cast<std::int8_t>(side);
}

// ---------------------------------------------------------------------------------------------
// Impact at theta = 0 with friction (Section 3.3, made consistent)
//
// The paper keeps the sliding velocity through the impact (Eqs 21-22 with x' unchanged). That
// can add energy: Eq 21's angular momentum leaves out what x' contributes about the new corner
// (tests/unit/core/test_sliding.cpp, SlideRocking). Here the impact is a rigid-body impact at the new
// corner with a plastic normal impulse Pn and a Coulomb tangential impulse Pt, the old corner
// lifting off (as in Housner's impact):
//   M_new q'+ = G_new^T M_free v-  +  e_x Pt,         Pn = m n.(v_C+ - v_C-),
// with v- = (v_C, omega, U) the free velocities before the impact, G_new the map from the new
// phase's coordinates to them (C's Jacobian about the new pivot, flows.h contact_kinematics),
// and M_new = G_new^T M_free G_new the new phase's frictionless mass matrix (the normal impulse
// does no work in the new coordinates; Pt acts on x, the slip of the new corner on the base).
//  - Stick (x'+ = 0) when |Pt| <= mu_s Pn: rocking about the new corner. With x'- = 0 this is
//    Eqs 21-24 exactly (test: CoulombImpact.WithoutSlidingIsEqs21To24).
//  - Otherwise slide with Pt = -d mu_k Pn, d the sliding direction: slide-rocking.
// Energy never grows (plastic normal impact, friction opposing the slip; tested on random
// states) and the horizontal momentum is kept when the base moves.
struct CoulombImpact {
  Real normal_impulse = 0.0;      // Pn, N s
  Real tangential_impulse = 0.0;  // Pt along x, N s
  bool sticks = true;
};

inline CoulombImpact coulomb_impact_reset(const Scene& s, bool base_moves, Mode& mode, State& y) {
  State at_impact = y;
  at_impact[kTheta] = 0.0;
  const Pivot old_pivot = pivot_of(s, mode, at_impact);
  const Corner to = opposite(mode.corner);
  const Pivot new_pivot = pivot_of(s, to, mode.overhang, y[kX]);
  const ContactKinematics before =
      contact_kinematics(s, old_pivot.geometry, old_pivot.overhanging, at_impact);
  const ContactKinematics after =
      contact_kinematics(s, new_pivot.geometry, new_pivot.overhanging, at_impact);
  const Vector3r q_dot_before = y.tail<3>();
  const Vector2r v_c_before(before.jx.dot(q_dot_before), before.jy.dot(q_dot_before));

  // G_new^T M_free v-: the new coordinates' generalized momenta before the impact.
  Vector3r momentum = s.m * (after.jx * v_c_before.x() + after.jy * v_c_before.y());
  momentum[0] += (s.total_mass - s.m) * y[kUDot];
  momentum[2] += s.inertia_c * y[kThetaDot];
  const Matrix3r mass = slide_rocking_matrices(s, after, 0).frictionless;
  const auto hold_base = [&](Matrix3r& a, Vector3r& b) {
    if (base_moves) return;
    a.row(0) << Real(1), Real(0), Real(0);
    b[0] = y[kUDot];
  };
  const auto normal_impulse = [&](const Vector3r& q_dot) {
    const Vector2r v_c(after.jx.dot(q_dot), after.jy.dot(q_dot));
    return s.m * after.normal.dot(v_c - v_c_before);
  };

  // Stick: unknowns (u'+, Pt, theta'+) with x'+ = 0.
  Matrix3r stick = mass;
  stick.col(1) = -Vector3r::UnitY();
  Vector3r stick_rhs = momentum;
  hold_base(stick, stick_rhs);
  const Vector3r z = stick.partialPivLu().solve(stick_rhs);
  const Vector3r q_stick(z[0], Real(0), z[2]);
  CoulombImpact result{normal_impulse(q_stick), z[1], true};
  Vector3r q_after = q_stick;

  if (std::fabs(result.tangential_impulse) >
      s.params.friction.static_coefficient * result.normal_impulse) {
    // Slide against the impulse sticking would need: Pt = -d mu_k Pn (the with-friction matrix
    // carries Pn's dependence on q'+, like Eqs 10-12 carry Y's on q'').
    const int direction = result.tangential_impulse > Real(0) ? -1 : 1;
    Matrix3r slide = slide_rocking_matrices(s, after, direction).with_friction;
    const Real mu = s.params.friction.kinetic_coefficient * static_cast<Real>(direction);
    Vector3r slide_rhs = momentum;
    slide_rhs[1] += mu * s.m * after.normal.dot(v_c_before);
    hold_base(slide, slide_rhs);
    const Vector3r q_slide = slide.partialPivLu().solve(slide_rhs);
    if (q_slide[1] * static_cast<Real>(direction) >
        Real(0)) {  // otherwise the slip stops within the impact: stick
      q_after = q_slide;
      result = {normal_impulse(q_slide),
                -static_cast<Real>(direction) * s.params.friction.kinetic_coefficient *
                    normal_impulse(q_slide),
                false};
      mode.slide_direction = static_cast<std::int8_t>(direction);
    }
  }
  if (result.sticks) mode.slide_direction = 0;
  mode.phase = result.sticks ? Phase::kRocking : Phase::kSlideRocking;
  mode.corner = to;
  y[kTheta] = 0.0;
  y.tail<3>() = q_after;
  if (!base_moves) y[kUDot] = q_dot_before[0];
  return result;
}

}  // namespace plinth::internal

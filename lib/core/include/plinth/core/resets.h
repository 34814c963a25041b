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
[[nodiscard]] inline double impact_velocity_ratio(const Scene& s, Corner to, bool base_moves) {
  const double inertia_to = s.corner(to).inertia;
  if (!base_moves) return s.impact_inertia / inertia_to;
  const double mh_squared = s.m * s.h * s.m * s.h;
  return (s.total_mass * s.impact_inertia - mh_squared) /
         (s.total_mass * inertia_to - mh_squared);
}

// Eq 22 solved for U+: the base picks up the horizontal momentum the block loses.
// U+ = U- + (m h / (m + m_b)) (theta'+ - theta'-)   (Eq 24 with the sign of Eqs 6-8).
inline void transfer_rocking_momentum(const Scene& s, double theta_dot_before,
                                      double theta_dot_after, State& y) {
  y[kUDot] += s.m * s.h / s.total_mass * (theta_dot_after - theta_dot_before);
}

// Impact at theta = 0: the block goes on rocking about the opposite corner (Eqs 21-24).
inline void rocking_impact_reset(const Scene& s, bool base_moves, Mode& mode, State& y) {
  const Corner to = opposite(mode.corner);
  const double before = y[kThetaDot];
  const double after = impact_velocity_ratio(s, to, base_moves) * before;
  if (base_moves) transfer_rocking_momentum(s, before, after, y);
  y[kTheta] = 0.0;
  y[kThetaDot] = after;
  mode.corner = to;
}

// End of rocking (rest criterion): a perfectly plastic impact, theta' -> 0, with the
// horizontal momentum of Eq 22 kept.
inline void rocking_stop_reset(const Scene& s, bool base_moves, Mode& mode, State& y) {
  if (base_moves) transfer_rocking_momentum(s, y[kThetaDot], 0.0, y);
  y[kTheta] = 0.0;
  y[kThetaDot] = 0.0;
  mode.phase = Phase::kFullContact;
}

// Rocking onset (Eq 16 met): the block starts turning about `corner` from theta = 0.
inline void rocking_onset_reset(Corner corner, Mode& mode, State& y) {
  mode.phase = Phase::kRocking;
  mode.corner = corner;
  y[kTheta] = 0.0;
  y[kThetaDot] = 0.0;
}

// Base hits a stop, Eq 29: u'+ = -eta_i u'-.
// The printed Eq 29 says nothing of theta'. Keeping theta' unchanged while u' reverses can
// create energy (the kinetic energy has the cross term -m h'_i u' theta'). The stop's impulse
// P acts on u alone; through the mass matrix of Eq 8 it changes
//   delta u' = I_i P / D,  delta theta' = m h'_i P / D   =>  delta theta' = (m h'_i / I_i) delta u'
// which is Eq 29 for u' and never adds energy for eta_i <= 1 (tests/unit/test_isolated.cpp).
inline void base_stop_reset(const Scene& s, int side, const Mode& mode, State& y) {
  const double before = y[kUDot];
  const double after = -s.params.base_stops.restitution * before;
  if (mode.rocking()) {
    const CornerGeometry& c = s.corner(mode.corner);
    const LeverArms arm = lever_arms(s, c, y[kTheta]);
    y[kThetaDot] += s.m * arm.vertical / c.inertia * (after - before);
  }
  y[kU] = side * s.params.base_stops.max_displacement;
  y[kUDot] = after;
}

// The base's rebounds died out against stop `side`: it rests there (u' = 0) while the stop
// pushes (guard kBaseStopRelease). The same impulse rule as base_stop_reset with eta_i = 0.
inline void base_stop_hold_reset(const Scene& s, int side, Mode& mode, State& y) {
  if (mode.rocking()) {
    const CornerGeometry& c = s.corner(mode.corner);
    const LeverArms arm = lever_arms(s, c, y[kTheta]);
    y[kThetaDot] -= s.m * arm.vertical / c.inertia * y[kUDot];
  }
  y[kU] = side * s.params.base_stops.max_displacement;
  y[kUDot] = 0.0;
  mode.held_stop = static_cast<std::int8_t>(side);
}

}  // namespace plinth

// Internal to plinth_core (tests may include it). Continuous dynamics: the equations of motion
// of each phase, solved for the accelerations.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <cstddef>

#include "plinth/core/excitation.h"
#include "plinth/core/internal/bounded_trig.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth::internal {

// Full contact, Eq 1: (m + m_b)(u'' + u_G'') + c u' + k u = 0.
[[nodiscard]] inline Real full_contact_base_acceleration(const Scene& s, Real u, Real u_dot,
                                                         Real ground_horizontal) {
  return -ground_horizontal - (s.damping * u_dot + s.stiffness * u) / s.total_mass;
}

[[nodiscard]] inline Accelerations full_contact_flow(const Scene& s, const State& y,
                                                     GroundAcceleration ag) {
  return {full_contact_base_acceleration(s, y[kU], y[kUDot], ag.horizontal), Real(0), Real(0)};
}

// Position of C relative to the rocking corner after a rotation theta, Eq 9:
// b'_i = b_i cos(theta) - h sin(theta), h'_i = b_i sin(theta) + h cos(theta), with the signed
// offset of CornerGeometry standing for b_1 (corner 1) or -b_2 (corner 2).
struct LeverArms {
  Real horizontal = 0.0;  // b'_i, m
  Real vertical = 0.0;    // h'_i, m
};

// sin and cos of the block's rotation theta, computed once per point and shared by the flow
// and the guards evaluated there.
struct SinCos {
  Real sin = 0.0;
  Real cos = 1.0;
};

// sin and cos from libm in a double build; in a float build from bounded_sin_cos
// (bounded_trig.h: |x| <= 8192 rad, without newlib's reduction of arbitrary arguments).
[[nodiscard]] inline SinCos real_sin_cos(Real x) {
  if constexpr (real_tolerance::kSingle) {
    const FloatSinCos t = bounded_sin_cos(static_cast<float>(x));
    return {static_cast<Real>(t.sin), static_cast<Real>(t.cos)};
  } else {
    return {std::sin(x), std::cos(x)};
  }
}

namespace trig_table {

// sin and cos of k / kSteps for |k| <= kLast: |theta| up to 1.64 rad, past pi / 2 (no block turns
// further about a corner). Built at compile time in long double (Taylor series to 1e-30), so
// each entry is the Real nearest the true value but for rare ties (within one rounding).
inline constexpr int kSteps = 64;  // entries per radian
inline constexpr int kLast = 105;
inline constexpr Real kRange = static_cast<Real>(kLast) / kSteps;  // rad

struct Table {
  Real sin[2 * kLast + 1];
  Real cos[2 * kLast + 1];
};

constexpr Table make() {
  Table t{};
  for (int k = -kLast; k <= kLast; ++k) {
    const long double x = static_cast<long double>(k) / kSteps;
    long double term = x;  // x^n / n!, n odd then even
    long double sin_x = 0.0L;
    long double cos_x = 1.0L;
    for (int n = 1; n < 40; ++n) {
      if (n % 2 == 1) {
        sin_x += term;
      } else {
        cos_x += term;
      }
      term = term * x / static_cast<long double>(n + 1) * (n % 2 == 1 ? -1.0L : 1.0L);
    }
    t.sin[k + kLast] = static_cast<Real>(sin_x);
    t.cos[k + kLast] = static_cast<Real>(cos_x);
  }
  return t;
}

inline constexpr Table kTable = make();

}  // namespace trig_table

// sin d and cos d - 1 for |d| <= kStageAngle by two terms each (the first left out, d^5 / 5!
// and d^6 / 6!, are below 1e-19): one step of a rocking block at the default step, rad.
inline constexpr Real kStageAngle = 0.000244140625;  // 2^-12
// The same for |d| <= kVeryNearAngle by three terms (d^7 / 7! and d^8 / 8! below 1e-19), rad.
inline constexpr Real kVeryNearAngle = 0.0078125;  // 2^-7
// The same to kNearAngle with two terms more (d^11 / 11! and d^12 / 12! below 1e-20), rad.
inline constexpr Real kNearAngle = 0.0625;

// sin and cos of theta0 + d from those of theta0 (angle addition), to about one rounding.
[[nodiscard]] inline SinCos turned_by(const SinCos& at0, Real d) {
  const Real d2 = d * d;
  Real sin_d = 0.0;
  Real cos_d_minus_1 = 0.0;
  if (std::fabs(d) <= kStageAngle) {
    sin_d = d + d * d2 * (-Real(1) / Real(6));
    cos_d_minus_1 = d2 * (-Real(0.5) + d2 * (Real(1) / Real(24)));
  } else if (std::fabs(d) <= kVeryNearAngle) {
    sin_d = d + d * d2 * (-Real(1) / Real(6) + d2 * (Real(1) / Real(120)));
    cos_d_minus_1 = d2 * (-Real(0.5) + d2 * (Real(1) / Real(24) + d2 * (-Real(1) / Real(720))));
  } else {
    sin_d = d + d * d2 *
                    (-Real(1) / Real(6) +
                     d2 * (Real(1) / Real(120) +
                           d2 * (-Real(1) / Real(5040) + d2 * (Real(1) / Real(362880)))));
    cos_d_minus_1 =
        d2 *
        (-Real(0.5) + d2 * (Real(1) / Real(24) +
                            d2 * (-Real(1) / Real(720) +
                                  d2 * (Real(1) / Real(40320) + d2 * (-Real(1) / Real(3628800))))));
  }
  return {at0.sin + (at0.cos * sin_d + at0.sin * cos_d_minus_1),
          at0.cos + (at0.cos * cos_d_minus_1 - at0.sin * sin_d)};
}

// sin and cos of theta to about one rounding, without libm for |theta| <= trig_table::kRange:
// theta = k / 64 + d with |d| <= 1/128, the table's entry turned by d. k is rounded by adding
// and subtracting 1.5 2^52 (no conversion to an integer on the way to d: this is on the
// critical path of every step). A float build takes bounded_sin_cos (real_sin_cos): its own
// reduction is as short, and the table, whose rounding would need 1.5 2^23 in float, is 1.7 KB
// of a microcontroller's flash.
[[nodiscard]] inline SinCos sin_cos_of_turned(Real theta) {
  if constexpr (real_tolerance::kSingle) return real_sin_cos(theta);
  if (!(std::fabs(theta) <= trig_table::kRange)) return real_sin_cos(theta);
  constexpr Real kRoundingShift = 6755399441055744.0;  // 1.5 2^52
  const Real shifted = theta * trig_table::kSteps + kRoundingShift;
  const Real k = shifted - kRoundingShift;
  const auto i = static_cast<std::size_t>(static_cast<int>(k) + trig_table::kLast);
  return turned_by({trig_table::kTable.sin[i], trig_table::kTable.cos[i]},
                   theta - k * (Real(1) / trig_table::kSteps));
}

// The same, theta = 0 (full contact and sliding) in a test small enough to be inlined.
[[nodiscard]] inline SinCos sin_cos(Real theta) {
  return theta == Real(0) ? SinCos{} : sin_cos_of_turned(theta);
}

// sin and cos of theta from those of a nearby angle theta0 (a Runge-Kutta stage from the step's
// start point): a shorter chain of dependent operations than sin_cos, which matters as the
// stages follow one another. Within kStageAngle, the Taylor series about theta0 to d^4 (the d^5
// term is below 1e-19) in Estrin's form: (s + c d) + d^2 ((-s/2 - c d/6) + d^2 s/24) for sin.
// sin_cos beyond kNearAngle.
[[nodiscard]] inline SinCos sin_cos_near(Real theta, Real theta0, const SinCos& at0) {
  const Real d = theta - theta0;
  if (std::fabs(d) <= kStageAngle) {
    const Real d2 = d * d;
    const Real s = at0.sin;
    const Real c = at0.cos;
    return {(s + c * d) + d2 * ((-Real(0.5) * s - (Real(1) / Real(6)) * c * d) +
                                d2 * ((Real(1) / Real(24)) * s)),
            (c - s * d) + d2 * ((-Real(0.5) * c + (Real(1) / Real(6)) * s * d) +
                                d2 * ((Real(1) / Real(24)) * c))};
  }
  if (!(std::fabs(d) <= kNearAngle)) return sin_cos(theta);
  return turned_by(at0, d);
}

[[nodiscard]] inline LeverArms lever_arms(const Scene& s, Real offset, const SinCos& t) {
  return {offset * t.cos - s.h * t.sin, offset * t.sin + s.h * t.cos};
}

// The lever arms at theta from those at a nearby theta0, without sin and cos on the way: (b', h')
// is (offset, h) turned by theta, so (Eq 9) h'(theta0 + d) = h'0 cos d + b'0 sin d and
// b'(theta0 + d) = b'0 cos d - h'0 sin d, the same series as sin_cos_near (h' in the place of
// sin, b' of cos). Within kStageAngle only (the caller falls back to lever_arms of sin_cos).
[[nodiscard]] inline LeverArms lever_arms_turned(const LeverArms& at0, Real d) {
  const Real d2 = d * d;
  const Real b = at0.horizontal;
  const Real v = at0.vertical;
  return {(b - v * d) + d2 * ((-Real(0.5) * b + (Real(1) / Real(6)) * v * d) +
                              d2 * ((Real(1) / Real(24)) * b)),
          (v + b * d) + d2 * ((-Real(0.5) * v - (Real(1) / Real(6)) * b * d) +
                              d2 * ((Real(1) / Real(24)) * v))};
}

[[nodiscard]] inline LeverArms lever_arms(const Scene& s, const CornerGeometry& c, Real theta) {
  return lever_arms(s, c.offset, real_sin_cos(theta));
}

// The pivot of rocking about `corner`: the body's own corner, or, when the block overhangs the
// support's edge on that side (mode.overhang), the support's corner, at b_hat_1 = b_1 + y,
// y = x + x_hat (corner 1), or b_hat_2 = b_2 - (x - x_hat) (corner 2) from C's vertical (Eq 16).
struct Pivot {
  CornerGeometry geometry;
  bool overhanging = false;
};

// Only the pivot's distance b_hat_i from C's vertical and its side: what the flows and the
// onset guards need, without the radius, inertia and critical angle (hypot, atan2) of Pivot.
struct PivotDistance {
  Real distance = 0.0;  // b_i or b_hat_i, m
  Real sign = 0.0;      // +1 corner 1, -1 corner 2
  bool overhanging = false;

  [[nodiscard]] Real offset() const { return sign * distance; }  // CornerGeometry::offset
};

[[nodiscard]] inline PivotDistance pivot_distance(const Scene& s, Corner corner, int overhang,
                                                  Real x) {
  const bool left = corner == Corner::kLeft;
  if (overhang == 0 || overhang != (left ? -1 : 1)) {
    return {left ? s.b1 : s.b2, left ? Real(1) : -Real(1), false};
  }
  const Real x_hat = s.params.support.clearance;
  return {left ? s.b1 + (x + x_hat) : s.b2 - (x - x_hat), left ? Real(1) : -Real(1), true};
}

[[nodiscard]] inline Pivot pivot_of(const Scene& s, Corner corner, int overhang, Real x) {
  const PivotDistance d = pivot_distance(s, corner, overhang, x);
  if (!d.overhanging) return {s.corner(corner), false};
  return {corner_geometry(s, d.distance, d.sign), true};
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
                                                bool base_moves, const LeverArms& arm) {
  const Real gravity_moment = s.m * (s.g + ag.vertical) * arm.horizontal;
  if (!base_moves) {
    return {Real(0), Real(0), (s.m * ag.horizontal * arm.vertical - gravity_moment) / c.inertia};
  }
  // The 2x2 system [M, -m h'_i; -m h'_i, I_i] (u'', theta'') = forces, by its inverse.
  const Real coupling = s.m * arm.vertical;  // m h'_i
  const Real force_u = -s.total_mass * ag.horizontal - s.damping * y[kUDot] - s.stiffness * y[kU] +
                       s.m * y[kThetaDot] * y[kThetaDot] * arm.horizontal;
  const Real force_theta = coupling * ag.horizontal - gravity_moment;
  // One multiplication after the division: the numerators are ready by the time it ends.
  const Real inverse_det = Real(1) / (s.total_mass * c.inertia - coupling * coupling);
  return {(c.inertia * force_u + coupling * force_theta) * inverse_det, Real(0),
          (coupling * force_u + s.total_mass * force_theta) * inverse_det};
}

[[nodiscard]] inline Accelerations rocking_flow(const Scene& s, const CornerGeometry& c,
                                                const State& y, GroundAcceleration ag,
                                                bool base_moves, const SinCos& trig) {
  return rocking_flow(s, c, y, ag, base_moves, lever_arms(s, c.offset, trig));
}

[[nodiscard]] inline Accelerations rocking_flow(const Scene& s, const CornerGeometry& c,
                                                const State& y, GroundAcceleration ag,
                                                bool base_moves) {
  return rocking_flow(s, c, y, ag, base_moves, sin_cos(y[kTheta]));
}

// Sliding, Eqs 4-5: m (u'' + u_G'' + x'') + F = 0, (m + m_b)(u'' + u_G'') + m x'' + c u' + k u = 0,
// F = mu_k sign(x') m (g + v_G''). `direction` is sign(x'), fixed for the phase.
[[nodiscard]] inline Accelerations sliding_flow(const Scene& s, int direction, const State& y,
                                                GroundAcceleration ag, bool base_moves) {
  const Real friction = s.params.friction.kinetic_coefficient * static_cast<Real>(direction) * s.m *
                        (s.g + ag.vertical);
  Real base = 0.0;  // u'' + u_G''
  if (base_moves) {
    base = (friction - s.damping * y[kUDot] - s.stiffness * y[kU]) / (s.total_mass - s.m);
  } else {
    base = ag.horizontal;
  }
  return {base_moves ? base - ag.horizontal : Real(0), -friction / s.m - base, Real(0)};
}

// Kinematics of C about a pivot, for slide-rocking: C's acceleration is J q'' + bias, q = (u, x,
// theta); `normal` and `tangent` are the contact's directions.
//  - About a body corner (Eqs 10-12) the pivot slides with x on the base.
//  - Overhanging (Eqs 13-14) the pivot is the support's corner, fixed on the base, and the block
//    slides over it along its bottom face, so b_hat = offset changes with x (Coriolis terms).
struct ContactKinematics {
  Vector3r jx, jy;   // rows of J, horizontal and vertical
  Vector2r bias;     // J' q', m/s2
  Vector2r normal;   // unit normal of the contact (up the block's face when overhanging)
  Vector2r tangent;  // unit direction of x
};

[[nodiscard]] inline ContactKinematics contact_kinematics(const Scene& s, Real offset,
                                                          bool overhanging, const State& y,
                                                          const SinCos& trig) {
  const Real sin_t = trig.sin;
  const Real cos_t = trig.cos;
  const Real bx = offset * cos_t - s.h * sin_t;  // b'_i, Eq 9
  const Real hy = offset * sin_t + s.h * cos_t;  // h'_i, Eq 9
  const Real w = y[kThetaDot];
  ContactKinematics k;
  if (overhanging) {
    const Real coriolis = Real(2) * y[kXDot] * w;
    k.jx << Real(1), cos_t, -hy;
    k.jy << Real(0), sin_t, bx;
    k.bias << -coriolis * sin_t - bx * w * w, coriolis * cos_t - hy * w * w;
    k.normal << -sin_t, cos_t;
    k.tangent << cos_t, sin_t;
  } else {
    k.jx << Real(1), Real(1), -hy;
    k.jy << Real(0), Real(0), bx;
    k.bias << -bx * w * w, -hy * w * w;
    k.normal << Real(0), Real(1);
    k.tangent << Real(1), Real(0);
  }
  return k;
}

[[nodiscard]] inline ContactKinematics contact_kinematics(const Scene& s, const CornerGeometry& c,
                                                          bool overhanging, const State& y) {
  return contact_kinematics(s, c.offset, overhanging, y, real_sin_cos(y[kTheta]));
}

// Contact force of the base (or the support's corner) on the block, in the contact's frame.
struct ContactForce {
  Real tangential = 0.0;  // X_i along x (Eq 19 inside, Eq 20 overhanging), N
  Real normal = 0.0;      // Y_i (Eq 12 inside, Eq 14 overhanging), N
};

// The block's equation m (a_C + a_G + g) = R, projected on the contact's directions.
[[nodiscard]] inline ContactForce contact_force(const Scene& s, const ContactKinematics& k,
                                                const Accelerations& acc, GroundAcceleration ag) {
  const Vector3r qdd(acc.u, acc.x, acc.theta);
  const Vector2r specific(k.jx.dot(qdd) + k.bias.x() + ag.horizontal,
                          k.jy.dot(qdd) + k.bias.y() + ag.vertical + s.g);
  return {s.m * k.tangent.dot(specific), s.m * k.normal.dot(specific)};
}

// Mass matrix of the slide-rocking Lagrange equations without friction, and with the friction
// coupling of sliding in `direction` (the x row gains mu_k s m n.J, Y being linear in q'').
struct SlideRockingMatrices {
  Matrix3r frictionless;
  Matrix3r with_friction;
};

[[nodiscard]] inline SlideRockingMatrices slide_rocking_matrices(const Scene& s,
                                                                const ContactKinematics& k,
                                                                int direction) {
  SlideRockingMatrices m;
  m.frictionless = s.m * (k.jx * k.jx.transpose() + k.jy * k.jy.transpose());
  m.frictionless(0, 0) += s.total_mass - s.m;
  m.frictionless(2, 2) += s.inertia_c;
  const Real mu = s.params.friction.kinetic_coefficient * static_cast<Real>(direction);
  const Vector3r normal_row = k.normal.x() * k.jx + k.normal.y() * k.jy;
  m.with_friction = m.frictionless;
  m.with_friction.row(1) += mu * s.m * normal_row.transpose();
  return m;
}

// Near Painlevé's singularity the normal force and the accelerations grow without bound, beyond
// what any fixed step resolves: below this consistency ratio the contact is taken as stuck.
inline constexpr Real kPainleveMargin = Real(0.05);

// The slide-rocking equations of one point as scalars: the entries of contact_kinematics and
// slide_rocking_matrices without Eigen temporaries (the flow is evaluated 4 times per RK4 step).
// J's rows are jx = (1, jx1, jx2) and jy = (0, jy1, jy2).
struct SlideRockingSystem {
  Real jx1 = Real(0), jx2 = Real(0), jy1 = Real(0), jy2 = 0.0;
  Real bias_x = Real(0), bias_y = 0.0;           // J' q', m/s2
  Real normal_x = Real(0), normal_y = 1.0;       // unit normal of the contact
  Real f00 = Real(0), f01 = Real(0), f02 = 0.0;  // frictionless mass matrix, symmetric
  Real f11 = Real(0), f12 = Real(0), f22 = 0.0;
  Real w10 = Real(0), w11 = Real(0), w12 = 0.0;  // its row 1 with the friction coupling
  Real friction = 0.0;                           // mu_k times the sliding direction

  // det(with friction) / det(frictionless): see sliding_consistency.
  [[nodiscard]] Real consistency() const {
    return det3(f00, f01, f02, w10, w11, w12, f02, f12, f22) /
           det3(f00, f01, f02, f01, f11, f12, f02, f12, f22);
  }

  // A 3x3 determinant by cofactors along row 0, in the order Eigen's determinant() uses.
  [[nodiscard]] static Real det3(Real a00, Real a01, Real a02, Real a10, Real a11, Real a12,
                                 Real a20, Real a21, Real a22) {
    return a00 * (a11 * a22 - a12 * a21) - a01 * (a10 * a22 - a12 * a20) +
           a02 * (a10 * a21 - a11 * a20);
  }
};

[[nodiscard]] inline SlideRockingSystem slide_rocking_system(const Scene& s, Real offset,
                                                             bool overhanging, int direction,
                                                             const State& y, const SinCos& trig) {
  const Real bx = offset * trig.cos - s.h * trig.sin;  // b'_i, Eq 9
  const Real hy = offset * trig.sin + s.h * trig.cos;  // h'_i, Eq 9
  const Real w = y[kThetaDot];
  SlideRockingSystem k;
  if (overhanging) {
    const Real coriolis = Real(2) * y[kXDot] * w;
    k.jx1 = trig.cos;
    k.jy1 = trig.sin;
    k.bias_x = -coriolis * trig.sin - bx * w * w;
    k.bias_y = coriolis * trig.cos - hy * w * w;
    k.normal_x = -trig.sin;
    k.normal_y = trig.cos;
  } else {
    k.jx1 = 1.0;
    k.jy1 = 0.0;
    k.bias_x = -bx * w * w;
    k.bias_y = -hy * w * w;
  }
  k.jx2 = -hy;
  k.jy2 = bx;
  // m (jx jx^T + jy jy^T) + diag(m_b, 0, I_C), with the products of the rotation worked out
  // (cos^2 + sin^2 = 1: J's rows are a rotation of (1, 0) and (offset, h)).
  k.f00 = s.total_mass;
  k.f01 = s.m * k.jx1;
  k.f02 = s.m * k.jx2;
  k.f11 = s.m;
  k.f12 = -s.m * (overhanging ? s.h : hy);
  k.f22 = s.m * (offset * offset + s.h * s.h) + s.inertia_c;  // I_i about the pivot
  // Row 1 gains mu_k s m n.J (Y is linear in q''): n.J = (n_x, 0, the offset overhanging or
  // b'_i on the support).
  k.friction = s.params.friction.kinetic_coefficient * static_cast<Real>(direction);
  const Real coupling = k.friction * s.m;
  k.w10 = k.f01 + coupling * k.normal_x;
  k.w11 = k.f11;
  k.w12 = k.f12 + coupling * (overhanging ? offset : bx);
  return k;
}

// det(with friction) / det(frictionless) of slide-rocking in `direction`. Where it is not
// positive, Coulomb friction makes the equations inconsistent (Painlevé's paradox: the normal
// force of the solution is negative, and it grows without bound as the ratio nears 0): high
// friction with the block well tilted. The contact then sticks (a tangential impact,
// kSlidingInconsistent in guards.h).
[[nodiscard]] inline Real sliding_consistency(const Scene& s, const Pivot& pivot, int direction,
                                              const State& y) {
  return slide_rocking_system(s, pivot.geometry.offset, pivot.overhanging, direction, y,
                              sin_cos(y[kTheta]))
      .consistency();
}

// Slide-rocking, Eqs 10-12 (about a body corner) or Eqs 13-14 (overhanging the support): the
// Lagrange equations M(q) q'' = f with the kinetic friction -mu_k sign(x') Y on x, Y being linear
// in q''. Assembled from the kinematics of C; tests/unit/core/test_sliding.cpp checks every printed
// equation's residual on the result. Solved by the adjugate (one division): the consistency
// guard keeps det(M) at least kPainleveMargin times the frictionless one.
[[nodiscard]] inline Accelerations slide_rocking_flow(const Scene& s, const SlideRockingSystem& k,
                                                      const State& y, GroundAcceleration ag,
                                                      bool base_moves) {
  const Real free_x = k.bias_x + ag.horizontal;
  const Real free_y = k.bias_y + ag.vertical + s.g;
  const Real force_u = -s.m * free_x - (s.total_mass - s.m) * ag.horizontal - s.damping * y[kUDot] -
                       s.stiffness * y[kU];
  // Friction on x: -mu_k s Y, Y = m n.(J q'' + free); its q'' part is in the mass matrix.
  const Real force_x = -s.m * (k.jx1 * free_x + k.jy1 * free_y) -
                       k.friction * s.m * (k.normal_x * free_x + k.normal_y * free_y);
  const Real force_theta = -s.m * (k.jx2 * free_x + k.jy2 * free_y);
  // Rows 1 and 2: [w11 w12; f12 f22] (x'', theta'') = (force_x, force_theta) - column 0 u''.
  const Real c11 = k.w11 * k.f22 - k.w12 * k.f12;  // minors of the lower-right 2x2 block
  if (!base_moves) {
    const Real inverse = Real(1) / c11;
    return {Real(0), (k.f22 * force_x - k.w12 * force_theta) * inverse,
            (k.w11 * force_theta - k.f12 * force_x) * inverse};
  }
  // Adjugate of [f00 f01 f02; w10 w11 w12; f02 f12 f22].
  const Real c01 = k.w12 * k.f02 - k.w10 * k.f22;
  const Real c02 = k.w10 * k.f12 - k.w11 * k.f02;
  const Real a01 = k.f02 * k.f12 - k.f01 * k.f22;
  const Real a02 = k.f01 * k.w12 - k.f02 * k.w11;
  const Real a11 = k.f00 * k.f22 - k.f02 * k.f02;
  const Real a12 = k.f02 * k.w10 - k.f00 * k.w12;
  const Real a21 = k.f01 * k.f02 - k.f00 * k.f12;
  const Real a22 = k.f00 * k.w11 - k.f01 * k.w10;
  const Real inverse = Real(1) / (k.f00 * c11 + k.f01 * c01 + k.f02 * c02);
  return {(c11 * force_u + a01 * force_x + a02 * force_theta) * inverse,
          (c01 * force_u + a11 * force_x + a12 * force_theta) * inverse,
          (c02 * force_u + a21 * force_x + a22 * force_theta) * inverse};
}

[[nodiscard]] inline Accelerations slide_rocking_flow(const Scene& s, const CornerGeometry& c,
                                                      bool overhanging, int direction,
                                                      const State& y, GroundAcceleration ag,
                                                      bool base_moves) {
  return slide_rocking_flow(
      s, slide_rocking_system(s, c.offset, overhanging, direction, y, sin_cos(y[kTheta])), y, ag,
      base_moves);
}

// Horizontal force the stops must exert on the base to hold it still (u' = u'' = 0), N: the
// base's own equation, m_b u_G'' + k u + (the block's horizontal force on the base), where the
// block's force is m times its absolute horizontal acceleration. Positive pushes towards +u.
[[nodiscard]] inline Real base_stop_reaction(const Scene& s, const Mode& mode, const State& y,
                                             GroundAcceleration ag, const Accelerations& acc,
                                             const SinCos& trig) {
  const PivotDistance pivot = pivot_distance(s, mode.corner, mode.overhang, y[kX]);
  const ContactKinematics k = contact_kinematics(s, pivot.offset(), pivot.overhanging, y, trig);
  const Real block = k.jx.dot(Vector3r(acc.u, acc.x, acc.theta)) + k.bias.x() + ag.horizontal;
  return (s.total_mass - s.m) * ag.horizontal + s.stiffness * y[kU] + s.m * block;
}

[[nodiscard]] inline Real base_stop_reaction(const Scene& s, const Mode& mode, const State& y,
                                             GroundAcceleration ag, const Accelerations& acc) {
  return base_stop_reaction(s, mode, y, ag, acc, sin_cos(y[kTheta]));
}

// What the solver knows at one point (t, y) of a phase's flow: the ground's acceleration, the
// rotation's sin and cos, and the accelerations. The guards are evaluated on it, and at the end
// of a step without event it is the next step's first Runge-Kutta stage.
struct FlowPoint {
  GroundAcceleration ground;
  SinCos trig;
  Accelerations acc;
  // Slide-rocking only: sliding_consistency in the sliding direction, from the same matrices
  // as the flow (the Painlevé guard needs it at every step's end).
  Real consistency = 1.0;
};

// dy/dt of the state for the phase's accelerations `a`.
[[nodiscard]] inline State state_derivative(const State& y, const Accelerations& a) {
  State d;
  d.head<3>() = y.tail<3>();
  d[kUDot] = a.u;
  d[kXDot] = a.x;
  d[kThetaDot] = a.theta;
  return d;
}

}  // namespace plinth::internal

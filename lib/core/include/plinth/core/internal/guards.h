// Internal to plinth_core (tests may include it). Guards (witness functions) of the hybrid
// system: each is a scalar function of time and state whose crossing from negative to
// non-negative is its event; only the guards of the current mode are live (active_guards, for
// the scene's Features, scene.h).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "plinth/core/excitation.h"
#include "plinth/core/internal/flows.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth::internal {

enum class GuardId : std::uint8_t {
  kRockingOnsetLeft,     // Eq 16 (from rest or full contact) or Eq 17 (while sliding), corner 1
  kRockingOnsetRight,    // the same about corner 2
  kRockingImpact,        // theta returns to 0 (Section 3.3)
  kOverturning,          // |theta| passes the active pivot's critical angle
  kSlidingOnsetLeft,     // Eq 15 (full contact) or Eq 18 (rocking): the block slides with x' < 0
  kSlidingOnsetRight,    // ... with x' > 0
  kSlidingStop,          // x' returns to 0 (Section 3.2.1)
  kSlidingInconsistent,  // slide-rocking reaches Painlevé's paradox: the contact sticks
  kOutOfBaseLeft,        // x passes -x_hat: the block overhangs the support's left edge
  kOutOfBaseRight,       // x passes +x_hat
  kBackOnBase,           // the overhanging block slides back onto the support
  kFall,                 // C passes the support's edge (b_hat = 0): the block falls off
  kSlidingStopLeft,      // Eq 30, x = -x_hat with sliding stops
  kSlidingStopRight,     // Eq 30, x = +x_hat
  kBaseStopRight,        // Eq 28, u = +u_max
  kBaseStopLeft,         // Eq 28, u = -u_max
  kBaseStopRelease,      // the held base's stop would have to pull: it leaves the stop
  kLiftOff,              // the support's normal force on the block reaches 0: outside the model
};

inline constexpr int kMaxActiveGuards = 13;

using GuardValues = std::array<Real, kMaxActiveGuards>;

struct ActiveGuards {
  std::array<GuardId, kMaxActiveGuards> ids{};
  int count = 0;

  constexpr void add(GuardId id) { ids[static_cast<std::size_t>(count++)] = id; }
};

// The guards every live mode of a phase has first, in active_guards' order: kLiftOff, then the
// rocking ones (rocking and slide-rocking) or the rocking onsets (full contact and sliding). The
// step evaluates these without a switch (step_interval.h).
inline constexpr int kLeadingGuards = 3;
[[nodiscard]] constexpr std::array<GuardId, kLeadingGuards> leading_guards(bool rocking) {
  if (rocking) return {GuardId::kLiftOff, GuardId::kRockingImpact, GuardId::kOverturning};
  return {GuardId::kLiftOff, GuardId::kRockingOnsetLeft, GuardId::kRockingOnsetRight};
}

template <Features F>
[[nodiscard]] constexpr ActiveGuards active_guards(const Mode& mode) {
  ActiveGuards g;
  if (mode.terminal()) return g;
  g.add(GuardId::kLiftOff);  // first: at a tie the model's validity ends before anything else
  if (mode.rocking()) {
    g.add(GuardId::kRockingImpact);
    g.add(GuardId::kOverturning);
  } else {
    g.add(GuardId::kRockingOnsetLeft);
    g.add(GuardId::kRockingOnsetRight);
  }
  if constexpr (F.sliding) {
    if (mode.sliding()) {
      g.add(GuardId::kSlidingStop);
      if (mode.rocking()) g.add(GuardId::kSlidingInconsistent);
      if constexpr (F.support_edge) {
        if (mode.overhang == 0) {
          g.add(GuardId::kOutOfBaseLeft);
          g.add(GuardId::kOutOfBaseRight);
        } else {
          g.add(GuardId::kBackOnBase);
          g.add(GuardId::kFall);
        }
      }
      if constexpr (F.sliding_stops) {
        g.add(GuardId::kSlidingStopLeft);
        g.add(GuardId::kSlidingStopRight);
      }
    } else {
      g.add(GuardId::kSlidingOnsetLeft);
      g.add(GuardId::kSlidingOnsetRight);
    }
  }
  if constexpr (F.base_stops) {
    if (mode.held_stop != 0) {
      g.add(GuardId::kBaseStopRelease);
    } else {
      g.add(GuardId::kBaseStopRight);
      g.add(GuardId::kBaseStopLeft);
    }
  }
  return g;
}

// Eqs 16-17: rocking about corner i starts when the block's absolute horizontal acceleration
// u'' + u_G'' + x'' reaches (b_hat_i / h)(g + v_G'') towards that corner's side (corner 1:
// positive). b_hat_i is the pivot's distance from C (b_i on the support).
[[nodiscard]] inline Real rocking_onset_guard(const Scene& s, Real sign, Real onset_ratio,
                                              const Accelerations& acc, GroundAcceleration ag) {
  const Real block = acc.u + acc.x + ag.horizontal;
  return sign * block - onset_ratio * (s.g + ag.vertical);
}

[[nodiscard]] inline Real rocking_onset_guard(const Scene& s, const Pivot& pivot,
                                              const Accelerations& acc, GroundAcceleration ag) {
  return rocking_onset_guard(s, pivot.geometry.sign, pivot.geometry.onset_ratio, acc, ag);
}

// The same about `corner`, with the pivot's onset ratio b_hat_i / h computed as make_scene does.
[[nodiscard]] inline Real rocking_onset_guard(const Scene& s, Corner corner, const Mode& mode,
                                              const State& y, const Accelerations& acc,
                                              GroundAcceleration ag) {
  const PivotDistance pivot = pivot_distance(s, corner, mode.overhang, y[kX]);
  const Real ratio = pivot.overhanging ? pivot.distance / s.h : s.corner(corner).onset_ratio;
  return rocking_onset_guard(s, pivot.sign, ratio, acc, ag);
}

// |theta| passes the pivot's critical angle alpha_i = atan(b_hat_i / h). About the body's
// corner alpha_i is fixed: sign theta - alpha_i. About the support's corner b_hat_i moves with x,
// and the guard is h sin(sign theta) - b_hat_i cos(theta) = r_i sin(sign theta - alpha_i), which
// has the same sign and the same root (C right above the pivot) without an atan2 per point.
[[nodiscard]] inline Real overturning_guard(const Scene& s, const Mode& mode, const State& y,
                                            const SinCos& trig) {
  const PivotDistance pivot = pivot_distance(s, mode.corner, mode.overhang, y[kX]);
  if (!pivot.overhanging) {
    const CornerGeometry& c = s.corner(mode.corner);
    return c.sign * y[kTheta] - c.critical_angle;
  }
  return s.h * pivot.sign * trig.sin - pivot.distance * trig.cos;
}

// Contact force on the block while it sticks (full contact or rocking), for Eqs 15 and 18.
[[nodiscard]] inline ContactForce sticking_contact_force(const Scene& s, const Mode& mode,
                                                         const State& y, GroundAcceleration ag,
                                                         const Accelerations& acc,
                                                         const SinCos& trig) {
  if (!mode.rocking()) {  // full contact, Eq 15: X = m (u'' + u_G''), Y = m (g + v_G'')
    return {s.m * (acc.u + ag.horizontal), s.m * (s.g + ag.vertical)};
  }
  const PivotDistance pivot = pivot_distance(s, mode.corner, mode.overhang, y[kX]);
  return contact_force(s, contact_kinematics(s, pivot.offset(), pivot.overhanging, y, trig), acc,
                       ag);
}

[[nodiscard]] inline ContactForce sticking_contact_force(const Scene& s, const Mode& mode,
                                                         const State& y, GroundAcceleration ag,
                                                         const Accelerations& acc) {
  return sticking_contact_force(s, mode, y, ag, acc, sin_cos(y[kTheta]));
}

// Lift-off: the witness is minus the support's normal force on the block per unit mass, Y / m
// (m/s2); the model has no free flight, so where Y reaches 0 its validity ends. Y per phase:
//  - full contact and sliding (Fig. 4(a), Eqs 5 and 15): Y = m (g + v_G''), so the block lifts
//    off when the ground falls faster than gravity, v_G'' <= -g;
//  - rocking and slide-rocking about a body corner, Eq 12 (pure rocking: x'' = 0):
//    Y = m (g + v_G'') + m b'_i theta'' - m h'_i theta'^2: besides the ground's fall, the
//    pivot unloads when the rotation accelerates the wrong way or spins fast (centripetal term);
//  - about the support's corner, Eq 14 (x' = 0 in pure rocking), with its Coriolis term.
// Computed by sticking_contact_force (one copy of the contact's equations: the Cortex-M image's
// flash); tests/unit/core/test_lift_off.cpp checks it against each printed form above.
[[nodiscard]] inline Real lift_off_guard(const Scene& s, const Mode& mode, const State& y,
                                         GroundAcceleration ag, const Accelerations& acc,
                                         const SinCos& trig) {
  return -sticking_contact_force(s, mode, y, ag, acc, trig).normal / s.m;
}

// The lift-off guard's sign at a glance while rocking, from an upper bound of the guard without
// the contact's kinematics. About a corner of the body (Eq 12) -Y / m = -(g + v_G'') -
// b'_i theta'' + h'_i theta'^2 with |b'_i|, |h'_i| <= r_i (Eq 9), so the guard is at most
// r_i (|theta''| + theta'^2) - (g + v_G''). About the support's corner (Eq 14) -Y / m =
// -(g + v_G'') cos theta + (u'' + u_G'') sin theta - 2 x' theta' - b_hat_i theta'' + h theta'^2,
// at most |(u'' + u_G'') sin theta| + 2 |x' theta'| + b_hat_i |theta''| + h theta'^2 -
// (g + v_G'') cos theta. Returns the bound when it is negative by more than kLiftOffBoundMargin
// of the size of the terms lift_off_guard adds up (its roundings are a few epsilon of that): the
// guard is then certainly negative too. Otherwise (near lift-off, or not a number) returns +1,
// and the guard must be evaluated. The bound is a witness value only for its sign: whoever needs
// the number (locating a crossing) evaluates lift_off_guard.
inline constexpr Real kLiftOffBoundMargin = Real(1024) * real_tolerance::kEpsilon;

[[nodiscard]] inline Real lift_off_bound(const Scene& s, const Mode& mode, const State& y,
                                         GroundAcceleration ag, const Accelerations& acc,
                                         const SinCos& trig) {
  const Real support = s.g + ag.vertical;  // per unit mass
  const Real spin = y[kThetaDot] * y[kThetaDot];
  Real load = 0.0;
  Real bound = 0.0;
  Real size = 0.0;
  const PivotDistance pivot = pivot_distance(s, mode.corner, mode.overhang, y[kX]);
  if (!pivot.overhanging) {
    load = s.corner(mode.corner).radius * (std::fabs(acc.theta) + spin);
    bound = load - support;
    size = std::fabs(support) + load;
  } else {
    const Real base = std::fabs(acc.u + ag.horizontal);
    const Real coriolis = Real(2) * std::fabs(y[kXDot] * y[kThetaDot]);
    load =
        base * std::fabs(trig.sin) + coriolis + pivot.distance * std::fabs(acc.theta) + s.h * spin;
    bound = load - support * trig.cos;
    // The contact's kinematics add terms that cancel (x'', b'_i theta''): their size too.
    size = std::fabs(support) + base + std::fabs(acc.x) + coriolis +
           (pivot.distance + s.h) * (std::fabs(acc.theta) + spin);
  }
  return bound < -kLiftOffBoundMargin * size ? bound : Real(1);
}

// det(with friction) / det(frictionless) of slide-rocking about the mode's pivot in `direction`
// (flows.h, sliding_consistency).
[[nodiscard]] inline Real sliding_consistency(const Scene& s, const Mode& mode, int direction,
                                              const State& y, const SinCos& trig) {
  const PivotDistance pivot = pivot_distance(s, mode.corner, mode.overhang, y[kX]);
  return slide_rocking_system(s, pivot.offset(), pivot.overhanging, direction, y, trig)
      .consistency();
}

// Eqs 15 and 18: sliding starts when static friction cannot hold, mu_s Y <= |X|. The block
// slides against X (direction -1 when X > 0). A block pressed against a sliding stop cannot
// slide into it.
// While rocking, a direction in which Painlevé's paradox holds (or nearly: kPainleveMargin)
// cannot start sliding either: the contact sticks.
[[nodiscard]] inline Real sliding_onset_guard(const Scene& s, const Mode& mode, const State& y,
                                              int direction, const ContactForce& f,
                                              const SinCos& trig) {
  if (s.params.has_sliding_stops &&
      static_cast<Real>(direction) * y[kX] >=
          s.params.support.clearance * (Real(1) - real_tolerance::kAtEdge)) {
    return -Real(1);
  }
  const Real onset = -static_cast<Real>(direction) * f.tangential -
                     s.params.friction.static_coefficient * f.normal;
  // The 3x3 determinants only where the onset would otherwise fire, not every step.
  if (onset >= Real(0) && mode.rocking() &&
      sliding_consistency(s, mode, direction, y, trig) <= kPainleveMargin) {
    return -Real(1);
  }
  return onset;
}

[[nodiscard]] inline Real sliding_onset_guard(const Scene& s, const Mode& mode, const State& y,
                                              int direction, const ContactForce& f) {
  return sliding_onset_guard(s, mode, y, direction, f, sin_cos(y[kTheta]));
}

// Value of guard `id` at (y, ag) with the mode's accelerations `acc`; trig holds sin and cos of
// y[kTheta] (FlowPoint).
[[nodiscard]] inline Real guard_value(GuardId id, const Scene& s, const Mode& mode, const State& y,
                                      GroundAcceleration ag, const Accelerations& acc,
                                      const SinCos& trig) {
  const Real x_hat = s.params.support.clearance;
  switch (id) {
    case GuardId::kRockingOnsetLeft:
      return rocking_onset_guard(s, Corner::kLeft, mode, y, acc, ag);
    case GuardId::kRockingOnsetRight:
      return rocking_onset_guard(s, Corner::kRight, mode, y, acc, ag);
    case GuardId::kRockingImpact:
      return -s.corner(mode.corner).sign * y[kTheta];
    case GuardId::kOverturning:
      return overturning_guard(s, mode, y, trig);
    case GuardId::kSlidingOnsetLeft:
    case GuardId::kSlidingOnsetRight:
      return sliding_onset_guard(s, mode, y, id == GuardId::kSlidingOnsetLeft ? -1 : 1,
                                 sticking_contact_force(s, mode, y, ag, acc, trig), trig);
    case GuardId::kSlidingStop:
      return -mode.slide_direction * y[kXDot];
    case GuardId::kSlidingInconsistent:
      return kPainleveMargin - sliding_consistency(s, mode, mode.slide_direction, y, trig);
    case GuardId::kOutOfBaseLeft:
    case GuardId::kSlidingStopLeft:
      return -y[kX] - x_hat;
    case GuardId::kOutOfBaseRight:
    case GuardId::kSlidingStopRight:
      return y[kX] - x_hat;
    case GuardId::kBackOnBase:
      return x_hat - mode.overhang * y[kX];
    case GuardId::kFall:  // b_hat of the overhanging side reaches 0
      return mode.overhang * y[kX] - x_hat - (mode.overhang < 0 ? s.b1 : s.b2);
    case GuardId::kBaseStopRight:
      return y[kU] - s.params.base_stops.max_displacement;
    case GuardId::kBaseStopLeft:
      return -y[kU] - s.params.base_stops.max_displacement;
    case GuardId::kBaseStopRelease:
      return static_cast<Real>(mode.held_stop) * base_stop_reaction(s, mode, y, ag, acc, trig);
    case GuardId::kLiftOff:
      return lift_off_guard(s, mode, y, ag, acc, trig);
  }
  return -Real(1);
}

[[nodiscard]] inline Real guard_value(GuardId id, const Scene& s, const Mode& mode, const State& y,
                                      GroundAcceleration ag, const Accelerations& acc) {
  return guard_value(id, s, mode, y, ag, acc, sin_cos(y[kTheta]));
}

// guard_value at a FlowPoint, with the guards every step evaluates written out here, small
// enough to be inlined into the solver's loop; the costlier ones (Eqs 15/18, the stop's
// reaction, the support's edge) go through guard_value. The same values, but for the lift-off
// guard while rocking far from lift-off: its bound (lift_off_bound), of the same sign; a crossing
// is located on guard_value's (step_interval.h, earliest_crossing).
[[nodiscard]] inline Real step_guard_value(GuardId id, const Scene& s, const Mode& mode,
                                           const State& y, const FlowPoint& p) {
  const Accelerations& acc = p.acc;
  const GroundAcceleration ag = p.ground;
  switch (id) {
    case GuardId::kRockingOnsetLeft:
    case GuardId::kRockingOnsetRight:
      if (mode.overhang == 0) {
        const CornerGeometry& c =
            s.corner(id == GuardId::kRockingOnsetLeft ? Corner::kLeft : Corner::kRight);
        return rocking_onset_guard(s, c.sign, c.onset_ratio, acc, ag);
      }
      break;
    case GuardId::kRockingImpact:
      return -s.corner(mode.corner).sign * y[kTheta];
    case GuardId::kOverturning:
      if (mode.overhang == 0) {
        const CornerGeometry& c = s.corner(mode.corner);
        return c.sign * y[kTheta] - c.critical_angle;
      }
      break;
    case GuardId::kSlidingStop:
      return -mode.slide_direction * y[kXDot];
    case GuardId::kBaseStopRight:
      return y[kU] - s.params.base_stops.max_displacement;
    case GuardId::kBaseStopLeft:
      return -y[kU] - s.params.base_stops.max_displacement;
    case GuardId::kSlidingInconsistent:
      return kPainleveMargin - p.consistency;
    case GuardId::kLiftOff:
      if (!mode.rocking()) return -(s.g + ag.vertical);
      if (const Real bound = lift_off_bound(s, mode, y, ag, acc, p.trig); bound < Real(0)) {
        return bound;
      }
      break;
    default:
      break;
  }
  return guard_value(id, s, mode, y, ag, acc, p.trig);
}

}  // namespace plinth::internal

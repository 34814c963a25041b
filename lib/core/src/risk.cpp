#include "plinth/core/risk.h"

#include <cmath>

#include "plinth/core/energy.h"
#include "plinth/core/internal/flows.h"

namespace plinth {

namespace {

Real unit_clamp(Real v) { return v < Real(0) ? Real(0) : (v > Real(1) ? Real(1) : v); }

// Sliding towards the support's edge, or resting over it (see risk.h).
Real sliding_fall_risk(const Scene& s, const Mode& mode, const State& y) {
  const Real x_hat = s.params.support.clearance;
  Real risk = 0.0;
  for (const int side : {-1, 1}) {
    // C passes the edge on `side` when static_cast<Real>(side) * x reaches x_hat + b_side
    // (internal/guards.h, kFall).
    const Real reach = x_hat + (side < 0 ? s.b1 : s.b2);
    const Real left = reach - static_cast<Real>(side) * y[kX];
    if (left <= Real(0)) return 1.0;
    if (static_cast<Real>(side) * y[kX] > x_hat)
      risk = std::fmax(risk, (static_cast<Real>(side) * y[kX] - x_hat) / (reach - x_hat));
    if (mode.sliding() && static_cast<Real>(side) * y[kXDot] > Real(0)) {
      const Real deceleration = s.params.friction.kinetic_coefficient * s.g;
      if (deceleration <= Real(0)) return 1.0;
      risk = std::fmax(risk, y[kXDot] * y[kXDot] / (Real(2) * deceleration) / left);
    }
  }
  return unit_clamp(risk);
}

}  // namespace

Error validate(const RiskSettings& st) {
  if (!std::isfinite(st.base_stop_weight) || st.base_stop_weight < Real(0) ||
      st.base_stop_weight > Real(1)) {
    return {ErrorCode::kOutOfRange, "risk.base_stop_weight", "must lie in [0, 1]"};
  }
  return ok_error();
}

Risk overturning_risk(const Scene& s, const Mode& mode, const State& y, const RiskSettings& st) {
  Risk r;
  if (mode.phase == Phase::kOverturned) r.overturning = 1.0;
  if (mode.phase == Phase::kFell) r.falling = 1.0;
  if (!mode.terminal()) {
    if (mode.rocking()) {
      const internal::Pivot pivot = internal::pivot_of(s, mode, y);
      const Real barrier = s.m * s.g * (pivot.geometry.radius - s.h);
      const Real ratio = barrier > Real(0) ? rocking_energy(s, mode, y) / barrier : Real(1);
      (pivot.overhanging ? r.falling : r.overturning) = unit_clamp(ratio);
    }
    if (s.params.has_support && !s.params.has_sliding_stops) {
      r.falling = std::fmax(r.falling, sliding_fall_risk(s, mode, y));
    }
    if (s.params.has_base_stops && mode.held_stop == 0) {
      const Real omega = std::sqrt(s.stiffness / s.total_mass);
      const Real amplitude = std::hypot(y[kU], y[kUDot] / omega);
      r.base_stops =
          st.base_stop_weight * unit_clamp(amplitude / s.params.base_stops.max_displacement);
    } else if (mode.held_stop != 0) {
      r.base_stops = st.base_stop_weight;
    }
  }
  r.total = std::fmax(r.overturning, std::fmax(r.falling, r.base_stops));
  return r;
}

}  // namespace plinth

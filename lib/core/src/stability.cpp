#include "plinth/core/stability.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "build_options.h"

namespace plinth {

namespace {

// Largest |lambda| of m u'' + c u' + k u = 0, 1/s.
Real largest_rate(Real mass, Real damping, Real stiffness) {
  const Real a = damping / (Real(2) * mass);
  const Real w2 = stiffness / mass;
  if (a * a <= w2) return std::sqrt(w2);  // complex pair, |lambda| = sqrt(k/m)
  return a + std::sqrt(a * a - w2);       // overdamped: the fast real root
}

// A 2x2 matrix on (q, q').
struct Matrix2 {
  Real a00, a01, a10, a11;
};

Matrix2 product(const Matrix2& x, const Matrix2& y) {
  return {x.a00 * y.a00 + x.a01 * y.a10, x.a00 * y.a01 + x.a01 * y.a11,
          x.a10 * y.a00 + x.a11 * y.a10, x.a10 * y.a01 + x.a11 * y.a11};
}

Real spectral_radius(const Matrix2& g) {
  const Real half_trace = Real(0.5) * (g.a00 + g.a11);
  const Real det = g.a00 * g.a11 - g.a01 * g.a10;
  const Real discriminant = half_trace * half_trace - det;
  if (discriminant < Real(0)) return std::sqrt(det);  // complex pair, |mu|^2 = det
  const Real root = std::sqrt(discriminant);
  return std::max(std::fabs(half_trace + root), std::fabs(half_trace - root));
}

// The one-step map of `stepper` with step h on m q'' + c q' + k q = 0.
Matrix2 amplification(Stepper stepper, Real mass, Real damping, Real stiffness, Real h) {
  const Real a = -stiffness / mass;
  const Real b = -damping / mass;
  if (stepper == Stepper::kSemiImplicitEuler) {
    return {Real(1) + h * h * a, h + h * h * b, h * a, Real(1) + h * b};
  }
  const Matrix2 ha{Real(0), h, h * a, h * b};
  const Matrix2 ha2 = product(ha, ha);
  Matrix2 g{Real(1) + ha.a00 + Real(0.5) * ha2.a00, ha.a01 + Real(0.5) * ha2.a01,
            ha.a10 + Real(0.5) * ha2.a10, Real(1) + ha.a11 + Real(0.5) * ha2.a11};
  if (stepper == Stepper::kHeunLocated) return g;
  const Matrix2 ha3 = product(ha2, ha);
  const Matrix2 ha4 = product(ha3, ha);
  g.a00 += ha3.a00 / Real(6) + ha4.a00 / Real(24);
  g.a01 += ha3.a01 / Real(6) + ha4.a01 / Real(24);
  g.a10 += ha3.a10 / Real(6) + ha4.a10 / Real(24);
  g.a11 += ha3.a11 / Real(6) + ha4.a11 / Real(24);
  return g;
}

// The largest h whose one-step map grows no mode by more than kStableGrowthPerStep: scanned up
// from far below the system's time scale in steps of 2 %, the first failure then bisected.
Real largest_stable_step_of(Stepper stepper, Real mass, Real damping, Real stiffness) {
  const Real rate = largest_rate(mass, damping, stiffness);
  const auto stable = [&](Real h) {
    return spectral_radius(amplification(stepper, mass, damping, stiffness, h)) <=
           Real(1) + kStableGrowthPerStep;
  };
  Real low = Real(1e-4) / rate;
  if (!stable(low)) return 0.0;
  Real high = low;
  while (stable(high)) {
    low = high;
    high *= Real(1.02);
    if (high > Real(100) / rate) return high;
  }
  for (int i = 0; i < 60; ++i) {
    const Real middle = Real(0.5) * (low + high);
    (stable(middle) ? low : high) = middle;
  }
  return low;
}

}  // namespace

Real largest_stable_step(const Scene& s) {
  if (!s.has_base()) return std::numeric_limits<Real>::infinity();
  constexpr Real kRk4StabilityRadius = 2.5;  // below 2.78 (real axis) and 2.83 (imaginary)
  const Real base_mass = s.total_mass - s.m;
  const Real rate = std::max(largest_rate(s.total_mass, s.damping, s.stiffness),
                             largest_rate(base_mass, s.damping, s.stiffness));
  return kRk4StabilityRadius / rate;
}

Real largest_stable_step(const Scene& s, Stepper stepper) {
  if (stepper == Stepper::kRk4Located || stepper == Stepper::kRk4StepEnd || !s.has_base()) {
    return largest_stable_step(s);
  }
  // A build with rk4_located alone has no other stepper: no step of one is stable.
  if constexpr (PLINTH_CORE_RK4_ONLY) return 0.0;
  return std::min(largest_stable_step_of(stepper, s.total_mass, s.damping, s.stiffness),
                  largest_stable_step_of(stepper, s.total_mass - s.m, s.damping, s.stiffness));
}

}  // namespace plinth

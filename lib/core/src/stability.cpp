#include "plinth/core/stability.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "build_options.h"

namespace plinth {

namespace {

// Largest |lambda| of m u'' + c u' + k u = 0, 1/s.
double largest_rate(double mass, double damping, double stiffness) {
  const double a = damping / (2.0 * mass);
  const double w2 = stiffness / mass;
  if (a * a <= w2) return std::sqrt(w2);  // complex pair, |lambda| = sqrt(k/m)
  return a + std::sqrt(a * a - w2);       // overdamped: the fast real root
}

// A 2x2 matrix on (q, q').
struct Matrix2 {
  double a00, a01, a10, a11;
};

Matrix2 product(const Matrix2& x, const Matrix2& y) {
  return {x.a00 * y.a00 + x.a01 * y.a10, x.a00 * y.a01 + x.a01 * y.a11,
          x.a10 * y.a00 + x.a11 * y.a10, x.a10 * y.a01 + x.a11 * y.a11};
}

double spectral_radius(const Matrix2& g) {
  const double half_trace = 0.5 * (g.a00 + g.a11);
  const double det = g.a00 * g.a11 - g.a01 * g.a10;
  const double discriminant = half_trace * half_trace - det;
  if (discriminant < 0.0) return std::sqrt(det);  // complex pair, |mu|^2 = det
  const double root = std::sqrt(discriminant);
  return std::max(std::fabs(half_trace + root), std::fabs(half_trace - root));
}

// The one-step map of `stepper` with step h on m q'' + c q' + k q = 0.
Matrix2 amplification(Stepper stepper, double mass, double damping, double stiffness, double h) {
  const double a = -stiffness / mass;
  const double b = -damping / mass;
  if (stepper == Stepper::kSemiImplicitEuler) {
    return {1.0 + h * h * a, h + h * h * b, h * a, 1.0 + h * b};
  }
  const Matrix2 ha{0.0, h, h * a, h * b};
  const Matrix2 ha2 = product(ha, ha);
  Matrix2 g{1.0 + ha.a00 + 0.5 * ha2.a00, ha.a01 + 0.5 * ha2.a01, ha.a10 + 0.5 * ha2.a10,
            1.0 + ha.a11 + 0.5 * ha2.a11};
  if (stepper == Stepper::kHeunLocated) return g;
  const Matrix2 ha3 = product(ha2, ha);
  const Matrix2 ha4 = product(ha3, ha);
  g.a00 += ha3.a00 / 6.0 + ha4.a00 / 24.0;
  g.a01 += ha3.a01 / 6.0 + ha4.a01 / 24.0;
  g.a10 += ha3.a10 / 6.0 + ha4.a10 / 24.0;
  g.a11 += ha3.a11 / 6.0 + ha4.a11 / 24.0;
  return g;
}

// The largest h whose one-step map grows no mode by more than kStableGrowthPerStep: scanned up
// from far below the system's time scale in steps of 2 %, the first failure then bisected.
double largest_stable_step_of(Stepper stepper, double mass, double damping, double stiffness) {
  const double rate = largest_rate(mass, damping, stiffness);
  const auto stable = [&](double h) {
    return spectral_radius(amplification(stepper, mass, damping, stiffness, h)) <=
           1.0 + kStableGrowthPerStep;
  };
  double low = 1e-4 / rate;
  if (!stable(low)) return 0.0;
  double high = low;
  while (stable(high)) {
    low = high;
    high *= 1.02;
    if (high > 100.0 / rate) return high;
  }
  for (int i = 0; i < 60; ++i) {
    const double middle = 0.5 * (low + high);
    (stable(middle) ? low : high) = middle;
  }
  return low;
}

}  // namespace

double largest_stable_step(const Scene& s) {
  if (!s.has_base()) return std::numeric_limits<double>::infinity();
  constexpr double kRk4StabilityRadius = 2.5;  // below 2.78 (real axis) and 2.83 (imaginary)
  const double base_mass = s.total_mass - s.m;
  const double rate = std::max(largest_rate(s.total_mass, s.damping, s.stiffness),
                               largest_rate(base_mass, s.damping, s.stiffness));
  return kRk4StabilityRadius / rate;
}

double largest_stable_step(const Scene& s, Stepper stepper) {
  if (stepper == Stepper::kRk4Located || stepper == Stepper::kRk4StepEnd || !s.has_base()) {
    return largest_stable_step(s);
  }
  // A build with rk4_located alone has no other stepper: no step of one is stable.
  if constexpr (PLINTH_CORE_RK4_ONLY) return 0.0;
  return std::min(largest_stable_step_of(stepper, s.total_mass, s.damping, s.stiffness),
                  largest_stable_step_of(stepper, s.total_mass - s.m, s.damping, s.stiffness));
}

}  // namespace plinth

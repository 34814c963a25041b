#include "plinth/core/closed_forms.h"

#include <cmath>

namespace plinth {

Real peak_acceleration_factor(Real xi) {
  if (xi > Real(0.5)) return Real(2) * xi;
  const Real s = std::sqrt(Real(1) - xi * xi);
  return std::exp(-(xi / s) * (std::acos(xi) - Real(2) * std::asin(xi)));
}

Real printed_peak_acceleration_factor(Real xi) {
  if (xi == Real(0)) return 1.0;
  const Real s = std::sqrt(Real(1) - xi * xi);
  const Real x2 = Real(4) * xi * xi;
  return std::exp(-(xi / s) * std::atan((s - Real(1) - x2) / (xi - Real(3) - x2)));
}

Real impulse_response_displacement(const Scene& s, Real impulse, Real t) {
  const Real xi = s.params.base.damping_ratio;
  const Real root = std::sqrt(Real(1) - xi * xi);
  return impulse / (s.omega * root) * std::exp(-xi * s.omega * t) * std::sin(s.omega * root * t);
}

Real rocking_impulse_threshold(const Scene& s, Corner corner) {
  const Real xi = s.params.base.damping_ratio;
  return s.g * s.corner(corner).onset_ratio / (s.omega * peak_acceleration_factor(xi));
}

Real sliding_impulse_threshold(const Scene& s) {
  const Real xi = s.params.base.damping_ratio;
  return s.params.friction.static_coefficient * s.g / (s.omega * peak_acceleration_factor(xi));
}

Real slide_rocking_friction_limit(const Scene& s, Corner corner) {
  return s.corner(corner).onset_ratio;
}

Real rocking_to_sliding_friction(const Scene& s, Corner corner, Real impulse) {
  const Real xi = s.params.base.damping_ratio;
  const Real a = std::fabs(impulse) * s.omega * peak_acceleration_factor(xi);  // Eq 40
  const Real bi = s.corner(corner).onset_ratio * s.h;                          // b_i
  const Real j = s.inertia_c / s.m;                                            // I_C / m
  return (a * (j + bi * bi) + s.g * s.h * bi) / (s.g * (j + s.h * s.h) + a * s.h * bi);
}

Real printed_eq41(Real epsilon, Real lambda, Real impulse, Real omega, Real a_xi, Real g) {
  const Real a = std::fabs(impulse) * omega * a_xi;
  const Real e1 = Real(1) + epsilon;
  return (a * (Real(3) + Real(6) * epsilon + Real(3) * epsilon * epsilon + lambda * lambda) +
          Real(3) * g * e1 * lambda) /
         (lambda * (Real(3) * a * e1 + Real(4) * g * lambda));
}

Real housner_velocity_ratio(Real alpha) {
  const Real sin_a = std::sin(alpha);
  return Real(1) - Real(1.5) * sin_a * sin_a;
}

}  // namespace plinth

#include "plinth/core/closed_forms.h"

#include <cmath>

namespace plinth {

double peak_acceleration_factor(double xi) {
  if (xi > 0.5) return 2.0 * xi;
  const double s = std::sqrt(1.0 - xi * xi);
  return std::exp(-(xi / s) * (std::acos(xi) - 2.0 * std::asin(xi)));
}

double printed_peak_acceleration_factor(double xi) {
  if (xi == 0.0) return 1.0;
  const double s = std::sqrt(1.0 - xi * xi);
  const double x2 = 4.0 * xi * xi;
  return std::exp(-(xi / s) * std::atan((s - 1.0 - x2) / (xi - 3.0 - x2)));
}

double impulse_response_displacement(const Scene& s, double impulse, double t) {
  const double xi = s.params.base.damping_ratio;
  const double root = std::sqrt(1.0 - xi * xi);
  return impulse / (s.omega * root) * std::exp(-xi * s.omega * t) * std::sin(s.omega * root * t);
}

double rocking_impulse_threshold(const Scene& s, Corner corner) {
  const double xi = s.params.base.damping_ratio;
  return s.g * s.corner(corner).onset_ratio / (s.omega * peak_acceleration_factor(xi));
}

double sliding_impulse_threshold(const Scene& s) {
  const double xi = s.params.base.damping_ratio;
  return s.params.friction.static_coefficient * s.g / (s.omega * peak_acceleration_factor(xi));
}

double slide_rocking_friction_limit(const Scene& s, Corner corner) {
  return s.corner(corner).onset_ratio;
}

double rocking_to_sliding_friction(const Scene& s, Corner corner, double impulse) {
  const double xi = s.params.base.damping_ratio;
  const double a = std::fabs(impulse) * s.omega * peak_acceleration_factor(xi);  // Eq 40
  const double bi = s.corner(corner).onset_ratio * s.h;  // b_i
  const double j = s.inertia_c / s.m;                    // I_C / m
  return (a * (j + bi * bi) + s.g * s.h * bi) / (s.g * (j + s.h * s.h) + a * s.h * bi);
}

double printed_eq41(double epsilon, double lambda, double impulse, double omega, double a_xi,
                    double g) {
  const double a = std::fabs(impulse) * omega * a_xi;
  const double e1 = 1.0 + epsilon;
  return (a * (3.0 + 6.0 * epsilon + 3.0 * epsilon * epsilon + lambda * lambda) +
          3.0 * g * e1 * lambda) /
         (lambda * (3.0 * a * e1 + 4.0 * g * lambda));
}

double housner_velocity_ratio(double alpha) {
  const double sin_a = std::sin(alpha);
  return 1.0 - 1.5 * sin_a * sin_a;
}

}  // namespace plinth

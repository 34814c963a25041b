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

double housner_velocity_ratio(double alpha) {
  const double sin_a = std::sin(alpha);
  return 1.0 - 1.5 * sin_a * sin_a;
}

}  // namespace plinth

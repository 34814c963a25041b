// Closed forms of the paper, for tests and analyses (and their corrections).
#pragma once

#include "plinth/core/scene.h"

namespace plinth {

// Peak of |u'' + u_G''| after an impulse, divided by |I| omega (Eq 35).
//
// The printed Eq 36 does not match Eq 34 (for xi = 0.2 it gives 0.988; the response peaks at
// 0.821). From Eq 34 the absolute acceleration is
//   u'' + u_G'' = -(I omega / s) e^(-xi omega t) sin(omega_d t + 2 asin(xi)),  s = sqrt(1-xi^2)
// whose first extremum lies at omega_d t* = acos(xi) - 2 asin(xi), positive for xi < 1/2; so
//   a(xi) = exp(-(xi / s)(acos(xi) - 2 asin(xi)))   for 0 <= xi <= 1/2,
//   a(xi) = 2 xi                                       for 1/2 < xi < 1 (peak at t = 0+).
[[nodiscard]] double peak_acceleration_factor(double xi);

// Eq 36 exactly as printed, kept to show the discrepancy in the tests and docs.
[[nodiscard]] double printed_peak_acceleration_factor(double xi);

// Eq 34: the base displacement after an impulse I (u'(0+) = I), full contact, m.
[[nodiscard]] double impulse_response_displacement(const Scene& s, double impulse, double t);

// Eq 37 (with the corrected a(xi)): the smallest |I| that starts rocking about `corner` when
// the first acceleration peak points its way (I < 0 for corner 1, I > 0 for corner 2), m/s.
[[nodiscard]] double rocking_impulse_threshold(const Scene& s, Corner corner);

// Housner's ratio of angular velocities after / before an impact of a symmetric homogeneous
// block on fixed ground: 1 - 1.5 sin^2(alpha).
[[nodiscard]] double housner_velocity_ratio(double alpha);

}  // namespace plinth

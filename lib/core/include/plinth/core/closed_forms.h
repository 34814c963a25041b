// Closed forms of the paper, for tests and analyses (and their corrections).
#pragma once

#include "plinth/core/real.h"
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
[[nodiscard]] Real peak_acceleration_factor(Real xi);

// Eq 36 exactly as printed, kept to show the discrepancy in the tests and docs.
[[nodiscard]] Real printed_peak_acceleration_factor(Real xi);

// Eq 34: the base displacement after an impulse I (u'(0+) = I), full contact, m.
[[nodiscard]] Real impulse_response_displacement(const Scene& s, Real impulse, Real t);

// Eq 37 (with the corrected a(xi)): the smallest |I| that starts rocking about `corner` when
// the first acceleration peak points its way (I < 0 for corner 1, I > 0 for corner 2), m/s.
[[nodiscard]] Real rocking_impulse_threshold(const Scene& s, Corner corner);

// Eq 38 (with the corrected a(xi)): the smallest |I| that starts sliding, |I| omega a(xi) =
// mu_s g, i.e. |I| = mu_s T g / (2 pi a(xi)), m/s. Either sign of I; meaningful with friction.
[[nodiscard]] Real sliding_impulse_threshold(const Scene& s);

// Eq 39: the static friction coefficient b_i / h (= (1 + epsilon) / lambda for corner 1) that
// separates the two first motions: below it an impulse starts sliding first (Eq 38 is met
// before Eq 37), above it rocking about `corner` comes first.
[[nodiscard]] Real slide_rocking_friction_limit(const Scene& s, Corner corner);

// Eq 41 in general form: the mu_s below which a block that starts rocking about `corner` after
// the impulse also starts sliding (slide-rocking). From Eq 18 (mu_s Y_i <= |X_i|) with Eqs 12
// and 19 at theta = theta' = 0 and Eq 40, theta'' = (m a h - m g b_i) / I_i, where a =
// |I| omega a(xi) is the peak acceleration of the full-contact response:
//   mu_s = (a (I_C/m + b_i^2) + g h b_i) / (g (I_C/m + h^2) + a h b_i),
// with the scene's own I_C. At a = g b_i / h it equals b_i / h (Eq 39).
[[nodiscard]] Real rocking_to_sliding_friction(const Scene& s, Corner corner, Real impulse);

// Eq 41 exactly as printed: the general form with I_C = m h^2 / 3 (a slender rod 2h tall; the
// homogeneous rectangle has m (b^2 + h^2) / 3), with eps = e / b and lambda = h / b (b
// cancels) and a = |I| omega a(xi):
//   mu_s = [a (3 + 6 eps + 3 eps^2 + lambda^2) + 3 g (1 + eps) lambda]
//          / (lambda [3 a (1 + eps) + 4 g lambda]).
[[nodiscard]] Real printed_eq41(Real epsilon, Real lambda, Real impulse, Real omega, Real a_xi,
                                Real g);

// Housner's ratio of angular velocities after / before an impact of a symmetric homogeneous
// block on fixed ground: 1 - 1.5 sin^2(alpha).
[[nodiscard]] Real housner_velocity_ratio(Real alpha);

}  // namespace plinth

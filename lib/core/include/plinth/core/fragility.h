// A lognormal fragility curve: the probability that a statue collapses under a ground motion of
// peak acceleration PGA,
//   P(collapse | PGA) = Phi(ln(PGA / median) / beta),
// the form in which rocking-block and structural fragilities are usually given (FEMA P-695's
// collapse fragility; plinth-eval fragility fits it per scene, docs/forecast.md). Phi is the
// standard normal CDF. Freestanding: the box may carry its statue's curve.
#pragma once

#include "plinth/core/real.h"

namespace plinth {

// Phi(z) = erfc(-z / sqrt(2)) / 2.
[[nodiscard]] Real standard_normal_cdf(Real z);

struct LognormalFragility {
  Real median_g = 1.0;  // PGA at which half the statues collapse, g (> 0)
  Real beta = 0.5;      // dispersion: the standard deviation of ln(collapse PGA), > 0

  // P(collapse | pga_g): 0 at pga_g <= 0; with beta <= 0 a step at the median (1 from it on).
  [[nodiscard]] Real probability(Real pga_g) const;
  // P(collapse) when the PGA is itself a lognormal guess (median pga_g, scatter sigma_ln, the
  // standard deviation of ln PGA): the curve under that scatter is lognormal again, the
  // dispersions added in quadrature, Phi(ln(pga_g / median) / sqrt(beta^2 + sigma_ln^2)).
  [[nodiscard]] Real probability(Real pga_g, Real sigma_ln) const;
};

}  // namespace plinth

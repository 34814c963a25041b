#include "plinth/core/fragility.h"

#include <cmath>

namespace plinth {

Real standard_normal_cdf(Real z) {
  constexpr Real kInverseSqrt2 = Real(0.70710678118654752440);
  return Real(0.5) * std::erfc(-z * kInverseSqrt2);
}

Real LognormalFragility::probability(Real pga_g) const {
  if (!(pga_g > Real(0))) return Real(0);
  if (!(beta > Real(0))) return pga_g >= median_g ? Real(1) : Real(0);
  return standard_normal_cdf(std::log(pga_g / median_g) / beta);
}

Real LognormalFragility::probability(Real pga_g, Real sigma_ln) const {
  return LognormalFragility{median_g, std::sqrt(beta * beta + sigma_ln * sigma_ln)}.probability(
      pga_g);
}

}  // namespace plinth

// The lognormal fragility curve (fragility.h) against the normal distribution's known values.
#include <gtest/gtest.h>

#include <cmath>

#include "plinth/core/fragility.h"

namespace plinth {
namespace {

TEST(Fragility, NormalCdfHasItsTabulatedValues) {
  EXPECT_DOUBLE_EQ(standard_normal_cdf(0.0), 0.5);
  EXPECT_NEAR(standard_normal_cdf(1.0), 0.8413447460685429, 1e-15);
  EXPECT_NEAR(standard_normal_cdf(-1.959963984540054), 0.025, 1e-15);
  // No cancellation in the lower tail: Phi(-6) to 12 digits.
  EXPECT_NEAR(standard_normal_cdf(-6.0) / 9.865876450377012e-10, 1.0, 1e-12);
}

TEST(Fragility, HalfTheStatuesFallAtTheMedianAndOneSigmaAboveIsPhiOfOne) {
  const LognormalFragility f{0.8, 0.5};
  EXPECT_DOUBLE_EQ(f.probability(0.8), 0.5);
  EXPECT_NEAR(f.probability(0.8 * std::exp(0.5)), 0.8413447460685429, 1e-14);
  EXPECT_NEAR(f.probability(0.8 * std::exp(-1.0)), 0.02275013194817922, 1e-14);
  EXPECT_EQ(f.probability(0.0), 0.0);
  EXPECT_EQ(f.probability(-1.0), 0.0);
  // Monotone in PGA.
  double last = 0.0;
  for (double pga = 0.05; pga < 5.0; pga += 0.05) {
    EXPECT_GE(f.probability(pga), last);
    last = f.probability(pga);
  }
  // No dispersion: a step at the median.
  const LognormalFragility step{1.2, 0.0};
  EXPECT_EQ(step.probability(1.19), 0.0);
  EXPECT_EQ(step.probability(1.2), 1.0);
}

// A guessed PGA: the curve under the guess's scatter, the dispersions in quadrature. Checked
// against the integral of the curve over the guess's lognormal density (midpoint rule in ln PGA).
TEST(LognormalFragility, UnderAGuessesScatterIsTheCurveIntegratedOverIt) {
  const LognormalFragility f{0.6, 0.4};
  for (const double sigma : {0.0, 0.3, 0.65}) {
    for (const double guess : {0.2, 0.6, 1.5}) {
      double integral = 0.0;
      if (sigma == 0.0) {
        integral = f.probability(guess);
      } else {
        constexpr int kSteps = 4000;
        const double dz = 16.0 / kSteps;  // z in [-8, 8]
        for (int i = 0; i < kSteps; ++i) {
          const double z = -8.0 + (i + 0.5) * dz;
          const double density = std::exp(-0.5 * z * z) / std::sqrt(2.0 * 3.14159265358979323846);
          integral += f.probability(guess * std::exp(sigma * z)) * density * dz;
        }
      }
      EXPECT_NEAR(f.probability(guess, sigma), integral, 1e-6) << guess << " " << sigma;
    }
  }
  // A median guess at the curve's median: one half, whatever the scatter.
  EXPECT_DOUBLE_EQ(f.probability(0.6, 0.7), 0.5);
  EXPECT_EQ(f.probability(0.0, 0.5), 0.0);
}

}  // namespace
}  // namespace plinth

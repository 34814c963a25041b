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

}  // namespace
}  // namespace plinth

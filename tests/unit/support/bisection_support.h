// Shared helper of the closed-form test suites: a predicted threshold checked by bisection.
#pragma once

#include <gtest/gtest.h>

#include "test_support.h"

namespace plinth::testing {

// `occurs` is monotone: `predicted` is the threshold it should switch at. Checks that it does
// not occur at low_factor * predicted and does at high_factor * predicted (fatal failures,
// wrap the call in ASSERT_NO_FATAL_FAILURE), then bisects to 1e-8 of `predicted` and expects
// the threshold found within 1e-6 of it.
template <typename Predicate>
void expect_threshold_by_bisection(Predicate occurs, double predicted, double low_factor,
                                   double high_factor) {
  const double low = low_factor * predicted;
  const double high = high_factor * predicted;
  ASSERT_FALSE(occurs(low));
  ASSERT_TRUE(occurs(high));
  const double found = bisect_threshold(occurs, low, high, 1e-8 * predicted);
  EXPECT_NEAR(found, predicted, 1e-6 * predicted);
}

}  // namespace plinth::testing

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "plinth/core/excitation.h"

namespace plinth {
namespace {

TEST(SampledSignal, InterpolatesLinearlyBetweenSamples) {
  const double values[] = {0.0, 1.0, -1.0, 3.0};
  const SampledSignal s{values, 4, 0.5};
  EXPECT_DOUBLE_EQ(s.at(0.0), 0.0);
  EXPECT_DOUBLE_EQ(s.at(0.25), 0.5);
  EXPECT_DOUBLE_EQ(s.at(0.5), 1.0);
  EXPECT_DOUBLE_EQ(s.at(0.75), 0.0);
  EXPECT_DOUBLE_EQ(s.at(1.25), 1.0);
  EXPECT_DOUBLE_EQ(s.at(1.5), 3.0);
  EXPECT_DOUBLE_EQ(s.duration(), 1.5);
}

TEST(SampledSignal, IsZeroOutsideTheRecord) {
  const double values[] = {2.0, 2.0};
  const SampledSignal s{values, 2, 0.1};
  EXPECT_EQ(s.at(-1e-9), 0.0);
  EXPECT_EQ(s.at(0.1 + 1e-9), 0.0);
  EXPECT_EQ(SampledSignal{}.at(0.0), 0.0);
}

TEST(Excitation, RecordIsScaledByGamma) {
  const double h[] = {0.0, 2.0};
  const double v[] = {1.0, 1.0};
  const Excitation e = Excitation::record({h, 2, 1.0}, {v, 2, 1.0}, -2.5);
  EXPECT_DOUBLE_EQ(e.at(0.5).horizontal, -2.5);
  EXPECT_DOUBLE_EQ(e.at(0.5).vertical, -2.5);
  EXPECT_DOUBLE_EQ(e.duration(), 1.0);
}

TEST(Excitation, PulsesLastOnePeriod) {
  const Excitation sine = Excitation::sine_pulse(3.0, 0.4);
  EXPECT_NEAR(sine.at(0.1).horizontal, 3.0, 1e-12);
  EXPECT_NEAR(sine.at(0.3).horizontal, -3.0, 1e-12);
  EXPECT_EQ(sine.at(0.41).horizontal, 0.0);
  EXPECT_EQ(sine.at(-0.01).horizontal, 0.0);
  const Excitation cosine = Excitation::cosine_pulse(3.0, 0.4);
  EXPECT_NEAR(cosine.at(0.0).horizontal, 3.0, 1e-12);
  EXPECT_NEAR(cosine.at(0.2).horizontal, -3.0, 1e-12);
  EXPECT_EQ(cosine.at(0.5).horizontal, 0.0);
  EXPECT_DOUBLE_EQ(cosine.duration(), 0.4);
}

TEST(Excitation, NoneIsStill) {
  const Excitation e = Excitation::none();
  EXPECT_EQ(e.at(1.0).horizontal, 0.0);
  EXPECT_EQ(e.at(1.0).vertical, 0.0);
  EXPECT_EQ(e.duration(), 0.0);
}

}  // namespace
}  // namespace plinth

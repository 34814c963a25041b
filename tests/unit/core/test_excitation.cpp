#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
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

TEST(GroundStream, InterpolatesBetweenTheTwoNewestSamplesHeldPastThem) {
  GroundStream s;
  s.reset(0.01, {1.0, -1.0});
  EXPECT_EQ(s.at(0.0).horizontal, 1.0);  // sample 0 held until sample 1 arrives
  s.push({3.0, 1.0});                    // sample 1, t = 0.01
  EXPECT_DOUBLE_EQ(s.at(0.0025).horizontal, 1.5);
  EXPECT_DOUBLE_EQ(s.at(0.0075).vertical, 0.5);
  EXPECT_EQ(s.at(-0.5).horizontal, 1.0);  // before the interval: the older sample
  EXPECT_EQ(s.at(0.5).horizontal, 3.0);   // past it: the newer one
}

// The weight is the old double expression, (t - start) / period clamped to [0, 1], to the last
// bit in a double build (the host's decisions unchanged), hours into a run.
TEST(GroundStream, WeightIsTheDoubleFractionBitForBit) {
  for (const double rate_hz : {100.0, 200.0, 344.8275862068966, 1000.0}) {
    GroundStream s;
    s.reset(1.0 / rate_hz, {});
    const int steps = 4;
    const Time step = s.period / steps;
    for (std::int64_t n = 0; n < 200000; ++n) {
      if (n % steps == 0) s.push({static_cast<Real>(n % 7), 0.0});
      for (std::int64_t i : {n, n + 1, n + 3600 * 1000}) {
        const Time t = static_cast<Time>(i) * step;
        const Time fraction = (t - s.start_time) / s.period;
        const double w = fraction < 0.0 ? 0.0 : (fraction > 1.0 ? 1.0 : fraction);
        ASSERT_EQ(s.at(t).horizontal,
                  s.previous.horizontal + w * (s.latest.horizontal - s.previous.horizontal))
            << "rate " << rate_hz << " step " << i;
      }
    }
  }
}

}  // namespace
}  // namespace plinth

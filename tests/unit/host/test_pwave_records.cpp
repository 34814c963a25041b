// Three-component records for the P-wave stage (pwave_records.h): joining a vertical file,
// the AIC pick and the strong motion's onset on synthetic records, and the predictor's fit
// against a known line.
#include "plinth/host/pwave_records.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "plinth/host/input_error.h"

namespace plinth::host {
namespace {

Record series(double dt, std::size_t n, double value) {
  Record r;
  r.name = "synthetic";
  r.dt = dt;
  r.horizontal.assign(n, value);
  return r;
}

TEST(AttachVertical, CutsBothToTheSharedSpanAndRefusesAnotherRate) {
  Record h = series(0.005, 100, 1.0);
  attach_vertical(h, series(0.005, 97, 2.0), "v.AT2");
  EXPECT_EQ(h.horizontal.size(), 97U);
  EXPECT_EQ(h.vertical.size(), 97U);
  EXPECT_EQ(h.vertical.front(), 2.0);
  Record longer = series(0.005, 50, 1.0);
  attach_vertical(longer, series(0.005, 80, 2.0), "v.AT2");
  EXPECT_EQ(longer.horizontal.size(), 50U);
  EXPECT_EQ(longer.vertical.size(), 50U);
  try {
    Record other = series(0.005, 50, 1.0);
    attach_vertical(other, series(0.01, 50, 2.0), "v.AT2");
    ADD_FAILURE() << "a vertical at another rate was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("v.AT2: sampling interval 0.01 s differs"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(attach_vertical(h, series(0.005, 97, 2.0), "again.AT2"), InputError);
}

TEST(AicPick, FindsWhereTheLouderPartBegins) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (const std::size_t onset : {200U, 1000U, 1700U}) {
    std::vector<double> x(2000);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = noise(rng) * (i < onset ? 1.0 : 8.0);
    EXPECT_NEAR(static_cast<double>(aic_pick(x)), static_cast<double>(onset), 5.0);
  }
  EXPECT_EQ(aic_pick(std::vector<double>{1.0, 2.0}), 0U);
}

// 3 s of quiet, a vertical P wave from 3 s, horizontal strong motion from 8 s.
Record synthetic_quake(double scale) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, 1e-3);
  Record r;
  r.dt = 0.01;
  for (int i = 0; i < 2000; ++i) {
    const double t = i * r.dt;
    const double p = t >= 3.0 ? 0.2 * std::sin(2.0 * 3.14159 * 2.0 * (t - 3.0)) : 0.0;
    const double s = t >= 8.0 ? 2.0 * std::sin(2.0 * 3.14159 * 1.0 * (t - 8.0)) : 0.0;
    r.horizontal.push_back(scale * (noise(rng) + 0.2 * p + s));
    r.vertical.push_back(scale * (noise(rng) + p + 0.3 * s));
  }
  return r;
}

TEST(RecordPhases, PickThePWaveAndTheStrongMotionWhateverTheScale) {
  for (const double scale : {1.0, 7.5}) {
    const RecordPhases phases = record_phases(synthetic_quake(scale));
    // 0.2 x 2 = 0.4 is first reached a quarter-period's arcsine after 8 s: 8.032 s.
    EXPECT_NEAR(phases.strong_motion_s, 8.0 + std::asin(0.2) / (2.0 * 3.14159), 0.011);
    EXPECT_NEAR(phases.p_pick_s, 3.0, 0.03);
    EXPECT_NEAR(phases.p_lead_s(), 5.03, 0.05);
  }
  // A record that begins in its strong motion has no pick.
  Record late = synthetic_quake(1.0);
  late.horizontal.erase(late.horizontal.begin(), late.horizontal.begin() + 750);
  late.vertical.erase(late.vertical.begin(), late.vertical.begin() + 750);
  const RecordPhases phases = record_phases(late);
  EXPECT_LT(phases.strong_motion_s, 1.0);
  EXPECT_EQ(phases.p_pick_s, -1.0);
  EXPECT_EQ(phases.p_lead_s(), 0.0);
  // Without a vertical: the strong motion only.
  Record horizontal = synthetic_quake(1.0);
  horizontal.vertical.clear();
  EXPECT_EQ(record_phases(horizontal).p_pick_s, -1.0);
}

TEST(PWaveFit, RecoversAKnownLinePerWindowAndBorrowsWhereDataAreShort) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::uniform_real_distribution<double> tau(std::log(0.3), std::log(3.0));
  std::vector<PWaveWindowSample> samples;
  for (int i = 0; i < 400; ++i) {
    const double x = tau(rng);
    samples.push_back({1.0, 3.0 + 0.4 * x + noise(rng), x});
    samples.push_back({2.0, 2.0 - 0.2 * x + noise(rng), x});
  }
  samples.push_back({3.0, 9.0, 0.0});  // one sample: not enough for a fit
  const std::vector<PWaveFitPoint> t = fit_pwave_predictor(samples, {0.5, 1.0, 2.0, 3.0});
  ASSERT_EQ(t.size(), 4U);
  // The standard errors at n = 400, sigma 0.5, spread of x ~0.66: c1 0.04, c0 0.03.
  EXPECT_NEAR(t[1].c0, 3.0, 0.1);
  EXPECT_NEAR(t[1].c1, 0.4, 0.12);
  EXPECT_NEAR(t[1].sigma, 0.5, 0.05);
  EXPECT_EQ(t[1].samples, 400U);
  EXPECT_FALSE(t[1].borrowed);
  EXPECT_NEAR(t[2].c0, 2.0, 0.1);
  EXPECT_NEAR(t[2].c1, -0.2, 0.12);
  // 0.5 s (no sample) borrows 1 s's line; 3 s (one sample) borrows 2 s's.
  EXPECT_TRUE(t[0].borrowed);
  EXPECT_EQ(t[0].c0, t[1].c0);
  EXPECT_EQ(t[0].window_s, 0.5);
  EXPECT_TRUE(t[3].borrowed);
  EXPECT_EQ(t[3].c0, t[2].c0);
  EXPECT_EQ(t[3].samples, 1U);
  EXPECT_THROW((void)fit_pwave_predictor({{1.0, 1.0, 0.0}}, {1.0}), InputError);
}

// Leave one earthquake out: with c0 alone, each group's residuals are its level less the
// other groups' mean (A 1, B 3, C 2: -1.5, +1.5, 0); a line every group follows is predicted
// exactly whichever group is left out.
TEST(PWaveCrossValidation, ResidualsOnEachGroupUnderTheFitWithoutIt) {
  std::vector<PWaveWindowSample> samples;
  std::vector<std::string> group;
  for (const auto& [name, level] : {std::pair{"A", 1.0}, {"B", 3.0}, {"C", 2.0}}) {
    for (int i = 0; i < 5; ++i) {
      samples.push_back({1.0, level, 0.0});
      group.emplace_back(name);
      const double x = 0.1 * i - 0.3 * level;  // the line y = 2 + 0.5 x at 2 s
      samples.push_back({2.0, 2.0 + 0.5 * x, x});
      group.emplace_back(name);
    }
  }
  const PWaveCrossValidation cv = cross_validate_pwave_predictor(samples, group, {1.0, 2.0});
  ASSERT_EQ(cv.groups, (std::vector<std::string>{"A", "B", "C"}));
  ASSERT_EQ(cv.pooled.size(), 2U);
  EXPECT_EQ(cv.pooled[0].samples, 15U);
  EXPECT_NEAR(cv.pooled[0].c0, 2.0, 1e-12);  // the fit on all samples
  EXPECT_NEAR(cv.pooled[0].sigma, std::sqrt(1.5), 1e-12);  // (5 x 1.5² x 2) / 15
  EXPECT_NEAR(cv.rms[0][0], 1.5, 1e-12);
  EXPECT_NEAR(cv.rms[1][0], 1.5, 1e-12);
  EXPECT_NEAR(cv.rms[2][0], 0.0, 1e-12);
  EXPECT_EQ(cv.count[2][0], 5U);
  EXPECT_NEAR(cv.pooled[1].c1, 0.5, 1e-12);
  EXPECT_NEAR(cv.pooled[1].sigma, 0.0, 1e-12);
  EXPECT_THROW((void)cross_validate_pwave_predictor(samples, std::vector<std::string>(
                                                                 samples.size(), "A"),
                                                    {1.0, 2.0}),
               InputError);  // one earthquake
  EXPECT_THROW((void)cross_validate_pwave_predictor(samples, {"A"}, {1.0, 2.0}), InputError);
}

}  // namespace
}  // namespace plinth::host

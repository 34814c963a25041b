// The lognormal fragility's maximum-likelihood fit (fragility_fit.h): closed forms of small cases,
// recovery of a known curve from censored and gridded draws within sampling error (fixed seed),
// the confidence interval's coverage, and the data that allow no fit.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "plinth/host/fragility_fit.h"

namespace plinth::host {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

CollapseIntensity exactly(double g) { return {g, g}; }

// Exact intensities without censoring: the maximum is the mean and the (1/n) standard deviation
// of ln(PGA). ln of 0.5, 1, 2 g: -ln 2, 0, ln 2, so median 1 g and beta = ln 2 sqrt(2/3).
TEST(FragilityFit, ExactIntensitiesGiveTheLogMeanAndSpread) {
  const std::vector<CollapseIntensity> cases{exactly(0.5), exactly(1.0), exactly(2.0)};
  const FragilityFit f = fit_lognormal_fragility(cases);
  ASSERT_TRUE(f.fitted()) << f.no_fit;
  EXPECT_NEAR(f.curve.median_g, 1.0, 1e-8);
  EXPECT_NEAR(f.curve.beta, std::log(2.0) * std::sqrt(2.0 / 3.0), 1e-8);
  EXPECT_EQ(f.cases, 3);
  EXPECT_EQ(f.collapsed, 3);
  // The observed information of a normal sample: se(mu) = beta / sqrt(n), se(beta) =
  // beta / sqrt(2n).
  EXPECT_NEAR(f.log_median_se, f.curve.beta / std::sqrt(3.0), 1e-5);
  EXPECT_NEAR(f.beta_se, f.curve.beta / std::sqrt(6.0), 1e-5);
  EXPECT_LT(f.median_ci95_low_g, 1.0);
  EXPECT_GT(f.median_ci95_high_g, 1.0);
}

// Two intervals symmetric in ln(PGA), (e^-2, e^-1] and (e^1, e^2]: mu = 0 by symmetry, and
// Phi(2a) - Phi(a) with a = 1/beta is largest where 2 phi(2a) = phi(a), i.e. a^2 = (2/3) ln 2:
// beta = 1 / sqrt((2/3) ln 2) = 1.4710685.
TEST(FragilityFit, SymmetricIntervalsHaveAClosedForm) {
  const std::vector<CollapseIntensity> cases{{std::exp(-2.0), std::exp(-1.0)},
                                             {std::exp(1.0), std::exp(2.0)}};
  const FragilityFit f = fit_lognormal_fragility(cases);
  ASSERT_TRUE(f.fitted()) << f.no_fit;
  EXPECT_NEAR(f.curve.median_g, 1.0, 1e-8);
  EXPECT_NEAR(f.curve.beta, 1.0 / std::sqrt(2.0 / 3.0 * std::log(2.0)), 1e-7);
  const double a = 1.0 / f.curve.beta;
  EXPECT_NEAR(f.log_likelihood,
              2.0 * std::log(0.5 * std::erfc(-2.0 * a / std::sqrt(2.0)) -
                             0.5 * std::erfc(-a / std::sqrt(2.0))),
              1e-10);
}

// A right-censored case moves the median up: 0.5 and 1 g exact and one case standing at 2 g.
// The maximum satisfies the score equations, checked here by their closed form: with z_i the
// exact cases' standardized values and z_c the censoring point's, h = phi(z_c) / (1 - Phi(z_c)),
//   sum z_i + h = 0   and   sum (z_i^2 - 1) + z_c h = 0.
TEST(FragilityFit, ACensoredCaseSatisfiesTheScoreEquations) {
  const std::vector<CollapseIntensity> cases{exactly(0.5), exactly(1.0), {2.0, kInfinity}};
  const FragilityFit f = fit_lognormal_fragility(cases);
  ASSERT_TRUE(f.fitted()) << f.no_fit;
  const double mu = std::log(f.curve.median_g);
  const double beta = f.curve.beta;
  const double z1 = (std::log(0.5) - mu) / beta;
  const double z2 = (std::log(1.0) - mu) / beta;
  const double zc = (std::log(2.0) - mu) / beta;
  const double density = std::exp(-0.5 * zc * zc) / std::sqrt(2.0 * M_PI);
  const double h = density / (0.5 * std::erfc(zc / std::sqrt(2.0)));
  EXPECT_NEAR(z1 + z2 + h, 0.0, 1e-7);
  EXPECT_NEAR(z1 * z1 - 1.0 + z2 * z2 - 1.0 + zc * h, 0.0, 1e-7);
  EXPECT_GT(f.curve.median_g, std::sqrt(0.5));  // above the two collapses' own median
  EXPECT_EQ(f.collapsed, 2);
}

// n cases whose collapse intensities are drawn from a known curve, seen as plinth-eval sees them:
// run up a grid from `from` to `top` in `steps` points, first collapse at the first point at or
// above the intensity (the interval from the point below), or standing at the top.
std::vector<CollapseIntensity> gridded_draws(const LognormalFragility& truth, int n, double from,
                                             double top, int steps, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<CollapseIntensity> cases;
  for (int i = 0; i < n; ++i) {
    const double intensity = truth.median_g * std::exp(truth.beta * normal(rng));
    CollapseIntensity c{top, kInfinity};
    for (int k = 0; k < steps; ++k) {
      const double point = from + (top - from) * k / (steps - 1);
      if (intensity <= point) {
        c = {k == 0 ? 0.0 : from + (top - from) * (k - 1) / (steps - 1), point};
        break;
      }
    }
    cases.push_back(c);
  }
  return cases;
}

TEST(FragilityFit, RecoversAKnownCurveFromGriddedCensoredDraws) {
  // plinth-eval's default grid (0.2 to 2.5 g, 12 points) and a statue like the eval scenes'.
  const LognormalFragility truth{0.8, 0.5};
  std::mt19937_64 rng(2026);
  const std::vector<CollapseIntensity> cases = gridded_draws(truth, 400, 0.2, 2.5, 12, rng);
  const FragilityFit f = fit_lognormal_fragility(cases);
  ASSERT_TRUE(f.fitted()) << f.no_fit;
  EXPECT_LT(f.collapsed, 400);  // some stood up to 2.5 g: censored
  // Within three standard errors, and those near a full sample's (beta / sqrt(n) = 0.025, beta /
  // sqrt(2 n) = 0.018): the grid's intervals cost little information.
  EXPECT_NEAR(std::log(f.curve.median_g), std::log(truth.median_g), 3.0 * f.log_median_se);
  EXPECT_NEAR(f.curve.beta, truth.beta, 3.0 * f.beta_se);
  EXPECT_GT(f.log_median_se, 0.02);
  EXPECT_LT(f.log_median_se, 0.035);
  EXPECT_GT(f.beta_se, 0.015);
  EXPECT_LT(f.beta_se, 0.03);
  // Taking each collapse at its grid point instead reads the intensities high, by up to a step:
  // the median comes out above the interval fit's.
  std::vector<CollapseIntensity> at_points;
  for (const CollapseIntensity& c : cases) {
    at_points.push_back(c.collapsed() ? exactly(c.upper_g) : c);
  }
  const FragilityFit high = fit_lognormal_fragility(at_points);
  ASSERT_TRUE(high.fitted()) << high.no_fit;
  EXPECT_GT(high.curve.median_g, f.curve.median_g);
}

TEST(FragilityFit, HeavyCensoringStillRecoversTheCurve) {
  // A fragile statue's grid stopping at its median: half the cases stand at the top.
  const LognormalFragility truth{1.0, 0.4};
  std::mt19937_64 rng(7);
  const FragilityFit f = fit_lognormal_fragility(gridded_draws(truth, 300, 0.2, 1.0, 9, rng));
  ASSERT_TRUE(f.fitted()) << f.no_fit;
  EXPECT_NEAR(f.collapsed, 150, 30);
  EXPECT_NEAR(std::log(f.curve.median_g), 0.0, 3.0 * f.log_median_se);
  EXPECT_NEAR(f.curve.beta, truth.beta, 3.0 * f.beta_se);
}

// The 95 % interval of the median holds the true median in about 95 % of samples (200 samples of
// 40 cases; binomial spread of the count about 3 in 200).
TEST(FragilityFit, TheMediansIntervalCoversAsOften) {
  const LognormalFragility truth{0.75, 0.5};
  std::mt19937_64 rng(11);
  int covered = 0;
  int fitted = 0;
  for (int sample = 0; sample < 200; ++sample) {
    const FragilityFit f = fit_lognormal_fragility(gridded_draws(truth, 40, 0.2, 2.5, 12, rng));
    if (!f.fitted()) continue;
    ++fitted;
    covered += f.median_ci95_low_g <= truth.median_g && truth.median_g <= f.median_ci95_high_g;
  }
  EXPECT_EQ(fitted, 200);
  EXPECT_GE(covered, 180);  // 90 %
  EXPECT_LE(covered, 198);  // 99 %
}

// Every case collapsing is no edge for the fit, so long as the intensities spread.
TEST(FragilityFit, AllCollapsingIsFitted) {
  const std::vector<CollapseIntensity> cases{{0.2, 0.4}, {0.4, 0.6}, {0.4, 0.6}, {0.6, 0.8}};
  const FragilityFit f = fit_lognormal_fragility(cases);
  ASSERT_TRUE(f.fitted()) << f.no_fit;
  EXPECT_EQ(f.collapsed, 4);
  EXPECT_GT(f.curve.median_g, 0.4);
  EXPECT_LT(f.curve.median_g, 0.6);
}

std::string no_fit(const std::vector<CollapseIntensity>& cases) {
  const FragilityFit f = fit_lognormal_fragility(cases);
  EXPECT_FALSE(f.fitted()) << "fitted: median " << f.curve.median_g << ", beta " << f.curve.beta;
  return f.no_fit;
}

TEST(FragilityFit, DataWithoutAFiniteMaximumAreRefusedWithTheReason) {
  EXPECT_EQ(no_fit({}), "no cases");
  EXPECT_EQ(no_fit({{2.5, kInfinity}, {2.5, kInfinity}, {2.5, kInfinity}}),
            "none of the 3 cases collapsed up to 2.5 g: the median is above it");
  EXPECT_EQ(no_fit({{0.0, 0.2}, {0.0, 0.2}}),
            "all 2 cases collapsed at or below 0.2 g, the lowest intensity tried: the median is "
            "below it");
  EXPECT_EQ(no_fit({{0.4, 0.6}}),
            "one case: a median and a dispersion need at least two cases whose collapse "
            "intensities differ");
  EXPECT_EQ(no_fit({exactly(0.7)}),
            "one case: a median and a dispersion need at least two cases whose collapse "
            "intensities differ");
  EXPECT_EQ(no_fit({{0.4, 0.6}, {0.4, 0.6}, {0.5, kInfinity}}),
            "the collapse intensities of all 3 cases meet at 0.5 g (every one between 0.4 and 0.6 "
            "g): the dispersion beta cannot be estimated (it tends to 0; a finer grid could tell "
            "them apart)");
  EXPECT_NE(no_fit({exactly(0.7), exactly(0.7)}).find("meet at 0.7 g"), std::string::npos);
  // Two neighbouring grid steps: the ranges touch at 0.4 g, where a step of beta -> 0 puts 7/8 of
  // the probability below and 1/8 above, the likelihood's supremum.
  std::vector<CollapseIntensity> neighbours(7, CollapseIntensity{0.2, 0.4});
  neighbours.push_back({0.4, 0.6});
  EXPECT_NE(no_fit(neighbours).find("meet at 0.4 g (every one between 0.2 and 0.6 g)"),
            std::string::npos);
  // Stood at the top 0.6 g, or collapsed in the step below it: the same.
  EXPECT_NE(no_fit({{0.4, 0.6}, {0.6, kInfinity}}).find("meet at 0.6 g"), std::string::npos);
  EXPECT_NE(no_fit({exactly(0.5), {0.5, 0.7}}).find("meet at 0.5 g"), std::string::npos);
  EXPECT_NE(no_fit({{0.0, 0.2}, {2.5, kInfinity}}).find("bounded on both sides"),
            std::string::npos);
  EXPECT_EQ(no_fit({{0.6, 0.4}, exactly(1.0)}), "case 1: not an intensity range: (0.6, 0.4] g");
  EXPECT_EQ(no_fit({exactly(0.0), exactly(1.0)}), "case 1: not an intensity range: (0, 0] g");
}

}  // namespace
}  // namespace plinth::host

#include "plinth/host/fragility_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

namespace plinth::host {
namespace {

constexpr double kInverseSqrt2 = 0.70710678118654752440;
constexpr double kInverseSqrt2Pi = 0.39894228040143267794;
constexpr double kZ95 = 1.959963984540054;  // the normal's 97.5th percentile
constexpr int kMaxIterations = 200;
// Of ln(median) and ln(beta): a millionth of the median and of beta, far below any sampling error.
constexpr double kStepTolerance = 1e-6;
// Beyond these the likelihood has no finite maximum (the checks before the fit should catch it).
constexpr double kMaxBeta = 50.0;
constexpr double kMinBeta = 1e-6;
constexpr double kMaxAbsLogMedian = 30.0;

double cdf(double z) { return 0.5 * std::erfc(-z * kInverseSqrt2); }
double upper_tail(double z) { return 0.5 * std::erfc(z * kInverseSqrt2); }
double density(double z) { return std::isinf(z) ? 0.0 : kInverseSqrt2Pi * std::exp(-0.5 * z * z); }
// z * phi(z), 0 at +-infinity.
double z_density(double z) { return std::isinf(z) ? 0.0 : z * density(z); }

std::string g_text(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

struct Parameters {
  double log_median = 0.0;  // mu
  double log_beta = 0.0;    // s = ln(beta)
};

// The log-likelihood and its gradient in (mu, s).
struct Evaluation {
  double log_likelihood = 0.0;
  std::array<double, 2> gradient{0.0, 0.0};
};

Evaluation evaluate(std::span<const CollapseIntensity> cases, const Parameters& p) {
  const double beta = std::exp(p.log_beta);
  Evaluation e;
  for (const CollapseIntensity& c : cases) {
    if (c.lower_g == c.upper_g) {
      const double z = (std::log(c.lower_g) - p.log_median) / beta;
      e.log_likelihood += -0.5 * z * z + std::log(kInverseSqrt2Pi) - p.log_beta;
      e.gradient[0] += z / beta;
      e.gradient[1] += z * z - 1.0;
      continue;
    }
    const double inf = std::numeric_limits<double>::infinity();
    const double a = c.lower_g > 0.0 ? (std::log(c.lower_g) - p.log_median) / beta : -inf;
    const double b = c.collapsed() ? (std::log(c.upper_g) - p.log_median) / beta : inf;
    // Phi(b) - Phi(a), from the upper tails when both lie above 0 (no cancellation there).
    const double probability = a > 0.0 ? upper_tail(a) - upper_tail(b) : cdf(b) - cdf(a);
    if (!(probability > 0.0)) {
      e.log_likelihood = -inf;
      return e;
    }
    e.log_likelihood += std::log(probability);
    e.gradient[0] += (density(a) - density(b)) / (beta * probability);
    e.gradient[1] += (z_density(a) - z_density(b)) / probability;
  }
  return e;
}

// The Hessian in (mu, s) by central differences of the analytic gradient.
std::array<std::array<double, 2>, 2> hessian(std::span<const CollapseIntensity> cases,
                                             const Parameters& p) {
  constexpr double kStep = 1e-5;
  std::array<std::array<double, 2>, 2> h{};
  for (std::size_t j = 0; j < 2; ++j) {
    Parameters up = p;
    Parameters down = p;
    (j == 0 ? up.log_median : up.log_beta) += kStep;
    (j == 0 ? down.log_median : down.log_beta) -= kStep;
    const Evaluation eu = evaluate(cases, up);
    const Evaluation ed = evaluate(cases, down);
    for (std::size_t i = 0; i < 2; ++i) h[i][j] = (eu.gradient[i] - ed.gradient[i]) / (2.0 * kStep);
  }
  const double off = 0.5 * (h[0][1] + h[1][0]);
  h[0][1] = off;
  h[1][0] = off;
  return h;
}

// Why these cases allow no finite maximum, or "" (see the header).
std::string refusal(std::span<const CollapseIntensity> cases) {
  const std::string n = std::to_string(cases.size());
  if (cases.empty()) return "no cases";
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const CollapseIntensity& c = cases[i];
    if (!(c.lower_g >= 0.0) || !std::isfinite(c.lower_g) || !(c.upper_g >= c.lower_g) ||
        !(c.upper_g > 0.0)) {
      return "case " + std::to_string(i + 1) + ": not an intensity range: (" + g_text(c.lower_g) +
             ", " + g_text(c.upper_g) + "] g";
    }
  }
  const auto collapsed = std::count_if(cases.begin(), cases.end(),
                                       [](const CollapseIntensity& c) { return c.collapsed(); });
  if (collapsed == 0) {
    double top = cases[0].lower_g;
    for (const CollapseIntensity& c : cases) top = std::min(top, c.lower_g);
    return "none of the " + n + " cases collapsed up to " + g_text(top) +
           " g: the median is above it";
  }
  const bool all_below = std::all_of(cases.begin(), cases.end(),
                                     [](const CollapseIntensity& c) { return c.lower_g == 0.0; });
  if (all_below) {
    double lowest = 0.0;
    for (const CollapseIntensity& c : cases) lowest = std::max(lowest, c.upper_g);
    return "all " + n + " cases collapsed at or below " + g_text(lowest) +
           " g, the lowest intensity tried: the median is below it";
  }
  // A point in every case's closed range, [highest lower, lowest upper]: with the median there and
  // beta tending to 0 the likelihood grows to its supremum (each range taking all, or a fixed part
  // of, the probability), so no beta > 0 is the maximum. On a grid: every collapse within two
  // neighbouring steps.
  double lowest_upper = std::numeric_limits<double>::infinity();
  double highest_lower = 0.0;
  double lowest = std::numeric_limits<double>::infinity();
  double highest = 0.0;
  for (const CollapseIntensity& c : cases) {
    lowest_upper = std::min(lowest_upper, c.upper_g);
    highest_lower = std::max(highest_lower, c.lower_g);
    lowest = std::min(lowest, c.lower_g);
    highest = std::max(highest, c.collapsed() ? c.upper_g : c.lower_g);
  }
  if (highest_lower <= lowest_upper && cases.size() == 1) {
    return "one case: a median and a dispersion need at least two cases whose collapse "
           "intensities differ";
  }
  if (highest_lower <= lowest_upper) {
    return "the collapse intensities of all " + n + " cases meet at " + g_text(highest_lower) +
           " g (every one between " + g_text(lowest) + " and " + g_text(highest) +
           " g): the dispersion beta cannot be estimated (it tends to 0; a finer grid could "
           "tell them apart)";
  }
  const bool bounded = std::any_of(cases.begin(), cases.end(), [](const CollapseIntensity& c) {
    return c.lower_g > 0.0 && c.collapsed();
  });
  if (!bounded) {
    return "no case's collapse intensity is bounded on both sides (each collapsed below the "
           "lowest intensity tried or stood up to the top): the dispersion beta cannot be "
           "estimated (it tends to infinity)";
  }
  return "";
}

// A starting point: the mean and spread of each case's intensity taken at its middle.
Parameters start(std::span<const CollapseIntensity> cases) {
  std::vector<double> x;
  for (const CollapseIntensity& c : cases) {
    if (c.lower_g == 0.0) {
      x.push_back(std::log(c.upper_g) - 0.5);
    } else if (!c.collapsed()) {
      x.push_back(std::log(c.lower_g) + 0.5);
    } else {
      x.push_back(0.5 * (std::log(c.lower_g) + std::log(c.upper_g)));
    }
  }
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double variance = 0.0;
  for (double v : x) variance += (v - mean) * (v - mean);
  variance /= static_cast<double>(x.size());
  return {mean, std::log(std::max(std::sqrt(variance), 0.2))};
}

}  // namespace

FragilityFit fit_lognormal_fragility(std::span<const CollapseIntensity> cases) {
  FragilityFit fit;
  fit.cases = static_cast<int>(cases.size());
  fit.no_fit = refusal(cases);
  fit.collapsed = static_cast<int>(std::count_if(
      cases.begin(), cases.end(), [](const CollapseIntensity& c) { return c.collapsed(); }));
  if (!fit.fitted()) return fit;
  Parameters p = start(cases);
  Evaluation e = evaluate(cases, p);
  bool converged = false;
  for (fit.iterations = 0; fit.iterations < kMaxIterations; ++fit.iterations) {
    const auto h = hessian(cases, p);
    const double det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    const bool concave = h[0][0] < 0.0 && det > 0.0;
    std::array<double, 2> d{};
    if (concave) {  // Newton's step, -H^-1 g
      d[0] = -(h[1][1] * e.gradient[0] - h[0][1] * e.gradient[1]) / det;
      d[1] = -(-h[1][0] * e.gradient[0] + h[0][0] * e.gradient[1]) / det;
    } else {  // otherwise uphill
      d = e.gradient;
    }
    const double length = std::hypot(d[0], d[1]);
    // Done when Newton's step would move ln(median) and ln(beta) by less than kStepTolerance: the
    // likelihood's rounding stops a line search short of 0 gradient (about 1e-9 from it), so that
    // step is taken whole, without one.
    if (concave && length < kStepTolerance) {  // the last step, whole: quadratic convergence
      p = {p.log_median + d[0], p.log_beta + d[1]};
      e = evaluate(cases, p);
      converged = true;
      break;
    }
    if (length > 1.0) {  // at most one unit of ln(PGA) or ln(beta) a step
      d[0] /= length;
      d[1] /= length;
    }
    double t = 1.0;
    Parameters next{};
    Evaluation en{};
    for (;;) {
      next = {p.log_median + t * d[0], p.log_beta + t * d[1]};
      en = evaluate(cases, next);
      if (en.log_likelihood >= e.log_likelihood || t < 1e-12) break;
      t *= 0.5;
    }
    if (!(en.log_likelihood >= e.log_likelihood)) {  // nothing uphill: at the maximum's rounding
      converged = concave && length < 100.0 * kStepTolerance;
      break;
    }
    p = next;
    e = en;
    if (std::exp(p.log_beta) > kMaxBeta || std::exp(p.log_beta) < kMinBeta ||
        std::abs(p.log_median) > kMaxAbsLogMedian) {
      break;
    }
  }
  const double beta = std::exp(p.log_beta);
  if (!converged || beta > kMaxBeta || beta < kMinBeta ||
      std::abs(p.log_median) > kMaxAbsLogMedian) {
    fit.no_fit = "the likelihood has no finite maximum (after " +
                 std::to_string(fit.iterations) + " steps: median " +
                 g_text(std::exp(p.log_median)) + " g, beta " + g_text(beta) + ")";
    return fit;
  }
  // Standard errors: the inverse of the observed information -H at the maximum.
  const auto h = hessian(cases, p);
  const double det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
  if (!(h[0][0] < 0.0 && det > 0.0)) {
    fit.no_fit = "the likelihood is flat or not a maximum at median " +
                 g_text(std::exp(p.log_median)) + " g, beta " + g_text(beta);
    return fit;
  }
  const double var_mu = -h[1][1] / det;
  const double var_s = -h[0][0] / det;
  fit.curve.median_g = std::exp(p.log_median);
  fit.curve.beta = beta;
  fit.log_likelihood = e.log_likelihood;
  fit.log_median_se = std::sqrt(std::max(var_mu, 0.0));
  fit.beta_se = beta * std::sqrt(std::max(var_s, 0.0));
  fit.median_ci95_low_g = std::exp(p.log_median - kZ95 * fit.log_median_se);
  fit.median_ci95_high_g = std::exp(p.log_median + kZ95 * fit.log_median_se);
  return fit;
}

}  // namespace plinth::host

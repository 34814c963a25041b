// The lognormal fragility (plinth/core/fragility.h) fitted by maximum likelihood to the collapse
// intensities of a set of cases, each known only as well as a grid of intensities tells it
// (incremental dynamic analysis, Vamvatsikos & Cornell 2002): a case that first collapses at a
// grid point collapses somewhere above the grid point below it; a case that never collapses up
// to the grid's top is right-censored there. With x = ln(PGA), mu = ln(median), each case adds
//   exact x:           ln(phi((x - mu) / beta) / beta)   (the density, without x's own -ln PGA)
//   in (lower, upper]: ln(Phi((x_upper - mu) / beta) - Phi((x_lower - mu) / beta))
// (lower 0: Phi(-inf) = 0; upper infinite: Phi(+inf) = 1) to the log-likelihood, maximised over
// (mu, ln beta) by Newton's method. The standard errors are the observed information's.
#pragma once

#include <limits>
#include <span>
#include <string>

#include "plinth/core/fragility.h"

namespace plinth::host {

// One case's collapse intensity (PGA, g): above lower_g and at most upper_g. lower_g == upper_g:
// known exactly; lower_g == 0: at most upper_g; upper_g infinite: no collapse up to lower_g.
struct CollapseIntensity {
  double lower_g = 0.0;
  double upper_g = std::numeric_limits<double>::infinity();

  [[nodiscard]] bool collapsed() const { return upper_g < std::numeric_limits<double>::infinity(); }
};

struct FragilityFit {
  // Empty when fitted; else why the data allow no fit, e.g. "none of the 20 cases collapsed up to
  // 2.5 g: the median is above 2.5 g" (nothing else below is then meaningful but the counts).
  std::string no_fit;
  LognormalFragility curve;
  double median_ci95_low_g = 0.0;   // exp(mu -+ 1.96 se(mu)), g
  double median_ci95_high_g = 0.0;
  double log_median_se = 0.0;       // se(mu), mu = ln(median / 1 g)
  double beta_se = 0.0;             // se(beta)
  double log_likelihood = 0.0;      // at the fit, without the exact cases' -ln(PGA)
  int iterations = 0;
  int cases = 0;
  int collapsed = 0;                // cases with a finite upper bound

  [[nodiscard]] bool fitted() const { return no_fit.empty(); }
};

// The fit (see above). Refuses, in no_fit, what has no finite maximum: no case, no collapse, every
// case collapsing below the lowest intensity tried, ranges that all reach one point (one case,
// or every collapse within two neighbouring grid steps: beta -> 0), or no case whose intensity is
// bounded on both sides (only "below the lowest" and "above the top": beta -> infinity).
[[nodiscard]] FragilityFit fit_lognormal_fragility(std::span<const CollapseIntensity> cases);

}  // namespace plinth::host

// Private to plinth_core: locating the first guard crossing of an interval (step_interval.h),
// one instance for every stepper and phase kernel: the kernel is seen through the witness alone.
#pragma once

#include <limits>

#include "plinth/core/internal/flows.h"
#include "plinth/core/internal/guards.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth::internal {

// A guard's witness along the method's solution over the interval: tau -> g(t0 + tau, y(tau)).
struct CrossingWitness {
  Real (*value)(const void* interval, GuardId id, Real tau);
  const void* interval;

  Real operator()(GuardId id, Real tau) const { return value(interval, id, tau); }
};

// What locating needs of an interval besides its guards' values at both ends.
struct CrossingSearch {
  CrossingWitness witness;
  const Scene& scene;
  const Mode& mode;
  const State& y0;
  const FlowPoint& start;  // y0's point
  Real tolerance;          // the bracket's width at which location stops, s
  bool located;            // the method locates crossings (else: taken at the interval's end)
};

// The guard that crossed first, and when (tau from the interval's start); tau is infinite when
// none did.
struct Crossing {
  GuardId id = GuardId::kRockingImpact;
  Real tau = std::numeric_limits<Real>::infinity();
};

// Out of line: the step's hot path only checks that no guard changed sign.
[[gnu::noinline]] Crossing earliest_crossing(const CrossingSearch& search,
                                             const ActiveGuards& guards, Real h,
                                             const GuardValues& g_start, const GuardValues& g_end);

}  // namespace plinth::internal

// Locating the first guard crossing of an interval (crossing.h).
#include "crossing.h"

namespace plinth::internal {
namespace {

// Time tau in (a, b] at which guard `id` reaches 0 on the method's solution: the witness is
// bracketed by g(a) < 0 <= g(b) and its root found by the Illinois variant of regula falsi, with
// a bisection whenever an update fails to halve the bracket. Returns the bracket's upper end,
// where the guard holds.
Real locate_crossing(const CrossingSearch& search, GuardId id, Real a, Real fa, Real b, Real fb) {
  int last_side = 0;
  bool bisect = false;
  for (int iteration = 0; iteration < 200 && b - a > search.tolerance; ++iteration) {
    const Real width = b - a;
    Real c = bisect ? Real(0.5) * (a + b) : (a * fb - b * fa) / (fb - fa);
    if (!(c > a && c < b)) c = Real(0.5) * (a + b);
    const Real fc = search.witness(id, c);
    if (fc >= Real(0)) {
      b = c;
      fb = fc;
      if (last_side == 1) fa *= Real(0.5);
      last_side = 1;
    } else {
      a = c;
      fa = fc;
      if (last_side == -1) fb *= Real(0.5);
      last_side = -1;
    }
    bisect = (b - a) > Real(0.5) * width;
  }
  return b;
}

// Crossing time of a guard that is negative or exactly zero at the start and non-negative
// at the end. Exactly zero means a reset has just put the state on the guard's surface
// (theta = 0 after an impact, u = +-u_max after a stop hit): the motion leaves the surface
// and may come back within the same step, so the step is probed for the excursion below 0
// and the return is located from there. An excursion too small to see is taken as an event
// at the end of the interval.
Real crossing_time(const CrossingSearch& search, GuardId id, Real h, Real g_start, Real g_end) {
  if (g_start < Real(0)) return locate_crossing(search, id, Real(0), g_start, h, g_end);
  for (const Real fraction : {Real(0.0625), Real(0.25), Real(0.5), Real(0.75)}) {
    const Real tau = fraction * h;
    const Real g = search.witness(id, tau);
    if (g < Real(0)) return locate_crossing(search, id, tau, g, h, g_end);
  }
  return h;
}

}  // namespace

Crossing earliest_crossing(const CrossingSearch& search, const ActiveGuards& guards, Real h,
                           const GuardValues& g_start, const GuardValues& g_end) {
  Crossing first;
  for (int i = 0; i < guards.count; ++i) {
    const auto j = static_cast<std::size_t>(i);
    Real a = g_start[j];
    const Real b = g_end[j];
    // The lift-off guard's start may be its bound (step_guard_value), negative as the guard
    // is: where it crossed, its own value is what the location starts from. (The end's is its
    // own: a bound is never at or above 0.)
    if (guards.ids[j] == GuardId::kLiftOff && a < Real(0) && b >= Real(0)) {
      a = guard_value(GuardId::kLiftOff, search.scene, search.mode, search.y0,
                      search.start.ground, search.start.acc, search.start.trig);
    }
    if (search.located) {
      if (a > Real(0) || b < Real(0) || (a == Real(0) && b == Real(0))) continue;
      const Real tau = crossing_time(search, guards.ids[j], h, a, b);
      if (tau < first.tau) first = {guards.ids[j], tau};
    } else {
      // No location: the crossing seen at the step's end; the guards are ranked by where
      // their straight line between the ends crosses zero.
      if (!(a < Real(0) && b >= Real(0))) continue;
      const Real tau = h * (a / (a - b));
      if (tau < first.tau) first = {guards.ids[j], tau};
    }
  }
  return first;
}

}  // namespace plinth::internal

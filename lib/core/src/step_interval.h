// Private to plinth_core: one interval of a step (Simulator::step_intervals, finish_step), the
// solver's hot path, one flattened instance per stepper and phase kernel (bound by
// EventLogic::bind_intervals, event_logic.h).
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "build_options.h"
#include "phase_kernels.h"
#include "plinth/core/internal/flows.h"
#include "plinth/core/internal/guards.h"
#include "plinth/core/real.h"
#include "plinth/core/simulator.h"

namespace plinth::internal {

// One interval of a step in a fixed mode: the stepper `Method` on the phase's `Kernel`, guards
// at both ends, the first crossing located (or, for a step-end method, taken at the end), its
// reset applied.
template <class Method, class Kernel>
struct StepInterval {
  static State advance_state(const Kernel& k, Time t, const State& y, const FlowPoint& start,
                             Real h, const GroundAcceleration* end_ground = nullptr) {
    if constexpr (Kernel::kExact) {
      return k.advance(t, y, start, h, end_ground);
    } else {
      return Method::advance(k, t, y, state_derivative(y, start.acc), h, end_ground);
    }
  }

  static void evaluate_guards(const Scene& s, const Mode& mode, const ActiveGuards& guards,
                              const State& y, const FlowPoint& p, GuardValues& out) {
    for (int i = 0; i < guards.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      out[k] = step_guard_value(guards.ids[k], s, mode, y, p);
    }
  }

  // evaluate_guards at the interval's end, and whether any guard may have crossed since the start:
  // negative or zero there and not negative now (both zero: resting on the surface). The
  // step-end methods need a strict start; earliest_crossing sorts that out. The kernel's leading
  // guards (guards.h) are evaluated with their ids known here, the rest by their ids' switch.
  static bool evaluate_end_guards(const Scene& s, const Mode& mode, const ActiveGuards& guards,
                                  const State& y, const FlowPoint& p, const GuardValues& start,
                                  GuardValues& out) {
    bool any = false;
    const auto check = [&](std::size_t k, GuardId id) {
      const Real b = step_guard_value(id, s, mode, y, p);
      const Real a = start[k];
      out[k] = b;
      any = any || (a <= Real(0) && b >= Real(0) && (a < Real(0) || b > Real(0)));
    };
    int i = 0;
    if constexpr (Kernel::kLeading != kernels::Leading::kByMode) {
      if (guards.count >= kLeadingGuards) {
        constexpr auto kIds = leading_guards(Kernel::kLeading == kernels::Leading::kRocking);
        check(0, kIds[0]);
        check(1, kIds[1]);
        check(2, kIds[2]);
        i = kLeadingGuards;
      }
    }
    for (; i < guards.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      check(k, guards.ids[k]);
    }
    return any;
  }

  static Real guard_at_time(const Simulator& sim, const Kernel& k, const Mode& mode, GuardId id,
                            Time t, const State& y) {
    const FlowPoint p = k.point(y, k.ground(t));
    return guard_value(id, *sim.scene_, mode, y, p.ground, p.acc, p.trig);
  }

  // Time tau in (a, b] at which guard `id` reaches 0 on the method's solution from (t0, y0):
  // the witness tau -> g(t0 + tau, advance_state(y0, tau)) is bracketed by g(a) < 0 <= g(b) and its
  // root found by the Illinois variant of regula falsi, with a bisection whenever an update
  // fails to halve the bracket. Returns the bracket's upper end, where the guard holds.
  [[gnu::noinline]] static Real locate_crossing(const Simulator& sim, const Kernel& k,
                                                const Mode& mode, GuardId id, Time t0,
                                                const State& y0, const FlowPoint& start, Real a,
                                                Real fa, Real b, Real fb) {
    const Real tolerance =
        sim.settings_.event_time_tolerance * static_cast<Real>(sim.settings_.step);
    int last_side = 0;
    bool bisect = false;
    for (int iteration = 0; iteration < 200 && b - a > tolerance; ++iteration) {
      const Real width = b - a;
      Real c = bisect ? Real(0.5) * (a + b) : (a * fb - b * fa) / (fb - fa);
      if (!(c > a && c < b)) c = Real(0.5) * (a + b);
      const Real fc = guard_at_time(sim, k, mode, id, t0 + static_cast<Time>(c),
                                    advance_state(k, t0, y0, start, c));
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
  static Real crossing_time(const Simulator& sim, const Kernel& k, const Mode& mode, GuardId id,
                            Time t0, const State& y0, const FlowPoint& start, Real h, Real g_start,
                            Real g_end) {
    if (g_start < Real(0))
      return locate_crossing(sim, k, mode, id, t0, y0, start, Real(0), g_start, h, g_end);
    for (const Real fraction : {Real(0.0625), Real(0.25), Real(0.5), Real(0.75)}) {
      const Real tau = fraction * h;
      const Real g = guard_at_time(sim, k, mode, id, t0 + static_cast<Time>(tau),
                                   advance_state(k, t0, y0, start, tau));
      if (g < Real(0)) return locate_crossing(sim, k, mode, id, t0, y0, start, tau, g, h, g_end);
    }
    return h;
  }

  // The guard that crossed first, and when (tau from t0); tau is infinite when none did.
  struct Crossing {
    GuardId id = GuardId::kRockingImpact;
    Real tau = std::numeric_limits<Real>::infinity();
  };

  // Out of line: the step's hot path only checks that no guard changed sign (evaluate_end_guards).
  [[gnu::noinline]] static Crossing earliest_crossing(const Simulator& sim, const Kernel& k,
                                                      const Mode& mode, const ActiveGuards& guards,
                                                      Time t0, const State& y0,
                                                      const FlowPoint& start, Real h,
                                                      const GuardValues& g_start,
                                                      const GuardValues& g_end) {
    Crossing first;
    for (int i = 0; i < guards.count; ++i) {
      const auto j = static_cast<std::size_t>(i);
      Real a = g_start[j];
      const Real b = g_end[j];
      // The lift-off guard's start may be its bound (step_guard_value), negative as the guard
      // is: where it crossed, its own value is what the location starts from. (The end's is its
      // own: a bound is never at or above 0.)
      if (guards.ids[j] == GuardId::kLiftOff && a < Real(0) && b >= Real(0)) {
        a = guard_value(GuardId::kLiftOff, *sim.scene_, mode, y0, start.ground, start.acc,
                        start.trig);
      }
      if constexpr (Method::kLocated) {
        if (a > Real(0) || b < Real(0) || (a == Real(0) && b == Real(0))) continue;
        const Real tau = crossing_time(sim, k, mode, guards.ids[j], t0, y0, start, h, a, b);
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

  PLINTH_FLATTEN static bool advance_interval(Simulator& sim, Time& t0, Time t_end,
                                              bool guards_live, bool full_step) {
    const Scene& s = *sim.scene_;
    const Mode mode = sim.mode_;
    const State& y0 = sim.y_;  // replaced only once y1 (or the event's state) is complete
    // The interval's length, and below the offsets inside it, in Real; the times themselves in
    // Time.
    const auto h = static_cast<Real>(t_end - t0);
    Kernel k({s, sim.excitation_, sim.propagator_, full_step ? h : Real(0), mode, y0});
    static constexpr ActiveGuards kNone{};
    const ActiveGuards& guards = guards_live ? sim.active_guards_ : kNone;
    // The start: kept from the end of the last step when it had no event.
    const std::size_t next = 1 - sim.current_;
    FlowPoint& start = sim.points_[sim.current_];
    GuardValues& g_start = sim.guard_values_[sim.current_];
    if (!sim.cache_valid_) {
      start = k.point(y0, k.ground(t0));
      evaluate_guards(s, mode, guards, y0, start, g_start);
    }
    // A whole step ends at t_end: in double t0 + h is t_end exactly (t_end - t0 is exact, t0
    // being n step and t_end (n + 1) step); in float h is that difference rounded, and the
    // ground is still taken at t_end, as the quiet full-contact step takes it.
    const GroundAcceleration end_ground = k.ground(t_end);
    const State y1 =
        advance_state(k, t0, y0, start, h,
                      full_step || t0 + static_cast<Time>(h) == t_end ? &end_ground : nullptr);
    FlowPoint& end = sim.points_[next];
    GuardValues& g_end = sim.guard_values_[next];
    end = k.point(y1, end_ground);
    const Crossing first =
        evaluate_end_guards(s, mode, guards, y1, end, g_start, g_end)
            ? earliest_crossing(sim, k, mode, guards, t0, y0, start, h, g_start, g_end)
            : Crossing{};
    if (!std::isfinite(first.tau)) {
      sim.y_ = y1;
      sim.current_ = next;
      sim.cache_valid_ = guards_live;
      t0 = t_end;
      return false;
    }
    sim.cache_valid_ = false;
    if constexpr (Method::kLocated) {
      sim.y_ = advance_state(k, t0, y0, start, first.tau);
      t0 += static_cast<Time>(first.tau);
    } else {
      sim.y_ = y1;
      t0 = t_end;
    }
    sim.apply_reset_fn_(sim, first.id, t0);
    return true;
  }
};

}  // namespace plinth::internal

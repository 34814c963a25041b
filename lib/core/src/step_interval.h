// Private to plinth_core: one interval of a step (Simulator::step_intervals, finish_step), the
// solver's hot path, one flattened instance per stepper and phase kernel (bound by
// EventLogic::bind_intervals, event_logic.h).
#pragma once

#include <cmath>
#include <cstddef>
#include <new>

#include "build_options.h"
#include "crossing.h"
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

  // The interval as crossing location (crossing.h) sees it: a guard's witness at tau.
  struct Interval {
    const Simulator& sim;
    const Kernel& k;
    const Mode& mode;
    Time t0;
    const State& y0;
    const FlowPoint& start;

    static Real witness(const void* interval, GuardId id, Real tau) {
      const auto& i = *static_cast<const Interval*>(interval);
      return guard_at_time(i.sim, i.k, i.mode, id, i.t0 + static_cast<Time>(tau),
                           advance_state(i.k, i.t0, i.y0, i.start, tau));
    }
  };

  // Out of line where the interval is flattened: its hot path only checks that no guard changed
  // sign.
  PLINTH_FLATTENED_OUT static Crossing earliest_crossing(const Simulator& sim, const Kernel& k,
                                                         const Mode& mode,
                                                         const ActiveGuards& guards, Time t0,
                                                         const State& y0, const FlowPoint& start,
                                                         Real h, const GuardValues& g_start,
                                                         const GuardValues& g_end) {
    const Interval interval{sim, k, mode, t0, y0, start};
    const CrossingSearch search{
        {&Interval::witness, &interval},
        *sim.scene_,
        mode,
        y0,
        start,
        sim.settings_.event_time_tolerance * static_cast<Real>(sim.settings_.step),
        Method::kLocated};
    return internal::earliest_crossing(search, guards, h, g_start, g_end);
  }

  PLINTH_FLATTEN static bool advance_interval(Simulator& sim, Time& t0, Time t_end,
                                              bool guards_live, bool full_step) {
    return advance_interval_of(sim, t0, t_end, guards_live, full_step);
  }

  // advance_interval through kernels::Erased (PLINTH_CORE_ONE_INTERVAL): this kernel's Ops and
  // the one interval of them all.
  static bool erased_interval(Simulator& sim, Time& t0, Time t_end, bool guards_live,
                              bool full_step) {
    static_assert(kernels::Erased::kFits<Kernel>);
    static constexpr kernels::Erased::Ops kOps{
        [](void* storage, const kernels::Context& c) { new (storage) Kernel(c); },
        [](const void* k, const State& y, GroundAcceleration ag) {
          return std::launder(static_cast<const Kernel*>(k))->point(y, ag);
        },
        [](const void* k, Time t, const State& y, const FlowPoint& start, Real h,
           const GroundAcceleration* end_ground) {
          return advance_state(*std::launder(static_cast<const Kernel*>(k)), t, y, start, h,
                               end_ground);
        }};
    return StepInterval<Method, kernels::Erased>::advance_interval_of(sim, t0, t_end, guards_live,
                                                                      full_step, kOps);
  }

  // KernelArgs: what the kernel is made from besides the interval's context (Erased: its Ops).
  template <class... KernelArgs>
  static bool advance_interval_of(Simulator& sim, Time& t0, Time t_end, bool guards_live,
                                  bool full_step, const KernelArgs&... kernel_args) {
    const Scene& s = *sim.scene_;
    const Mode mode = sim.mode_;
    const State& y0 = sim.y_;  // replaced only once y1 (or the event's state) is complete
    // The interval's length, and below the offsets inside it, in Real; the times themselves in
    // Time.
    const auto h = static_cast<Real>(t_end - t0);
    Kernel k(kernels::Context{s, sim.excitation_, sim.propagator_, full_step ? h : Real(0), mode,
                              y0},
             kernel_args...);
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

// Private to plinth_core. The continuous dynamics of each phase as the one-step methods see them
// (internal/steppers.h): the ground at t, dy/dt at a Runge-Kutta stage, and the full FlowPoint at
// a point where guards are evaluated. A kernel is made for one interval of a step, its mode
// fixed, so what the mode fixes (the pivot, the direction, whether the base moves) is computed
// once.
#pragma once

#include <cstddef>
#include <type_traits>

#include "plinth/core/excitation.h"
#include "plinth/core/internal/flows.h"
#include "plinth/core/internal/full_contact_propagator.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth::internal::kernels {

struct Context {
  const Scene& scene;
  const Excitation& excitation;
  const FullContactPropagator& propagator;  // over one step (exact full contact)
  Real full_step;  // the interval's length when it is a whole step, s; else 0
  const Mode& mode;
  const State& y0;
};

// Which leading guards (guards.h, leading_guards) a kernel's modes have.
enum class Leading { kRocking, kOnsets, kByMode };

struct Base {
  static constexpr bool kExact = false;  // true: the kernel propagates itself (no stepper)
  static constexpr Leading kLeading = Leading::kOnsets;

  const Scene* s;
  const Excitation* excitation;
  bool moves;  // the base is free (not absent, not held at a stop)

  explicit Base(const Context& c)
      : s(&c.scene),
        excitation(&c.excitation),
        moves(c.scene.has_base() && c.mode.held_stop == 0) {}

  // Without excitation (free motion, the benchmarks) no call at all.
  // Inlined also where the solver is not flattened (the quiet full-contact step).
  [[nodiscard, gnu::always_inline]] static GroundAcceleration ground(const Excitation& e, Time t) {
    return e.kind == ExcitationKind::kNone ? GroundAcceleration{} : e.at(t);
  }
  [[nodiscard]] GroundAcceleration ground(Time t) const { return ground(*excitation, t); }
};

// What rocking kernels share: sin and cos at every point of the interval (its stages, its end,
// the points where an event is located) from those of its start, theta0, computed once by
// sin_cos (not carried over from the last step: no drift of roundings).
struct Turning : Base {
  static constexpr Leading kLeading = Leading::kRocking;
  Real theta0;
  SinCos trig0;

  explicit Turning(const Context& c)
      : Base(c), theta0(c.y0[kTheta]), trig0(sin_cos(c.y0[kTheta])) {}

  [[nodiscard]] SinCos trig(const State& y) const { return sin_cos_near(y[kTheta], theta0, trig0); }
};

// Full contact, Eq 1; with the base held or absent, nothing moves.
struct FullContact : Base {
  explicit FullContact(const Context& c) : Base(c) {}

  [[nodiscard]] Accelerations flow(GroundAcceleration ag, const State& y) const {
    return moves ? full_contact_flow(*s, y, ag) : Accelerations{};
  }
  [[nodiscard]] State derivative(GroundAcceleration ag, const State& y) const {
    return state_derivative(y, flow(ag, y));
  }
  [[nodiscard]] FlowPoint point(const State& y, GroundAcceleration ag) const {
    return {ag, sin_cos(y[kTheta]), flow(ag, y)};
  }
};

// A phase the scene's features do not have (a sliding phase without friction, set by
// start_from): it stays still.
struct Frozen : Base {
  static constexpr Leading kLeading = Leading::kByMode;  // sliding or slide-rocking
  explicit Frozen(const Context& c) : Base(c) {}

  [[nodiscard]] State derivative(GroundAcceleration /*ag*/, const State& y) const {
    return state_derivative(y, {});
  }
  [[nodiscard]] FlowPoint point(const State& y, GroundAcceleration ag) const {
    return {ag, sin_cos(y[kTheta]), {}};
  }
};

// Full contact propagated exactly over the step (full_contact_propagator.h): the matrices of one
// step are made once per simulator; those of a shorter interval (after an event, or while
// locating one) when needed.
struct ExactFullContact : FullContact {
  static constexpr bool kExact = true;

  const FullContactPropagator* propagator;
  Real full_step;

  explicit ExactFullContact(const Context& c)
      : FullContact(c), propagator(&c.propagator), full_step(c.full_step) {}

  [[nodiscard]] State advance(Time t, const State& y, const FlowPoint& start, Real h,
                              const GroundAcceleration* end_ground) const {
    State next = y;
    next.head<3>() += h * y.tail<3>();  // x and theta stay (their rates are 0 in full contact)
    if (!moves) return next;
    const Real a1 =
        (end_ground != nullptr ? *end_ground : ground(t + static_cast<Time>(h))).horizontal;
    next[kU] = y[kU];
    if (h == full_step) {  // a whole step: its t_end - t0 differs from the step by roundings
      propagator->advance(next[kU], next[kUDot], start.ground.horizontal, a1);
    } else {
      FullContactPropagator::make(*s, h).advance(next[kU], next[kUDot], start.ground.horizontal,
                                                 a1);
    }
    return next;
  }
};

// Sliding, Eqs 2-5.
struct Sliding : Base {
  int direction;

  explicit Sliding(const Context& c) : Base(c), direction(c.mode.slide_direction) {}

  [[nodiscard]] Accelerations flow(GroundAcceleration ag, const State& y) const {
    return sliding_flow(*s, direction, y, ag, moves);
  }
  [[nodiscard]] State derivative(GroundAcceleration ag, const State& y) const {
    return state_derivative(y, flow(ag, y));
  }
  [[nodiscard]] FlowPoint point(const State& y, GroundAcceleration ag) const {
    return {ag, sin_cos(y[kTheta]), flow(ag, y)};
  }
};

// Rocking, Eq 8 (about the support's corner with b_hat_i, Eqs 13-14's pivot). x does not move
// while the block sticks, so the pivot is fixed for the interval.
struct Rocking : Turning {
  CornerGeometry pivot;  // offset and inertia (all rocking_flow uses)

  explicit Rocking(const Context& c) : Turning(c) {
    const PivotDistance d = pivot_distance(c.scene, c.mode.corner, c.mode.overhang, c.y0[kX]);
    pivot.offset = d.offset();
    // I_i = I_C + m (b_hat_i^2 + h^2), as corner_geometry makes it
    pivot.inertia =
        d.overhanging
            ? c.scene.inertia_c + c.scene.m * (d.distance * d.distance + c.scene.h * c.scene.h)
            : c.scene.corner(c.mode.corner).inertia;
    arms0 = lever_arms(c.scene, pivot.offset, trig0);
  }

  // The lever arms at a stage turned from the start's (lever_arms_turned): the stages' chain of
  // dependent operations skips sin and cos. Beyond kStageAngle, from sin_cos_near.
  [[nodiscard]] LeverArms arms(const State& y) const {
    const Real d = y[kTheta] - theta0;
    if (std::fabs(d) <= kStageAngle) return lever_arms_turned(arms0, d);
    return lever_arms(*s, pivot.offset, trig(y));
  }
  [[nodiscard]] State derivative(GroundAcceleration ag, const State& y) const {
    return state_derivative(y, rocking_flow(*s, pivot, y, ag, moves, arms(y)));
  }
  [[nodiscard]] FlowPoint point(const State& y, GroundAcceleration ag) const {
    return {ag, trig(y), rocking_flow(*s, pivot, y, ag, moves, arms(y))};
  }

  LeverArms arms0;  // b'_i, h'_i at theta0 (Eq 9)
};

// Slide-rocking, Eqs 10-12 or 13-14: overhanging, the pivot's distance moves with x.
struct SlideRocking : Turning {
  Corner corner;
  int overhang;
  int direction;

  explicit SlideRocking(const Context& c)
      : Turning(c),
        corner(c.mode.corner),
        overhang(c.mode.overhang),
        direction(c.mode.slide_direction) {}

  [[nodiscard]] SlideRockingSystem system(const State& y, const SinCos& trig) const {
    const PivotDistance d = pivot_distance(*s, corner, overhang, y[kX]);
    return slide_rocking_system(*s, d.offset(), d.overhanging, direction, y, trig);
  }
  [[nodiscard]] State derivative(GroundAcceleration ag, const State& y) const {
    return state_derivative(y, slide_rocking_flow(*s, system(y, trig(y)), y, ag, moves));
  }
  [[nodiscard]] FlowPoint point(const State& y, GroundAcceleration ag) const {
    const SinCos t = trig(y);
    const SlideRockingSystem k = system(y, t);
    return {ag, t, slide_rocking_flow(*s, k, y, ag, moves), k.consistency()};
  }
};

// A phase kernel behind function pointers: one interval's code serves every kernel
// (PLINTH_CORE_ONE_INTERVAL, a build that flattens nothing: the microcontroller's flash). The
// kernel itself is made in place; its point and its advance by the stepper are called through
// `Ops` (StepInterval::erased_interval), the ground directly.
struct Erased {
  static constexpr bool kExact = true;  // advances through Ops (the stepper on the kernel)
  static constexpr Leading kLeading = Leading::kByMode;

  struct Ops {
    void (*make)(void* storage, const Context& c);
    FlowPoint (*point)(const void* kernel, const State& y, GroundAcceleration ag);
    State (*advance)(const void* kernel, Time t, const State& y, const FlowPoint& start, Real h,
                     const GroundAcceleration* end_ground);
  };

  Erased(const Context& c, const Ops& kernel_ops) : excitation(&c.excitation), ops(&kernel_ops) {
    kernel_ops.make(storage, c);
  }

  [[nodiscard]] GroundAcceleration ground(Time t) const { return Base::ground(*excitation, t); }
  [[nodiscard]] FlowPoint point(const State& y, GroundAcceleration ag) const {
    return ops->point(storage, y, ag);
  }
  [[nodiscard]] State advance(Time t, const State& y, const FlowPoint& start, Real h,
                              const GroundAcceleration* end_ground) const {
    return ops->advance(storage, t, y, start, h, end_ground);
  }

  // Room for the largest kernel, bytes; kernels hold pointers and numbers alone (nothing to
  // destroy).
  static constexpr std::size_t kStorageBytes = 160;
  template <class K>
  static constexpr bool kFits = sizeof(K) <= kStorageBytes && alignof(K) <= 8 &&
                                std::is_trivially_destructible_v<K>;

  const Excitation* excitation;
  const Ops* ops;
  alignas(8) unsigned char storage[kStorageBytes];
};

}  // namespace plinth::internal::kernels

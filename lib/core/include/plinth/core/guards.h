// Guards (witness functions) of the hybrid system. Each guard is a scalar function of time and
// state whose crossing from negative to non-negative is its event; only the guards of the
// current mode are live (active_guards).
#pragma once

#include <array>
#include <cstdint>

#include "plinth/core/excitation.h"
#include "plinth/core/flows.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth {

enum class GuardId : std::uint8_t {
  kRockingOnsetLeft,   // Eq 16 about corner 1
  kRockingOnsetRight,  // Eq 16 mirrored, about corner 2
  kRockingImpact,      // theta returns to 0 (Section 3.3)
  kOverturning,        // |theta| passes the active corner's critical angle alpha_i
  kBaseStopRight,      // Eq 28, u = +u_max
  kBaseStopLeft,       // Eq 28, u = -u_max
  kBaseStopRelease,    // the held base's stop would have to pull: it leaves the stop
};

inline constexpr int kMaxActiveGuards = 4;

struct ActiveGuards {
  std::array<GuardId, kMaxActiveGuards> ids{};
  int count = 0;

  constexpr void add(GuardId id) { ids[static_cast<std::size_t>(count++)] = id; }
};

// What the model of a scene carries, fixed once when the scene is loaded.
struct Features {
  bool base = false;        // an isolated base (u is a degree of freedom)
  bool base_stops = false;  // security stops on the base (Eqs 28-29)
};

[[nodiscard]] constexpr Features features_of(const Scene& s) {
  return {s.params.has_base, s.params.has_base_stops};
}

template <Features F>
[[nodiscard]] constexpr ActiveGuards active_guards(const Mode& mode) {
  ActiveGuards g;
  if (mode.terminal()) return g;
  if (mode.rocking()) {
    g.add(GuardId::kRockingImpact);
    g.add(GuardId::kOverturning);
  } else {
    g.add(GuardId::kRockingOnsetLeft);
    g.add(GuardId::kRockingOnsetRight);
  }
  if constexpr (F.base_stops) {
    if (mode.held_stop != 0) {
      g.add(GuardId::kBaseStopRelease);
    } else {
      g.add(GuardId::kBaseStopRight);
      g.add(GuardId::kBaseStopLeft);
    }
  }
  return g;
}

// Absolute horizontal acceleration of the base, u'' + u_G'' (the ground's when it is fixed).
[[nodiscard]] inline double base_absolute_acceleration(const Accelerations& acc,
                                                       GroundAcceleration ag) {
  return acc.u + ag.horizontal;
}

// Eq 16: rocking about corner 1 starts when u'' + u_G'' >= (b_1 / h)(g + v_G''); about
// corner 2 when -(u'' + u_G'') >= (b_2 / h)(g + v_G''). Full-contact accelerations.
[[nodiscard]] inline double rocking_onset_guard(const Scene& s, Corner corner,
                                                const Accelerations& acc, GroundAcceleration ag) {
  const CornerGeometry& c = s.corner(corner);
  return c.sign * base_absolute_acceleration(acc, ag) - c.onset_ratio * (s.g + ag.vertical);
}

// Value of guard `id` at (y, ag) with the mode's accelerations `acc`.
[[nodiscard]] inline double guard_value(GuardId id, const Scene& s, const Mode& mode,
                                        const State& y, GroundAcceleration ag,
                                        const Accelerations& acc) {
  switch (id) {
    case GuardId::kRockingOnsetLeft:
      return rocking_onset_guard(s, Corner::kLeft, acc, ag);
    case GuardId::kRockingOnsetRight:
      return rocking_onset_guard(s, Corner::kRight, acc, ag);
    case GuardId::kRockingImpact:
      return -s.corner(mode.corner).sign * y[kTheta];
    case GuardId::kOverturning: {
      const CornerGeometry& c = s.corner(mode.corner);
      return c.sign * y[kTheta] - c.critical_angle;
    }
    case GuardId::kBaseStopRight:
      return y[kU] - s.params.base_stops.max_displacement;
    case GuardId::kBaseStopLeft:
      return -y[kU] - s.params.base_stops.max_displacement;
    case GuardId::kBaseStopRelease:
      return static_cast<double>(mode.held_stop) * base_stop_reaction(s, mode, y, ag, acc);
  }
  return -1.0;
}

}  // namespace plinth

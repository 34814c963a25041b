// The monitor's parts that a build may leave out (CMake options, OFF in the cortex-m4f presets,
// whose 64 KiB of flash they outgrow: docs/microcontroller.md), and one way to hold them: a
// field that only a build with the part fills is OptionalPart<Part, kBuilt> (Part there, an empty
// stand-in elsewhere), reached through built_part<Part>(field), which gives nullptr in a build
// without, so that every use compiles in both and vanishes from the latter.
#pragma once

#include <type_traits>

#ifndef PLINTH_REGIONAL_ALERT
#define PLINTH_REGIONAL_ALERT 1
#endif
#ifndef PLINTH_PWAVE_STAGE
#define PLINTH_PWAVE_STAGE 1
#endif

namespace plinth::monitor {

// The regional alerts' room (regional_alert.h; option PLINTH_REGIONAL_ALERT). A build without
// ignores the alert frames like identifiers it does not know, refuses every other alert, and
// refuses a box file that configures regional alerts.
inline constexpr bool kRegionalAlertBuiltIn = PLINTH_REGIONAL_ALERT != 0;
// The on-site P-wave stage in the monitor's loop (p_wave.h; option PLINTH_PWAVE_STAGE). A build
// without refuses a [pwave] table.
inline constexpr bool kPWaveStageBuiltIn = PLINTH_PWAVE_STAGE != 0;

// What a build without a part holds in its place.
struct NotBuilt {};

template <class Part, bool kBuilt, class StandIn = NotBuilt>
using OptionalPart = std::conditional_t<kBuilt, Part, StandIn>;

// `value` in a build with the part, the stand-in in one without (a default member initializer).
template <bool kBuilt, class Part, class StandIn = NotBuilt>
[[nodiscard]] constexpr OptionalPart<Part, kBuilt, StandIn> part_if(const Part& value) {
  if constexpr (kBuilt) {
    return value;
  } else {
    return StandIn{};
  }
}

// `held` as `Part` in a build that has it; nullptr in one that has not.
template <class Part, class Held>
[[nodiscard]] constexpr auto* built_part(Held& held) {
  using Out = std::conditional_t<std::is_const_v<Held>, const Part, Part>;
  if constexpr (std::is_same_v<std::remove_const_t<Held>, Part>) {
    return &held;
  } else {
    return static_cast<Out*>(nullptr);
  }
}

}  // namespace plinth::monitor

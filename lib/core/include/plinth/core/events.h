// Discrete events reported by the simulator.
#pragma once

#include <cstdint>

#include "plinth/core/name_table.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/state.h"

namespace plinth {

enum class EventKind : std::uint8_t {
  kRockingStart,      // Eq 16 met; `corner` is the pivot
  kImpact,            // theta returned to 0; `corner` is the new pivot; before/after: theta'
  kRockingStop,       // rocking energy spent (rest criterion); the block is in full contact
  kBaseStopHit,       // Eq 28; `side` +1 right, -1 left; before/after: u'
  kBaseStopHeld,      // the base came to rest against stop `side`
  kBaseStopReleased,  // the held base leaves stop `side`
  kOverturned,        // |theta| passed the critical angle of `corner`
  kSlidingStart,      // Eq 15 or 18 met (or x' changed sign); `side` is the sign of x'
  kSlidingStop,       // x' returned to 0 and static friction holds
  kSlideStopHit,      // Eq 30; `side` +1 right; before: x', after: u' (Eq 32)
  kOutOfBase,         // |x| passed x_hat: the block overhangs the support's `side` edge
  kBackOnBase,        // the overhanging block slid back onto the support
  kFell,              // C passed the support's `side` edge: the block fell off the base
  kLiftOff,           // the support's normal force on the block reached 0 (guards.h, kLiftOff):
                      // `left` is the phase it left, `before` g + v_G'' (m/s2) then
};

struct Event {
  Time t = 0.0;  // s
  EventKind kind = EventKind::kRockingStart;
  Corner corner = Corner::kLeft;
  std::int8_t side = 0;
  Real before = 0.0;
  Real after = 0.0;
  Phase phase = Phase::kFullContact;  // the phase just after the event
  std::int8_t overhang = 0;           // Mode::overhang just after the event
  Phase left = Phase::kFullContact;   // kLiftOff: the phase the block was in
  State state = State::Zero();        // just after the reset
};

// Names used in plinth-sim's JSON Lines event log.
inline constexpr NameTable<EventKind, 14> kEventKindNames{{{
    {EventKind::kRockingStart, "rocking_start"},
    {EventKind::kImpact, "impact"},
    {EventKind::kRockingStop, "rocking_stop"},
    {EventKind::kBaseStopHit, "base_stop_hit"},
    {EventKind::kBaseStopHeld, "base_stop_held"},
    {EventKind::kBaseStopReleased, "base_stop_released"},
    {EventKind::kOverturned, "overturned"},
    {EventKind::kSlidingStart, "sliding_start"},
    {EventKind::kSlidingStop, "sliding_stop"},
    {EventKind::kSlideStopHit, "slide_stop_hit"},
    {EventKind::kOutOfBase, "out_of_base"},
    {EventKind::kBackOnBase, "back_on_base"},
    {EventKind::kFell, "fell"},
    {EventKind::kLiftOff, "lift_off"},
}}};
[[nodiscard]] constexpr const char* event_name(EventKind kind) {
  return kEventKindNames.name(kind);
}

// True when `corner` turns about the support's corner rather than the body's own.
[[nodiscard]] constexpr bool pivots_on_support(Corner corner, int overhang) {
  return overhang == (corner == Corner::kLeft ? -1 : 1);
}

// Receives events as the solver finds them, on the stepping path: must not block.
class EventSink {
 public:
  virtual void on_event(const Event& event) = 0;

 protected:
  EventSink() = default;
  EventSink(const EventSink&) = default;
  EventSink& operator=(const EventSink&) = default;
  ~EventSink() = default;
};

}  // namespace plinth

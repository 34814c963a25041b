// Relay outputs for a building's alarm panel: one GPIO line per alarm level (and one for the
// box's fault), fail-safe: a relay is energised while its level is not reached and the box is
// healthy, so power loss, a crash, a watchdog kill or the fault level open its contact. Latched
// levels keep their relays open until acknowledged (the alarm policy's latch). The logic is
// here; the lines are behind RelayBackend: libgpiod (relay_gpiod.h) or a fake that records
// (relay_fake.h). docs/relays-and-supervision.md. Host code: may allocate and throw.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "plinth/monitor/alarm_level.h"

namespace plinth::firmware {

// The relays, in the order of RelaySettings::lines.
enum class Relay : std::uint8_t { kAdvisory = 0, kWarning = 1, kAlarm = 2, kFault = 3 };
inline constexpr std::size_t kRelayCount = 4;
// Their names: the [relays] keys.
inline constexpr std::array<const char*, kRelayCount> kRelayNames = {"advisory", "warning", "alarm",
                                                                     "fault"};

struct RelayLine {
  int offset = -1;          // the line's offset on the chip; -1: this relay is not wired
  bool active_low = false;  // energised by driving the line low (most opto-isolated boards)
};

// The box's [relays] table.
struct RelaySettings {
  std::string chip;  // relays.chip: a gpiochip name, number or /dev path; empty: no relays
  std::array<RelayLine, kRelayCount> lines{};
  [[nodiscard]] bool enabled() const { return !chip.empty(); }
};

// Whether `relay`'s coil is energised (its normally-open contact closed, "healthy") with the
// alarm level shown, the level latched until acknowledged, and `fault`: a fault input present
// (no usable ground sensor, sensors disagreeing) even where the level shown is an alarm, which
// a fault never hides. The fault level opens every relay, a fault input the fault relay; a
// level relay opens at its level or above, shown or latched.
[[nodiscard]] bool relay_energised(Relay relay, monitor::AlarmLevel shown,
                                   monitor::AlarmLevel latched, bool fault);

// The wired lines (RelaySettings::lines with offset >= 0), in that order.
class RelayBackend {
 public:
  virtual ~RelayBackend() = default;
  // Drives wired line `index` to energise (true) or release (false) its relay; false when the
  // write failed (errno says why).
  [[nodiscard]] virtual bool set(std::size_t index, bool energised) = 0;
};

class RelayOutputs {
 public:
  // `backend` holds the wired lines, every one released (de-energised) at first.
  RelayOutputs(const RelaySettings& settings, std::unique_ptr<RelayBackend> backend);

  // The relays for the monitor's current levels and fault input (relay_energised); writes only
  // the lines that change. A failed write is counted and tried again at the next update.
  void update(monitor::AlarmLevel shown, monitor::AlarmLevel latched, bool fault);

  [[nodiscard]] bool energised(Relay relay) const {
    return energised_[static_cast<std::size_t>(relay)];
  }
  [[nodiscard]] std::uint64_t writes() const { return writes_; }
  [[nodiscard]] std::uint64_t write_errors() const { return write_errors_; }

 private:
  std::unique_ptr<RelayBackend> backend_;
  std::array<int, kRelayCount> wired_index_{};  // the backend's index, -1: not wired
  std::array<bool, kRelayCount> energised_{};   // as last written successfully
  std::uint64_t writes_ = 0;
  std::uint64_t write_errors_ = 0;
};

}  // namespace plinth::firmware

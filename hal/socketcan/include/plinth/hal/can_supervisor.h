// Supervision of a Linux CAN interface: up/down and running (any interface), and through
// libsocketcan the controller's fault confinement state, bus-off recovery and error counters.
//
// Only real controllers (the kernel's "can" link kind: can-dev drivers) have a controller state.
// On a virtual interface (vcan, vxcan) libsocketcan returns -1 for state, restart and counters;
// that is reported as kNotSupported, which is not a fault of the bus. start()/stop() work on any
// CAN interface (they set IFF_UP) and need CAP_NET_ADMIN.
//
// Not for the receive path: every call opens a netlink socket and may allocate.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "plinth/hal/socketcan.h"

namespace plinth::hal {

enum class SupervisionStatus : std::uint8_t {
  kOk = 0,
  kNotSupported,  // the interface has no such thing (a vcan has no controller state)
  kFailed,        // the call failed: no such interface, no permission, ... (see message)
};
[[nodiscard]] const char* supervision_status_name(SupervisionStatus status);

struct SupervisionResult {
  SupervisionStatus status = SupervisionStatus::kOk;
  int error_number = 0;  // errno of a failure, 0 when there is none
  std::string message;   // names the interface and what happened; empty when ok

  [[nodiscard]] bool ok() const { return status == SupervisionStatus::kOk; }
};

// A value with the result of reading it; `value` is meaningful only when result.ok().
template <typename T>
struct Supervised {
  SupervisionResult result;
  T value{};
};

// IFF_UP: administratively up (`ip link set up`); IFF_RUNNING: operationally up (carrier; a
// CAN controller in bus-off or stopped is up but not running on most drivers).
struct LinkState {
  bool up = false;
  bool running = false;
};

// The controller's transmit and receive error counters (TEC, REC).
struct ErrorCounters {
  std::uint16_t tx = 0;
  std::uint16_t rx = 0;
};

class CanInterfaceSupervisor {
 public:
  explicit CanInterfaceSupervisor(std::string_view interface_name);

  [[nodiscard]] const std::string& interface_name() const { return interface_name_; }

  // The kernel's link kind ("can" for a real controller, "vcan", "vxcan"); kFailed when the
  // interface does not exist.
  [[nodiscard]] Supervised<std::string> link_kind() const;
  // SIOCGIFFLAGS: works on every interface, virtual or not.
  [[nodiscard]] Supervised<LinkState> link_state() const;

  SupervisionResult start() const;    // can_do_start: set the interface up
  SupervisionResult stop() const;     // can_do_stop: set it down
  SupervisionResult restart() const;  // can_do_restart: leave bus-off (only from bus-off, and
                                      // only when the driver's automatic restart is off)
  [[nodiscard]] Supervised<ControllerState> state() const;     // can_get_state
  [[nodiscard]] Supervised<ErrorCounters> error_counters() const;  // can_get_berr_counter

 private:
  // kOk when libsocketcan's controller calls apply to the interface; kNotSupported on a virtual
  // one; kFailed when the interface is missing.
  [[nodiscard]] SupervisionResult controller_support() const;
  [[nodiscard]] SupervisionResult libsocketcan_failure(const char* call, int saved_errno) const;

  std::string interface_name_;
};

}  // namespace plinth::hal

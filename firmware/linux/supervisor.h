// Supervision by systemd (sd_notify(3), libsystemd): READY=1 once the loop runs, WATCHDOG=1
// from the loop while it makes progress, at half the service's WatchdogSec (WATCHDOG_USEC), so
// a loop that hangs is killed and restarted (firmware/linux/systemd/plinth-monitor.service,
// docs/relays-and-supervision.md). Without NOTIFY_SOCKET (not under systemd) it sends nothing.
// Host code: may allocate and throw.
#pragma once

#include <csignal>
#include <cstdint>
#include <string>

namespace plinth::firmware {

// The box's [watchdog] table.
struct WatchdogSettings {
  bool notify = true;  // watchdog.notify: READY=1 and WATCHDOG=1 when systemd asks for them
  // watchdog.test_stall_after_s, TEST ONLY: the loop stops taking input this many seconds (wall
  // clock) after it started, as a hung loop would, until SIGINT or SIGTERM; 0: never. Tests
  // use it to see WATCHDOG=1 stop; a box in service never sets it.
  double test_stall_after_s = 0.0;
};

class Supervisor {
 public:
  // Reads WATCHDOG_USEC (and WATCHDOG_PID) through sd_watchdog_enabled(3).
  explicit Supervisor(const WatchdogSettings& settings);

  // READY=1 with a STATUS= line: the input is open and the loop starts now.
  void ready(const std::string& status);
  // The loop took an input item at `now_ns` (monotonic clock): WATCHDOG=1 when half the watchdog
  // interval has passed since the previous one. Called only after progress, never from a timer.
  void on_progress(std::int64_t now_ns) {
    if (interval_ns_ > 0 && now_ns >= next_ping_ns_) ping(now_ns);
  }
  // STOPPING=1: the loop ended (input done, a signal, --duration).
  void stopping();

  // TEST ONLY (watchdog.test_stall_after_s): true once the stall is due at `now_ns`.
  [[nodiscard]] bool stall_due(std::int64_t now_ns) const {
    return stall_at_ns_ > 0 && now_ns >= stall_at_ns_;
  }
  // TEST ONLY: blocks, sending nothing, until `stop` is set.
  static void stall(const volatile std::sig_atomic_t& stop);

  // WATCHDOG=1 spacing, ns (half of WATCHDOG_USEC); 0: the watchdog is off.
  [[nodiscard]] std::int64_t ping_interval_ns() const { return interval_ns_; }
  [[nodiscard]] std::uint64_t pings() const { return pings_; }
  [[nodiscard]] std::uint64_t notify_errors() const { return notify_errors_; }

 private:
  void ping(std::int64_t now_ns);
  void notify(const char* state);

  bool enabled_;
  std::int64_t interval_ns_ = 0;
  std::int64_t next_ping_ns_ = 0;
  std::int64_t stall_after_ns_ = 0;
  std::int64_t stall_at_ns_ = 0;
  std::uint64_t pings_ = 0;
  std::uint64_t notify_errors_ = 0;
};

}  // namespace plinth::firmware

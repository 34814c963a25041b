// Supervision by systemd (sd_notify(3), libsystemd): READY=1 once the loop runs, WATCHDOG=1
// from the loop while it makes progress, at half the service's WatchdogSec (WATCHDOG_USEC), so
// a loop that hangs is killed and restarted (firmware/linux/systemd/plinth-monitor@.service,
// docs/relays-and-supervision.md); STATUS= kept at the alarm level shown, for `systemctl
// status`. Without NOTIFY_SOCKET (not under systemd) it sends nothing. Under systemd (a service
// has INVOCATION_ID) each alarm change also goes to the journal (sd_journal_send(3)) at its own
// priority with structured fields: PLINTH_ALARM_LEVEL, PLINTH_ALARM_PREVIOUS, PLINTH_ALARM_CAUSE,
// PLINTH_ALARM_T (s), PLINTH_ALARM_LATCHED, PLINTH_ALARM_SEQUENCE. Host code: may allocate and
// throw.
#pragma once

#include <csignal>
#include <cstdint>
#include <string>

#include "plinth/monitor/alarm_policy.h"

namespace plinth::firmware {

// The journal's priority (syslog(3)) of a change to `level`: alarm LOG_ALERT (1); warning and
// fault LOG_CRIT (2); advisory LOG_WARNING (4); back to normal LOG_NOTICE (5). The box's other
// messages (its JSON lines on stdout) are LOG_INFO (6).
[[nodiscard]] int journal_priority(monitor::AlarmLevel level);

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
  // An alarm change (t in s, the status lines' time): STATUS= with the level now, and the
  // journal entry. Called on the loop at each change only (a datagram each, no waiting).
  void alarm_changed(const monitor::AlarmEventRecord& event, double t);
  [[nodiscard]] std::uint64_t journal_entries() const { return journal_entries_; }

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
  bool journal_ = false;  // under systemd (INVOCATION_ID)
  std::string source_;    // "monitoring can0", the STATUS= lines' end
  std::uint64_t journal_entries_ = 0;
  std::uint64_t journal_errors_ = 0;
  std::int64_t interval_ns_ = 0;
  std::int64_t next_ping_ns_ = 0;
  std::int64_t stall_after_ns_ = 0;
  std::int64_t stall_at_ns_ = 0;
  std::uint64_t pings_ = 0;
  std::uint64_t notify_errors_ = 0;
};

}  // namespace plinth::firmware

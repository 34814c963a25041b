#include "supervisor.h"

#include <systemd/sd-daemon.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>

#include "plinth/hal/pacing.h"

namespace plinth::firmware {

Supervisor::Supervisor(const WatchdogSettings& settings) : enabled_(settings.notify) {
  if (settings.test_stall_after_s > 0.0) {
    stall_after_ns_ = std::llround(settings.test_stall_after_s * 1e9);
  }
  if (!enabled_) return;
  std::uint64_t usec = 0;
  const int r = sd_watchdog_enabled(0, &usec);
  if (r < 0) {
    std::fprintf(stderr, "plinth-monitor: warning: WATCHDOG_USEC: %s; no watchdog pings\n",
                 std::strerror(-r));
  } else if (r > 0 && usec > 0) {
    interval_ns_ = static_cast<std::int64_t>(usec) * 1000 / 2;  // sd_watchdog_enabled(3): half
  }
}

void Supervisor::notify(const char* state) {
  if (!enabled_) return;
  const int r = sd_notify(0, state);
  if (r >= 0) return;
  if (notify_errors_++ == 0) {  // once: the loop must not flood stderr
    std::fprintf(stderr, "plinth-monitor: warning: sd_notify: %s\n", std::strerror(-r));
  }
}

void Supervisor::ready(const std::string& status) {
  const std::int64_t now_ns = hal::monotonic_now_ns();
  if (stall_after_ns_ > 0) stall_at_ns_ = now_ns + stall_after_ns_;
  const std::string state = "READY=1\nSTATUS=" + status;
  notify(state.c_str());
  if (interval_ns_ > 0) ping(now_ns);
}

void Supervisor::ping(std::int64_t now_ns) {
  notify("WATCHDOG=1");
  ++pings_;
  next_ping_ns_ = now_ns + interval_ns_;
}

void Supervisor::stopping() { notify("STOPPING=1"); }

void Supervisor::stall(const volatile std::sig_atomic_t& stop) {
  while (stop == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

}  // namespace plinth::firmware

#include "supervisor.h"

#include <syslog.h>
#include <systemd/sd-daemon.h>
// No CODE_FILE/CODE_LINE in the entries: they would name the build's source path, of no use on a
// box (and no installed file names the source tree: tests/cli/test_install.sh).
#define SD_JOURNAL_SUPPRESS_LOCATION
#include <systemd/sd-journal.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "plinth/hal/pacing.h"

namespace plinth::firmware {

int journal_priority(monitor::AlarmLevel level) {
  switch (level) {
    case monitor::AlarmLevel::kAlarm: return LOG_ALERT;
    case monitor::AlarmLevel::kWarning:
    case monitor::AlarmLevel::kFault: return LOG_CRIT;
    case monitor::AlarmLevel::kAdvisory: return LOG_WARNING;
    case monitor::AlarmLevel::kNormal: break;
  }
  return LOG_NOTICE;
}

Supervisor::Supervisor(const WatchdogSettings& settings) : enabled_(settings.notify) {
  const char* invocation = std::getenv("INVOCATION_ID");  // systemd.exec(5): set for services
  journal_ = invocation != nullptr && invocation[0] != '\0';
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
  source_ = status;
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

void Supervisor::alarm_changed(const monitor::AlarmEventRecord& e, double t) {
  const char* level = monitor::alarm_level_name(e.level);
  const char* previous = monitor::alarm_level_name(e.previous_level);
  const char* cause = monitor::alarm_cause_name(e.cause);
  char text[256];
  std::snprintf(text, sizeof text, "alarm level %s%s (was %s, cause %s) since t = %.3f s", level,
                e.latched ? ", latched" : "", previous, cause, t);
  const std::string status = std::string("STATUS=") + text + "; " + source_;
  notify(status.c_str());
  if (!journal_) return;
  const int r = sd_journal_send("MESSAGE=%s", text, "PRIORITY=%d", journal_priority(e.level),
                                "SYSLOG_IDENTIFIER=plinth-monitor",
                                "PLINTH_ALARM_LEVEL=%s", level, "PLINTH_ALARM_PREVIOUS=%s", previous,
                                "PLINTH_ALARM_CAUSE=%s", cause, "PLINTH_ALARM_T=%.6f", t,
                                "PLINTH_ALARM_LATCHED=%d", e.latched ? 1 : 0,
                                "PLINTH_ALARM_SEQUENCE=%u", static_cast<unsigned>(e.sequence),
                                nullptr);
  if (r >= 0) {
    ++journal_entries_;
  } else if (journal_errors_++ == 0) {  // once: the loop must not flood stderr
    std::fprintf(stderr, "plinth-monitor: warning: sd_journal_send: %s\n", std::strerror(-r));
  }
}

void Supervisor::stall(const volatile std::sig_atomic_t& stop) {
  while (stop == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

}  // namespace plinth::firmware

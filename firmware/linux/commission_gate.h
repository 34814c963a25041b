// plinth-monitor's reading of the commissioning (docs/commissioning.md): the newest report of the
// recorder's folder, or the one the box file names, against the box file's mounting. A failed,
// stale or unreadable report, or none where the box file requires one, refuses: the box shows
// fault, cause commissioning_failed (Monitor::hold_fault), until a passing report appears (the
// folder is looked at again every kGateRescanS) or an override with its reason is given. Host
// code: allocates.
#pragma once

#include <cstdint>
#include <string>

#include "commission_settings.h"

namespace plinth::firmware {

// s between two looks at the folder (or the named report) for a newer report.
inline constexpr double kGateRescanS = 2.0;

enum class GateState : std::uint8_t {
  kNone,        // no report, none required: the box monitors, saying so at each start
  kPassed,      // the report passed, for this mounting
  kRefused,     // fault, cause commissioning_failed
  kOverridden,  // it would refuse; an override's reason lets the box monitor
};
[[nodiscard]] const char* gate_state_name(GateState state);

struct GateVerdict {
  GateState state = GateState::kNone;
  std::string report;       // the report read ("" none)
  std::string report_time;  // its "time"
  std::string why;          // kRefused, kOverridden: what is wrong; kNone: where none was found
};

class CommissioningGate {
 public:
  // `record_dir`: plinth-monitor's --record-dir ("" none); `override_option`: the reason given
  // with --commissioning-override ("" none; it goes before the box file's).
  CommissioningGate(const CommissioningSettings& settings, std::string record_dir,
                    std::string mounting_sha256, std::string override_option);

  // Reads the report now.
  const GateVerdict& check();
  // Every kGateRescanS of `now_ns` (a monotonic clock): reads again when the folder or the named
  // report changed. True when the verdict's state or report changed.
  bool poll(std::int64_t now_ns);

  [[nodiscard]] const GateVerdict& verdict() const { return verdict_; }
  [[nodiscard]] bool refuses() const { return verdict_.state == GateState::kRefused; }
  // The line for the journal (stderr, or sd_journal_send at its priority under systemd).
  [[nodiscard]] std::string message() const;
  // Tells the journal (or stderr) of the verdict: at start and at each change.
  void announce() const;
  // "\"commissioning\": {...}" for a status line.
  [[nodiscard]] std::string status_member() const;
  // The same object alone, for the summary.
  [[nodiscard]] std::string json() const;

 private:
  [[nodiscard]] GateVerdict evaluate() const;
  [[nodiscard]] std::int64_t watched_stamp() const;  // mtime of what is watched, ns

  CommissioningSettings settings_;
  std::string record_dir_;
  std::string mounting_sha256_;
  std::string override_reason_;  // "" none
  std::string override_source_;  // "--commissioning-override" or "commissioning.override"
  GateVerdict verdict_;
  std::int64_t next_look_ns_ = 0;
  std::int64_t stamp_ = 0;
};

}  // namespace plinth::firmware

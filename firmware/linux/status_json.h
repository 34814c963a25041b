// plinth-monitor's JSON Lines (docs/monitor.md): status, alarm, phase event and summary lines.
// Host code: allocates.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plinth/core/events.h"
#include "plinth/firmware/frame_decoder.h"
#include "plinth/firmware/monitor.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/alarm_policy.h"
#include "recorder_status.h"

namespace plinth::firmware {

// One JSON object, member by member, as plinth's JSON Lines write it: {"key": value, ...}.
class JsonObject {
 public:
  JsonObject& text(std::string_view key, std::string_view value);       // a string, escaped
  JsonObject& fixed(std::string_view key, double value, int decimals);  // printf's %.<decimals>f
  JsonObject& general(std::string_view key, double value, int digits);  // printf's %.<digits>g
  JsonObject& count(std::string_view key, std::uint64_t value);
  JsonObject& flag(std::string_view key, bool value);
  JsonObject& raw(std::string_view key, std::string_view json);  // a value written already
  [[nodiscard]] std::string close() const { return text_ + "}"; }

 private:
  JsonObject& member(std::string_view key);
  std::string text_ = "{";
  bool empty_ = true;
};

// "[a, b, ...]" of values written already.
[[nodiscard]] std::string json_array(const std::vector<std::string>& values);

// {"type": "status", "t": .., "phase": .., "risk": .., "alarm": .., ...}: the monitor's status;
// t in s of monitor time less `t_origin` (a record replay's lead-in).
[[nodiscard]] std::string status_json(const BoxStatus& status, double t_origin);
// What the statue sensor's weights say of one axis (the status line's and the MQTT state's).
[[nodiscard]] std::string statue_weights_json(const StatueAxisStatus& axis);
// A held collapse (BoxStatus::collapse): its axis, phase, corner, whether it was restored.
[[nodiscard]] std::string collapse_json(const CollapseRecord& collapse);

// The event recorder's health: {"health": "ok", "problem": "none", "captures_written": ..,
// "captures_lost": .., "captures_truncated": .., "captures_deleted": ..} (the status line's
// "recorder", after the monitor's members; the MQTT state's).
[[nodiscard]] std::string recorder_status_json(const RecorderStatus& recorder);

// The refusals of regional alerts more dangerous than the worst held (regional_alert.h): their
// count and the latest, refused at JSON time `t` (null: none).
[[nodiscard]] std::string refused_dangerous_json(std::uint64_t count,
                                                 const monitor::RefusedRegionalAlert& latest,
                                                 double t);

// {"type": "alarm", "t": .., "level": .., "previous": .., "cause": .., "latched": .., ...}.
[[nodiscard]] std::string alarm_json(const monitor::AlarmEventRecord& event, double t_origin);
// The P-wave stage's part of a status line ("pwave", when it runs): state, probability,
// counters, and the latest trigger's window (onset_t in the lines' time: the stage counts from
// `start_ns`, monitor time).
[[nodiscard]] std::string pwave_status_json(const monitor::PWaveStatus& pwave,
                                            std::int64_t start_ns, double t_origin);
// The regional room's part of a status line ("regional", when an alert was ever received): the
// worst held alert, its probability of collapse and time to the S arrival, the counters.
[[nodiscard]] std::string regional_status_json(const monitor::RegionalAlertStatus& regional,
                                               double t_origin);
// {"type": "regional", "result": "accepted" | "refused", ...}: what came of one regional alert.
[[nodiscard]] std::string regional_json(const monitor::RegionalOutcome& outcome,
                                        const BoxStatus& status);

// {"type": "event", "axis": "x", "t": .., "event": .., ...}: a phase event of axis `axis`, its
// time already in the output's time.
[[nodiscard]] std::string event_json(int axis, const Event& event);

// What a run did besides the monitor's own counters: the summary's other fields.
struct RunTotals {
  std::string source;  // the record, the log or the interface
  FrameCounters frames;  // the frame decoder's (a log or a bus)
  std::uint64_t samples = 0;
  double max_risk = 0.0;
  monitor::AlarmLevel max_level = monitor::AlarmLevel::kNormal;  // the highest but fault
  std::uint64_t alarm_events = 0;
  std::uint64_t fault_events = 0;
  std::uint64_t phase_events = 0;
  std::uint64_t bus_send_errors = 0;     // frames not sent (the bus refused or not encodable)
  std::uint64_t bus_errors = 0;          // error frames reported by the controller (live)
  std::uint64_t bus_dropped_frames = 0;  // frames the kernel dropped before we read them (live)
  std::uint64_t log_time_back = 0;       // log frames stamped before the previous (dropped)
  std::uint64_t log_time_still = 0;      // log frames stamped at the previous time (dropped)
  std::uint64_t log_time_gaps = 0;       // log jumps forward beyond kMaxLogGapS
  std::uint64_t log_drop_reports = 0;    // a log's DROPCOUNT lines (its logger lost frames)
  std::uint64_t log_drop_frames = 0;     // the frames they say were lost
  // Why the run cannot be vouched for ("no_sensor_data", "log_time", "log_drops"), "" when it
  // can: the summary then says "alarm": "fault" with this "input_fault".
  std::string input_fault;
  bool recorder = false;                 // the event recorder ran: its counters follow
  RecorderStatus recorder_status;        // its health at the end, written, lost, cut, deleted
  std::uint64_t captures_dropped = 0;    // triggers that found both buffers busy
  std::uint64_t recorder_write_errors = 0;  // captures the writer could not write
  std::uint64_t frames_lost = 0;            // frames of capture windows no capture holds
  std::uint64_t recorder_first_index = 0;   // this run's first capture number
  std::uint64_t partial_files_removed = 0;  // left by a process killed while writing
  // Members written already, after the others: the outputs' counters ("modbus": {...}, ...).
  std::vector<std::pair<std::string, std::string>> outputs;
};

// {"type": "summary", "source": .., "samples": .., "final_phase": .., "max_risk": .., ...}.
[[nodiscard]] std::string summary_json(const Monitor& monitor, const RunTotals& totals,
                                       double t_origin);

}  // namespace plinth::firmware

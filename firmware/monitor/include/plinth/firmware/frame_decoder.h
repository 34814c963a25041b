// The bus's frames (hal/can_codec) as the monitor's inputs: a configured sensor's
// SensorAcceleration is its sample, the statue sensor's StatueRotation and SensorAcceleration
// its gyroscope's and accelerometer's samples, an Acknowledge an operator's acknowledgement
// (unauthenticated: BusStatementGuard bounds a sweep), a RegionalAlert after its
// RegionalAlertOrigin a regional alert (with a key, only once its RegionalAlertTag checks);
// every other frame, and every frame the codec refuses, is counted and is no input.
// Freestanding.
#pragma once

#include <array>
#include <cstdint>

#include "plinth/firmware/config.h"
#include "plinth/firmware/monitor.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/frame_io.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// What the frames were.
struct FrameCounters {
  std::uint64_t received = 0;
  std::uint64_t sensor_samples = 0;       // SensorAcceleration of a configured node, decoded
  std::uint64_t statue_rates = 0;         // StatueRotation of the statue sensor's node
  std::uint64_t statue_accelerations = 0;  // SensorAcceleration of the statue sensor's node
  std::uint64_t other_nodes = 0;  // SensorAcceleration / StatueRotation of other nodes (not used)
  std::uint64_t heartbeats = 0;           // SensorHeartbeat of any node
  std::uint64_t acknowledgements = 0;     // Acknowledge frames, decoded
  std::uint64_t acknowledgements_refused = 0;  // of which the monitor refused (stale, wrong level)
  std::uint64_t acknowledgements_ignored = 0;  // of which came while the bus was locked out
  std::uint64_t acknowledgement_lockouts = 0;  // times the bus's acknowledgements were locked out
  std::uint64_t statue_stands = 0;             // StatueStands frames, decoded
  std::uint64_t statue_stands_refused = 0;     // of which the monitor refused (stale sequence)
  std::uint64_t statue_stands_ignored = 0;     // of which came while the bus was locked out
  std::uint64_t statue_stands_lockouts = 0;    // times the bus's statements were locked out
  std::uint64_t monitor_frames = 0;  // MonitorStatus / AlarmEvent / CollapseForecast (any box's)
  std::uint64_t regional_alerts = 0;  // RegionalAlert frames taken with their origin frame
  // RegionalAlert frames without their RegionalAlertOrigin (same event and version, within
  // kRegionalPairWindowNs before), or refused by the codec: malformed alerts
  std::uint64_t regional_malformed = 0;
  // With a key (RegionalAuthentication): RegionalAlertTag frames, and alerts refused for a tag
  // missing, wrong or replayed (its Counter not above the last taken).
  std::uint64_t regional_tags = 0;
  std::uint64_t regional_unauthenticated = 0;
  std::uint64_t rejected = 0;             // failed to decode (length, range, reserved bits)
  std::uint64_t unknown_identifiers = 0;  // not a plinth identifier
  hal::can::CodecError last_error = hal::can::CodecError::kOk;  // of the latest rejected frame
  const char* last_error_signal = "";
};

// One frame's input for the monitor.
struct FrameInput {
  enum class Kind : std::uint8_t {
    kNone,             // no input (another message, another node, refused)
    kSensorSample,     // `sample` of sensor `sensor` (Monitor::on_sensor_sample)
    kAcknowledgement,  // `acknowledgement` (Monitor::acknowledge)
    kStatueStands,     // `stands` (Monitor::statue_stands)
    kStatueRate,          // `statue` (Monitor::on_statue_sample)
    kStatueAcceleration,  // `sample` of the statue sensor (Monitor::on_statue_acceleration)
    kRegionalAlert,       // `regional` (Monitor::on_regional_alert at the frame's time)
    kRegionalMalformed,   // a regional alert that cannot be read (`malformed_field` says why)
    kRegionalUnauthenticated,  // one whose tag is missing, wrong or replayed (`malformed_field`)
  };
  Kind kind = Kind::kNone;
  int sensor = -1;  // its index in the configured order
  monitor::SensorSample sample;
  StatueSample statue;
  monitor::Acknowledgement acknowledgement;
  hal::can::StatueStands stands;
  monitor::RegionalAlert regional;
  const char* malformed_field = "";
};

// The longest time from a RegionalAlertOrigin to its RegionalAlert frame, and from that to its
// RegionalAlertTag (the bridge sends them back to back).
inline constexpr std::int64_t kRegionalPairWindowNs = 100'000'000;

// Acknowledge and StatueStands frames carry no proof of their sender: any node on the bus (or a
// gateway into it) can send one, and one that reads the bus's AlarmEvent frames knows the
// sequence to quote. A node that cannot read it could still sweep the 256 sequences (and the
// levels) until one releases the latch or clears a held collapse. So: after
// kRefusedStatementsBeforeLockout refused within kRefusedStatementWindowNs, the bus's statements
// of that kind are ignored (counted) while what they met stays held (the latched level; the
// collapse): a sweep gets 4 guesses (at most 4 in 256 of succeeding), and the latch is released
// by an operator at the box, over MQTT or Modbus, or by no one (the alarm stays shown: the safe
// side). A new level latched ends the lockout. docs/monitor.md.
inline constexpr int kRefusedStatementsBeforeLockout = 4;
inline constexpr std::int64_t kRefusedStatementWindowNs = 60'000'000'000;

class BusStatementGuard {
 public:
  // Whether a statement may go to the monitor while `held` is held (kNormal: nothing).
  [[nodiscard]] bool admits(monitor::AlarmLevel held);
  // A statement the monitor refused at `time_ns` while `held` was held: true when this refusal
  // locks the bus's statements of this kind out.
  [[nodiscard]] bool refused(std::int64_t time_ns, monitor::AlarmLevel held);
  [[nodiscard]] bool locked() const { return locked_; }

 private:
  std::array<std::int64_t, kRefusedStatementsBeforeLockout> refused_ns_{};  // a ring
  int refused_count_ = 0;
  int next_ = 0;
  bool locked_ = false;
  monitor::AlarmLevel locked_level_ = monitor::AlarmLevel::kNormal;
};

// With a key (regional_alert.key_file), a regional alert is taken only with its
// RegionalAlertTag: the first 4 bytes of HMAC-SHA256(key, the origin frame's 8 data bytes, the
// alert frame's 8, the tag frame's Counter bytes), and a Counter above the last one taken (the
// box's run remembers it: after a restart, a recorded alert can be replayed once).
struct RegionalTagCheck {
  monitor::RegionalAuthentication authentication;
  bool pending = false;  // an alert waits for its tag
  FrameInput alert;      // that alert (kind kRegionalAlert)
  std::array<std::uint8_t, 8> origin_bytes{};
  std::array<std::uint8_t, 8> alert_bytes{};
  std::int64_t alert_time_ns = 0;
  bool any_counter = false;
  std::uint32_t last_counter = 0;
};

class FrameDecoder {
 public:
  // The sensors' nodes of `config` (resolved_sensors()), in configured order, and the statue
  // sensor's node if it has one; the counters start at zero.
  void start(const MonitorConfig& config);
  [[nodiscard]] FrameInput decode(const hal::TimedFrame& frame);
  [[nodiscard]] const FrameCounters& counters() const { return counters_; }
  // An Acknowledge frame's acknowledgement into `target` (on_frame): the monitor's update, or
  // its poll() while the bus's acknowledgements are locked out (BusStatementGuard).
  [[nodiscard]] MonitorUpdate acknowledge(Monitor& target,
                                          const monitor::Acknowledgement& acknowledgement,
                                          std::int64_t time_ns);
  [[nodiscard]] bool acknowledgements_locked_out() const { return ack_guard_.locked(); }
  // A StatueStands frame's statement into `target` (on_frame), guarded as acknowledgements are
  // (the collapse held is what a sweep would clear).
  [[nodiscard]] MonitorUpdate statue_stands(Monitor& target, const hal::can::StatueStands& stands,
                                            std::int64_t time_ns);

 private:
  // Decodes `frame`; a refusal is counted (rejected, last_error).
  template <typename Message>
  [[nodiscard]] bool decoded(const hal::can::CanFrame& frame, Message& message);
  [[nodiscard]] int sensor_of_node(std::uint8_t node) const;  // -1: not configured

  // A regional alert's two frames into one input (with a key: held for its tag).
  void decode_regional(const hal::TimedFrame& timed, FrameInput& input);
  // A RegionalAlertTag: the held alert, authenticated or refused.
  void decode_tag(const hal::TimedFrame& timed, FrameInput& input);
  // With a key, an alert still waiting for its tag when the next one begins: unauthenticated.
  void drop_untagged(FrameInput& input);
  // The field a refused regional frame names: the codec's signal, else `message` (its length
  // or reserved bits were wrong).
  [[nodiscard]] const char* refused_regional(const char* message) const;

  std::array<std::uint8_t, kMaxSensors> nodes_{};
  int count_ = 0;
  int statue_node_ = -1;  // -1: no statue sensor
  FrameCounters counters_;
  bool have_origin_ = false;  // origin_ is the latest RegionalAlertOrigin, not yet used
  hal::can::RegionalAlertOrigin origin_;
  std::array<std::uint8_t, 8> origin_bytes_{};
  std::int64_t origin_time_ns_ = 0;
  [[no_unique_address]] monitor::OptionalPart<RegionalTagCheck, monitor::kRegionalAlertBuiltIn>
      tags_;
  BusStatementGuard ack_guard_;
  BusStatementGuard stands_guard_;
};

// One frame from the bus (or a candump log) into `monitor`: its input, or, for a frame that
// carries none, the status if one is due (Monitor::poll).
[[nodiscard]] MonitorUpdate on_frame(Monitor& monitor, FrameDecoder& decoder,
                                     const hal::TimedFrame& frame);

}  // namespace plinth::firmware

// The bus's frames (hal/can_codec) as the monitor's inputs: a configured sensor's
// SensorAcceleration is its sample, the statue sensor's StatueRotation and SensorAcceleration
// its gyroscope's and accelerometer's samples, an Acknowledge an operator's acknowledgement, a
// RegionalAlert after its RegionalAlertOrigin a regional alert; every other frame, and every
// frame the codec refuses, is counted and is no input. Freestanding.
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
  std::uint64_t statue_stands = 0;        // StatueStands frames, decoded
  std::uint64_t monitor_frames = 0;  // MonitorStatus / AlarmEvent / CollapseForecast (any box's)
  std::uint64_t regional_alerts = 0;  // RegionalAlert frames taken with their origin frame
  // RegionalAlert frames without their RegionalAlertOrigin (same event and version, within
  // kRegionalPairWindowNs before), or refused by the codec: malformed alerts
  std::uint64_t regional_malformed = 0;
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

// The longest time from a RegionalAlertOrigin to its RegionalAlert frame (the bridge sends them
// back to back).
inline constexpr std::int64_t kRegionalPairWindowNs = 100'000'000;

class FrameDecoder {
 public:
  // The sensors' nodes of `config` (resolved_sensors()), in configured order, and the statue
  // sensor's node if it has one; the counters start at zero.
  void start(const MonitorConfig& config);
  [[nodiscard]] FrameInput decode(const hal::TimedFrame& frame);
  [[nodiscard]] const FrameCounters& counters() const { return counters_; }

 private:
  // Decodes `frame`; a refusal is counted (rejected, last_error).
  template <typename Message>
  [[nodiscard]] bool decoded(const hal::can::CanFrame& frame, Message& message);
  [[nodiscard]] int sensor_of_node(std::uint8_t node) const;  // -1: not configured

  // A regional alert's two frames into one input.
  void decode_regional(const hal::TimedFrame& timed, FrameInput& input);
  // The field a refused regional frame names: the codec's signal, else `message` (its length
  // or reserved bits were wrong).
  [[nodiscard]] const char* refused_regional(const char* message) const;

  std::array<std::uint8_t, kMaxSensors> nodes_{};
  int count_ = 0;
  int statue_node_ = -1;  // -1: no statue sensor
  FrameCounters counters_;
  bool have_origin_ = false;  // origin_ is the latest RegionalAlertOrigin, not yet used
  hal::can::RegionalAlertOrigin origin_;
  std::int64_t origin_time_ns_ = 0;
};

// One frame from the bus (or a candump log) into `monitor`: its input, or, for a frame that
// carries none, the status if one is due (Monitor::poll).
[[nodiscard]] MonitorUpdate on_frame(Monitor& monitor, FrameDecoder& decoder,
                                     const hal::TimedFrame& frame);

}  // namespace plinth::firmware

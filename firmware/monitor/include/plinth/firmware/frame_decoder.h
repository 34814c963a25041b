// The bus's frames (hal/can_codec) as the monitor's inputs: a configured sensor's
// SensorAcceleration is its sample, an Acknowledge an operator's acknowledgement; every other
// frame, and every frame the codec refuses, is counted and is no input. Freestanding.
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
  std::uint64_t other_nodes = 0;          // SensorAcceleration of other nodes (not used)
  std::uint64_t heartbeats = 0;           // SensorHeartbeat of any node
  std::uint64_t acknowledgements = 0;     // Acknowledge frames, decoded
  std::uint64_t monitor_frames = 0;  // MonitorStatus / AlarmEvent / CollapseForecast (any box's)
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
  };
  Kind kind = Kind::kNone;
  int sensor = -1;  // its index in the configured order
  monitor::SensorSample sample;
  monitor::Acknowledgement acknowledgement;
};

class FrameDecoder {
 public:
  // The sensors' nodes of `config` (resolved_sensors()), in configured order; the counters
  // start at zero.
  void start(const MonitorConfig& config);
  [[nodiscard]] FrameInput decode(const hal::TimedFrame& frame);
  [[nodiscard]] const FrameCounters& counters() const { return counters_; }

 private:
  // Decodes `frame`; a refusal is counted (rejected, last_error).
  template <typename Message>
  [[nodiscard]] bool decoded(const hal::can::CanFrame& frame, Message& message);
  [[nodiscard]] int sensor_of_node(std::uint8_t node) const;  // -1: not configured

  std::array<std::uint8_t, kMaxSensors> nodes_{};
  int count_ = 0;
  FrameCounters counters_;
};

// One frame from the bus (or a candump log) into `monitor`: its input, or, for a frame that
// carries none, the status if one is due (Monitor::poll).
[[nodiscard]] MonitorUpdate on_frame(Monitor& monitor, FrameDecoder& decoder,
                                     const hal::TimedFrame& frame);

}  // namespace plinth::firmware

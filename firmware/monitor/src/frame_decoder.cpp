#include "plinth/firmware/frame_decoder.h"

#include "plinth/firmware/can_frames.h"

namespace plinth::firmware {

// The CAN protocol (hal/can_codec).
namespace can = hal::can;

void FrameDecoder::start(const MonitorConfig& config) {
  std::array<SensorConfig, kMaxSensors> sensors{};
  count_ = resolved_sensors(config, sensors);
  for (int i = 0; i < count_; ++i) {
    nodes_[static_cast<std::size_t>(i)] = sensors[static_cast<std::size_t>(i)].node;
  }
  const StatueSensorSettings* statue =
      monitor::built_part<StatueSensorSettings>(config.statue_sensor);
  statue_node_ = statue != nullptr && statue->present ? statue->node : -1;
  counters_ = FrameCounters{};
  have_origin_ = false;
}

template <typename Message>
bool FrameDecoder::decoded(const can::CanFrame& frame, Message& message) {
  const can::DecodeResult r = can::decode(frame, message);
  if (r.ok()) return true;
  ++counters_.rejected;
  counters_.last_error = r.error;
  counters_.last_error_signal = r.signal;
  return false;
}

// What a regional frame the codec refused names: the signal at fault, else (its length, its
// reserved bits) the frame itself, so that every refusal says what was wrong.
const char* FrameDecoder::refused_regional(const char* message) const {
  return counters_.last_error_signal[0] != '\0' ? counters_.last_error_signal : message;
}

int FrameDecoder::sensor_of_node(std::uint8_t node) const {
  for (int i = 0; i < count_; ++i) {
    if (nodes_[static_cast<std::size_t>(i)] == node) return i;
  }
  return -1;
}

FrameInput FrameDecoder::decode(const hal::TimedFrame& timed) {
  ++counters_.received;
  FrameInput input;
  const can::CanFrame& frame = timed.frame;
  switch (can::classify(frame.id)) {
    case can::MessageKind::kSensorAcceleration: {
      can::SensorAcceleration message;
      if (!decoded(frame, message)) break;
      input.sensor = sensor_of_node(message.node);
      if (input.sensor < 0 && message.node == statue_node_) {
        ++counters_.statue_accelerations;
        input.kind = FrameInput::Kind::kStatueAcceleration;
        input.sample = sample_of(message, timed.timestamp_ns);
        break;
      }
      if (input.sensor < 0) {
        ++counters_.other_nodes;
        break;
      }
      ++counters_.sensor_samples;
      input.kind = FrameInput::Kind::kSensorSample;
      input.sample = sample_of(message, timed.timestamp_ns);
      break;
    }
    case can::MessageKind::kSensorHeartbeat: {
      can::SensorHeartbeat message;
      if (decoded(frame, message)) ++counters_.heartbeats;
      break;
    }
    case can::MessageKind::kAcknowledge: {
      can::Acknowledge message;
      if (!decoded(frame, message)) break;
      ++counters_.acknowledgements;
      input.kind = FrameInput::Kind::kAcknowledgement;
      input.acknowledgement = acknowledgement_of(message);
      break;
    }
    case can::MessageKind::kStatueStands: {
      if (!decoded(frame, input.stands)) break;
      ++counters_.statue_stands;
      input.kind = FrameInput::Kind::kStatueStands;
      break;
    }
    case can::MessageKind::kMonitorStatus: {
      can::MonitorStatus message;
      if (decoded(frame, message)) ++counters_.monitor_frames;
      break;
    }
    case can::MessageKind::kAlarmEvent: {
      can::AlarmEvent message;
      if (decoded(frame, message)) ++counters_.monitor_frames;
      break;
    }
    case can::MessageKind::kCollapseForecast: {
      can::CollapseForecast message;
      if (decoded(frame, message)) ++counters_.monitor_frames;
      break;
    }
    case can::MessageKind::kStatueRotation: {
      can::StatueRotation message;
      if (!decoded(frame, message)) break;
      if (message.node != statue_node_) {
        ++counters_.other_nodes;
        break;
      }
      ++counters_.statue_rates;
      input.kind = FrameInput::Kind::kStatueRate;
      input.statue = sample_of(message, timed.timestamp_ns);
      break;
    }
    case can::MessageKind::kRegionalAlertOrigin: {
      if constexpr (!monitor::kRegionalAlertBuiltIn) {
        ++counters_.unknown_identifiers;
        break;
      }
      can::RegionalAlertOrigin message;
      have_origin_ = decoded(frame, message);
      if (have_origin_) {
        origin_ = message;
        origin_time_ns_ = timed.timestamp_ns;
      } else {
        ++counters_.regional_malformed;
        input.kind = FrameInput::Kind::kRegionalMalformed;
        input.malformed_field = refused_regional("RegionalAlertOrigin");
      }
      break;
    }
    case can::MessageKind::kRegionalAlert:
      if constexpr (!monitor::kRegionalAlertBuiltIn) {
        ++counters_.unknown_identifiers;
        break;
      }
      decode_regional(timed, input);
      break;
    case can::MessageKind::kUnknown:
      ++counters_.unknown_identifiers;
      break;
  }
  return input;
}

void FrameDecoder::decode_regional(const hal::TimedFrame& timed, FrameInput& input) {
  can::RegionalAlert message;
  input.kind = FrameInput::Kind::kRegionalMalformed;
  if (!decoded(timed.frame, message)) {
    ++counters_.regional_malformed;
    input.malformed_field = refused_regional("RegionalAlert");
    return;
  }
  const std::int64_t gap_ns = timed.timestamp_ns - origin_time_ns_;
  if (!have_origin_ || origin_.event_id != message.event_id ||
      origin_.version != message.version || gap_ns < 0 || gap_ns > kRegionalPairWindowNs) {
    ++counters_.regional_malformed;
    input.malformed_field = "RegionalAlertOrigin";  // missing, another alert's, or too old
    return;
  }
  have_origin_ = false;
  ++counters_.regional_alerts;
  input.kind = FrameInput::Kind::kRegionalAlert;
  input.regional = regional_alert_of(origin_, message, static_cast<double>(gap_ns) * 1e-9);
}

MonitorUpdate on_frame(Monitor& monitor, FrameDecoder& decoder, const hal::TimedFrame& frame) {
  const FrameInput input = decoder.decode(frame);
  switch (input.kind) {
    case FrameInput::Kind::kSensorSample:
      return monitor.on_sensor_sample(input.sensor, input.sample);
    case FrameInput::Kind::kAcknowledgement:
      return monitor.acknowledge(input.acknowledgement);
    case FrameInput::Kind::kStatueStands: {
      MonitorUpdate update = monitor.statue_stands(input.stands.event_sequence);
      update.stands_source = input.stands.source_id;
      return update;
    }
    case FrameInput::Kind::kStatueRate:
      return monitor.on_statue_sample(input.statue);
    case FrameInput::Kind::kStatueAcceleration:
      return monitor.on_statue_acceleration(input.sample);
    case FrameInput::Kind::kRegionalAlert:
      return monitor.on_regional_alert(input.regional, frame.timestamp_ns);
    case FrameInput::Kind::kRegionalMalformed:
      return monitor.regional_alert_malformed(input.malformed_field);
    case FrameInput::Kind::kNone:
      break;
  }
  return monitor.poll();
}

}  // namespace plinth::firmware

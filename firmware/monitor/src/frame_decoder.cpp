#include "plinth/firmware/frame_decoder.h"

#include "plinth/firmware/can_frames.h"
#include "plinth/monitor/hmac_sha256.h"

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
  if (auto* tags = monitor::built_part<RegionalTagCheck>(tags_)) {
    const auto* room = monitor::built_part<monitor::RegionalAlertSettings>(config.regional);
    *tags = RegionalTagCheck{};
    if (room != nullptr) tags->authentication = room->authentication;
  }
  ack_guard_ = BusStatementGuard{};
  stands_guard_ = BusStatementGuard{};
}

bool BusStatementGuard::admits(monitor::AlarmLevel held) {
  // The lockout holds while what it began under stays held.
  if (locked_ && held != locked_level_) locked_ = false;
  return !locked_;
}

bool BusStatementGuard::refused(std::int64_t time_ns, monitor::AlarmLevel held) {
  refused_ns_[static_cast<std::size_t>(next_)] = time_ns;
  next_ = (next_ + 1) % kRefusedStatementsBeforeLockout;
  if (refused_count_ < kRefusedStatementsBeforeLockout) ++refused_count_;
  // The oldest of the last kRefusedStatementsBeforeLockout refusals, within the window.
  const std::int64_t oldest = refused_ns_[static_cast<std::size_t>(next_)];
  if (refused_count_ < kRefusedStatementsBeforeLockout ||
      time_ns - oldest > kRefusedStatementWindowNs || held == monitor::AlarmLevel::kNormal) {
    return false;
  }
  locked_ = true;
  locked_level_ = held;
  refused_count_ = 0;
  return true;
}

MonitorUpdate FrameDecoder::acknowledge(Monitor& target,
                                        const monitor::Acknowledgement& acknowledgement,
                                        std::int64_t time_ns) {
  const monitor::AlarmLevel latched = target.status().latched;
  if (!ack_guard_.admits(latched)) {
    ++counters_.acknowledgements_ignored;
    return target.poll();
  }
  MonitorUpdate update = target.acknowledge(acknowledgement);
  if (update.acknowledgement == monitor::AckOutcome::kStale ||
      update.acknowledgement == monitor::AckOutcome::kWrongLevel) {
    ++counters_.acknowledgements_refused;
    if (ack_guard_.refused(time_ns, latched)) ++counters_.acknowledgement_lockouts;
  }
  return update;
}

namespace {

// What a held collapse is to the stands guard: the level it holds, or nothing.
monitor::AlarmLevel collapse_held(const Monitor& target) {
  return target.status().collapse.held ? monitor::AlarmLevel::kAlarm
                                       : monitor::AlarmLevel::kNormal;
}

}  // namespace

MonitorUpdate FrameDecoder::statue_stands(Monitor& target, const can::StatueStands& stands,
                                          std::int64_t time_ns) {
  const monitor::AlarmLevel held = collapse_held(target);
  if (!stands_guard_.admits(held)) {
    ++counters_.statue_stands_ignored;
    return target.poll();
  }
  MonitorUpdate update = target.statue_stands(stands.event_sequence);
  update.stands_source = stands.source_id;
  if (update.statue_stands == monitor::StandsOutcome::kStale) {
    ++counters_.statue_stands_refused;
    if (stands_guard_.refused(time_ns, held)) ++counters_.statue_stands_lockouts;
  }
  return update;
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
      drop_untagged(input);  // the alert before never got its tag
      can::RegionalAlertOrigin message;
      have_origin_ = decoded(frame, message);
      if (have_origin_) {
        origin_ = message;
        origin_bytes_ = frame.data;
        origin_time_ns_ = timed.timestamp_ns;
      } else {
        ++counters_.regional_malformed;
        if (input.kind == FrameInput::Kind::kNone) {  // one input a frame: the untagged's first
          input.kind = FrameInput::Kind::kRegionalMalformed;
          input.malformed_field = refused_regional("RegionalAlertOrigin");
        }
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
    case can::MessageKind::kRegionalAlertTag:
      if constexpr (monitor::kRegionalAlertBuiltIn) {
        decode_tag(timed, input);
      } else {
        ++counters_.unknown_identifiers;  // no room, no tag, no SHA-256 in the image
      }
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
  RegionalTagCheck* tags = monitor::built_part<RegionalTagCheck>(tags_);
  if (tags == nullptr || !tags->authentication.required) return;
  // Held for its tag; an alert before it still waiting is refused now.
  FrameInput held = input;
  input = FrameInput{};
  drop_untagged(input);
  tags->pending = true;
  tags->alert = held;
  tags->origin_bytes = origin_bytes_;
  tags->alert_bytes = timed.frame.data;
  tags->alert_time_ns = timed.timestamp_ns;
}

void FrameDecoder::drop_untagged(FrameInput& input) {
  RegionalTagCheck* tags = monitor::built_part<RegionalTagCheck>(tags_);
  if (tags == nullptr || !tags->pending) return;
  tags->pending = false;
  ++counters_.regional_unauthenticated;
  input.kind = FrameInput::Kind::kRegionalUnauthenticated;
  input.malformed_field = "RegionalAlertTag";  // missing
}

void FrameDecoder::decode_tag(const hal::TimedFrame& timed, FrameInput& input) {
  can::RegionalAlertTag message;
  if (!decoded(timed.frame, message)) return;  // only its length can be wrong: counted
  ++counters_.regional_tags;
  RegionalTagCheck* tags = monitor::built_part<RegionalTagCheck>(tags_);
  if (tags == nullptr || !tags->authentication.required || !tags->pending) return;  // ignored
  const std::int64_t gap_ns = timed.timestamp_ns - tags->alert_time_ns;
  if (gap_ns < 0 || gap_ns > kRegionalPairWindowNs) return drop_untagged(input);
  tags->pending = false;
  const monitor::ByteSpan parts[] = {{tags->origin_bytes.data(), tags->origin_bytes.size()},
                                     {tags->alert_bytes.data(), tags->alert_bytes.size()},
                                     {timed.frame.data.data(), 4}};
  const monitor::Sha256Digest mac =
      monitor::hmac_sha256(tags->authentication.key, parts, sizeof parts / sizeof parts[0]);
  const bool replayed = tags->any_counter && message.counter <= tags->last_counter;
  if (!monitor::same_bytes(mac.data(), timed.frame.data.data() + 4, 4) || replayed) {
    ++counters_.regional_unauthenticated;
    input.kind = FrameInput::Kind::kRegionalUnauthenticated;
    input.malformed_field = replayed ? "Counter" : "Tag";
    return;
  }
  tags->any_counter = true;
  tags->last_counter = message.counter;
  input = tags->alert;
  // Its times were relative to the alert frame; the tag came `gap` later.
  const auto gap_s = static_cast<Real>(static_cast<double>(gap_ns) * 1e-9);
  input.regional.origin_age_s += gap_s;
  input.regional.s_arrival_in_s -= gap_s;
}

MonitorUpdate on_frame(Monitor& monitor, FrameDecoder& decoder, const hal::TimedFrame& frame) {
  const FrameInput input = decoder.decode(frame);
  switch (input.kind) {
    case FrameInput::Kind::kSensorSample:
      return monitor.on_sensor_sample(input.sensor, input.sample);
    case FrameInput::Kind::kAcknowledgement:
      return decoder.acknowledge(monitor, input.acknowledgement, frame.timestamp_ns);
    case FrameInput::Kind::kStatueStands:
      return decoder.statue_stands(monitor, input.stands, frame.timestamp_ns);
    case FrameInput::Kind::kStatueRate:
      return monitor.on_statue_sample(input.statue);
    case FrameInput::Kind::kStatueAcceleration:
      return monitor.on_statue_acceleration(input.sample);
    case FrameInput::Kind::kRegionalAlert:
      return monitor.on_regional_alert(input.regional, frame.timestamp_ns);
    case FrameInput::Kind::kRegionalMalformed:
      return monitor.regional_alert_malformed(input.malformed_field);
    case FrameInput::Kind::kRegionalUnauthenticated:
      return monitor.regional_alert_refused(plinth::monitor::RegionalRefusal::kUnauthenticated,
                                            input.malformed_field);
    case FrameInput::Kind::kNone:
      break;
  }
  return monitor.poll();
}

}  // namespace plinth::firmware

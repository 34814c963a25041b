#include "commission_session.h"

namespace plinth::firmware {

namespace can = hal::can;

namespace {

// Counts one frame of a node's stream: its sequence against the previous one's.
void count(NodeTraffic& traffic, double t, bool has_sequence, std::uint8_t sequence,
           std::uint8_t status) {
  if (traffic.frames == 0) traffic.first_t = t;
  ++traffic.frames;
  traffic.last_t = t;
  traffic.status_flags |= status;
  if (!has_sequence) return;
  if (traffic.have_sequence) {
    const auto step = static_cast<std::uint8_t>(sequence - traffic.last_sequence);
    if (step != 1) {
      ++traffic.sequence_breaks;
      if (step != 0 && step < 128) traffic.lost += step - 1U;
    }
  }
  traffic.have_sequence = true;
  traffic.last_sequence = sequence;
}

}  // namespace

double NodeTraffic::rate_hz() const {
  if (frames < 2 || last_t <= first_t) return 0.0;
  return static_cast<double>(frames - 1) / (last_t - first_t);
}

void SessionRecording::take(const hal::TimedFrame& timed) {
  if (!started_) {
    started_ = true;
    start_ns_ = timed.timestamp_ns;
  }
  ++frames_;
  const double t = seconds(timed.timestamp_ns);
  if (t > last_t_) last_t_ = t;
  const can::CanFrame& frame = timed.frame;
  switch (can::classify(frame.id)) {
    case can::MessageKind::kSensorAcceleration: {
      can::SensorAcceleration m;
      NodeRecording& node = nodes_[frame.id - can::kSensorAccelerationBaseId];
      if (!can::decode(frame, m).ok()) {
        ++node.acceleration_traffic.rejected;
        return;
      }
      count(node.acceleration_traffic, t, true, m.sequence, m.status);
      node.accelerations.push_back({t, Eigen::Vector3d(m.ax_g, m.ay_g, m.az_g), m.status});
      return;
    }
    case can::MessageKind::kStatueRotation: {
      can::StatueRotation m;
      NodeRecording& node = nodes_[frame.id - can::kStatueRotationBaseId];
      if (!can::decode(frame, m).ok()) {
        ++node.rate_traffic.rejected;
        return;
      }
      count(node.rate_traffic, t, true, m.sequence, m.status);
      node.rates.push_back({t, Eigen::Vector3d(m.wx_rad_s, m.wy_rad_s, m.wz_rad_s), m.status});
      return;
    }
    case can::MessageKind::kSensorHeartbeat: {
      can::SensorHeartbeat m;
      NodeRecording& node = nodes_[frame.id - can::kSensorHeartbeatBaseId];
      if (!can::decode(frame, m).ok()) {
        ++node.heartbeat_traffic.rejected;
        return;
      }
      count(node.heartbeat_traffic, t, false, 0, m.status);
      return;
    }
    case can::MessageKind::kMonitorStatus:
    case can::MessageKind::kAlarmEvent:
    case can::MessageKind::kCollapseForecast:
      ++monitor_frames_;
      return;
    default:
      ++other_frames_;
      return;
  }
}

}  // namespace plinth::firmware

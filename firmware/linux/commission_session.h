// plinth-commission's recording of a session (docs/commissioning.md): every frame of the bus or
// of a candump log, decoded by node into the accelerometers' and gyroscopes' samples, with a
// census of who spoke (frames per node and kind, sequence breaks, status flags). Host code:
// allocates.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "plinth/hal/can_codec.h"
#include "plinth/hal/frame_io.h"

namespace plinth::firmware {

// One sample, as the node sent it: sensor frame, the frame's unit (g, or rad/s). t: s since
// the session's first frame.
struct NodeSample {
  double t = 0.0;
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
  std::uint8_t status = 0;  // the frame's sensor_status flags
};

// What one node sent of one message kind.
struct NodeTraffic {
  std::uint64_t frames = 0;           // decoded
  std::uint64_t rejected = 0;         // refused by the codec (length, range, reserved bits)
  std::uint64_t sequence_breaks = 0;  // a Sequence other than the previous one's + 1
  std::uint64_t lost = 0;             // samples the breaks skipped, when they went forward by < 128
  std::uint8_t status_flags = 0;      // every flag any of its frames set
  double first_t = 0.0;
  double last_t = 0.0;
  bool have_sequence = false;
  std::uint8_t last_sequence = 0;

  // Frames per second over first_t..last_t (0 with fewer than 2 frames).
  [[nodiscard]] double rate_hz() const;
};

inline constexpr int kNodeSlots = hal::can::kLastSensorNode + 1;  // index = node id

struct NodeRecording {
  std::vector<NodeSample> accelerations;  // SensorAcceleration, g
  std::vector<NodeSample> rates;          // StatueRotation, rad/s
  NodeTraffic acceleration_traffic;
  NodeTraffic rate_traffic;
  NodeTraffic heartbeat_traffic;
};

class SessionRecording {
 public:
  // One frame, at its receive (or logged) time.
  void take(const hal::TimedFrame& frame);

  [[nodiscard]] const NodeRecording& node(int id) const {
    return nodes_[static_cast<std::size_t>(id)];
  }
  // Seconds from the first frame to the latest.
  [[nodiscard]] double duration_s() const { return last_t_; }
  [[nodiscard]] bool started() const { return started_; }
  [[nodiscard]] std::int64_t start_ns() const { return start_ns_; }
  // s since the session's first frame of a receive time.
  [[nodiscard]] double seconds(std::int64_t time_ns) const {
    return started_ ? static_cast<double>(time_ns - start_ns_) * 1e-9 : 0.0;
  }
  [[nodiscard]] std::uint64_t frames() const { return frames_; }
  // MonitorStatus, AlarmEvent, CollapseForecast: a box on the bus (not a sensor's).
  [[nodiscard]] std::uint64_t monitor_frames() const { return monitor_frames_; }
  // Any other frame: acknowledgements, regional alerts, identifiers outside plinth's table.
  [[nodiscard]] std::uint64_t other_frames() const { return other_frames_; }

 private:
  std::array<NodeRecording, kNodeSlots> nodes_{};
  bool started_ = false;
  std::int64_t start_ns_ = 0;
  double last_t_ = 0.0;
  std::uint64_t frames_ = 0;
  std::uint64_t monitor_frames_ = 0;
  std::uint64_t other_frames_ = 0;
};

}  // namespace plinth::firmware

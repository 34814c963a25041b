// The box's main loop, without the operating system: CAN frames (or decoded sensor samples) in;
// sensor health, conditioning, one planar estimator per modelled axis, the overturning risk
// and the alarm policy; a status and alarm events out. Freestanding like lib/core: no heap, no
// exceptions; everything is sized at compile time and set up once by start().
//
//   frame --codec--> SensorSample --SensorHealthTracker--> fed samples (bridged, restarts)
//     --Conditioner--> ground acceleration in the statue frame (m/s2)
//     --PlanarEstimator per axis (x: statue axis 1, y: axis 2; z feeds g + v_G'')-->
//     phase, state --overturning_risk--> risk --AlarmPolicy--> level, events
//
// Time: monitor time is ns since the first sensor sample's receive time. The estimator starts
// (at rest, full contact) with the first sample that conditioning marks ready, and starts again
// at rest on a sample the health tracker marks `restart` (after a fault nothing is known of
// what happened meanwhile; the fault level shows it).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/estimator.h"
#include "plinth/core/events.h"
#include "plinth/core/risk.h"
#include "plinth/core/scene.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/frame_io.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/conditioning.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

inline constexpr int kMaxAxes = 2;

struct MonitorConfig {
  int axis_count = 1;  // 1: the statue's first principal axis; 2: both
  std::uint8_t ground_node = 1;  // CAN node id of the ground accelerometer, 1..15
  EstimatorSettings estimator;   // sample rate (= the sensor's) and solver steps per sample
  RiskSettings risk;
  monitor::ConditioningSettings conditioning;  // its sample period is the estimator's
  monitor::SensorHealthSettings sensor_health;  // its sample period is the estimator's
  monitor::AlarmPolicySettings alarm;
  // Quiet (offset tracking allowed): every axis at rest in full contact with risk below this.
  double quiet_risk = 1e-3;
};

// Checks every part; the Error names the field ("monitor.axis_count", "estimator....", ...).
[[nodiscard]] Error validate(const MonitorConfig& config);

struct AxisStatus {
  Mode mode;
  State state = State::Zero();
  Risk risk;
};

// Frames that were not sensor samples of the ground node, or could not be decoded.
struct FrameCounters {
  std::uint64_t received = 0;
  std::uint64_t sensor_samples = 0;       // SensorAcceleration of the ground node, decoded
  std::uint64_t other_nodes = 0;          // SensorAcceleration of other nodes (not used)
  std::uint64_t heartbeats = 0;           // SensorHeartbeat of any node
  std::uint64_t acknowledgements = 0;     // Acknowledge frames, decoded
  std::uint64_t monitor_frames = 0;       // MonitorStatus / AlarmEvent (ours or another box's)
  std::uint64_t rejected = 0;             // failed to decode (length, range, reserved bits)
  std::uint64_t unknown_identifiers = 0;  // not a plinth identifier
  can::CodecError last_error = can::CodecError::kOk;  // of the latest rejected frame
  const char* last_error_signal = "";
};

struct MonitorStatus {
  std::int64_t time_ns = 0;  // monitor time of the newest sample (or tick)
  bool estimating = false;   // conditioning ready and the estimators running
  int axis_count = 1;
  std::array<AxisStatus, kMaxAxes> axes{};
  double risk = 0.0;  // the worst axis's total
  monitor::AlarmLevel alarm = monitor::AlarmLevel::kNormal;
  monitor::AlarmLevel latched = monitor::AlarmLevel::kNormal;
  monitor::SensorHealth sensor;
  std::uint64_t estimator_restarts = 0;  // starts of the estimators (the first one included)
  std::int64_t estimator_start_ns = 0;   // monitor time of the estimators' latest start (t = 0)
  std::int64_t newest_sample_time_ns = 0;  // monitor time of the newest sample fed
};

// What one input did.
struct MonitorUpdate {
  std::array<monitor::AlarmEventRecord, 2 * monitor::kMaxEventsPerUpdate> events{};
  std::size_t event_count = 0;
  bool status_due = false;  // the heartbeat period passed or an event happened: send a status
  monitor::AckOutcome acknowledgement = monitor::AckOutcome::kNone;
};

class Monitor {
 public:
  Monitor() = default;
  // The estimators refer to their own input streams: a Monitor stays where it was started.
  Monitor(const Monitor&) = delete;
  Monitor& operator=(const Monitor&) = delete;

  // `scenes[i]` is the planar model of axis i; they must outlive the monitor.
  [[nodiscard]] Error start(const MonitorConfig& config,
                            const std::array<const Scene*, kMaxAxes>& scenes);

  // Phase changes and impacts of axis `axis` go to `sink` (nullptr: nowhere).
  void set_event_sink(int axis, EventSink* sink);

  // One frame from the bus (or a candump log).
  [[nodiscard]] MonitorUpdate on_frame(const hal::TimedFrame& frame);
  // One decoded sample of the ground node (file replay feeds these directly).
  [[nodiscard]] MonitorUpdate on_sample(const monitor::SensorSample& sample);
  // Call periodically with the receive clock's time: sensor timeouts, heartbeats.
  [[nodiscard]] MonitorUpdate on_tick(std::int64_t receive_time_ns);
  // Bus trouble reported by the frame source (bus-off, dropped frames): raises the fault level
  // until `active` is cleared.
  void set_bus_fault(bool active) { bus_fault_ = active; }

  [[nodiscard]] const MonitorStatus& status() const { return status_; }
  [[nodiscard]] const FrameCounters& frames() const { return frames_; }
  [[nodiscard]] const monitor::ConditioningStatus& conditioning() const {
    return conditioner_.status();
  }
  [[nodiscard]] const MonitorConfig& config() const { return config_; }
  // Records that a status went out (resets the heartbeat).
  void status_sent() { alarm_.heartbeat_sent(status_.time_ns); }

 private:
  void feed(const monitor::FedSample& sample);
  void evaluate(MonitorUpdate& update);
  [[nodiscard]] std::int64_t monitor_time(std::int64_t receive_time_ns);

  MonitorConfig config_;
  std::array<const Scene*, kMaxAxes> scenes_{};
  std::array<PlanarEstimator, kMaxAxes> estimators_{};
  std::array<EventSink*, kMaxAxes> sinks_{};
  monitor::SensorHealthTracker health_;
  monitor::Conditioner conditioner_;
  monitor::AlarmPolicy alarm_;
  MonitorStatus status_;
  FrameCounters frames_;
  bool have_epoch_ = false;
  std::int64_t epoch_ns_ = 0;  // receive time of the first sample
  bool bus_fault_ = false;
  bool pending_ack_ = false;
  monitor::Acknowledgement ack_;
};

}  // namespace plinth::firmware

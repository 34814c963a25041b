// The box's loop, without the operating system: CAN frames (or decoded sensor samples) in;
// sensor health, conditioning, one planar estimator per modelled axis, the overturning risk
// and the alarm policy; a status and alarm events out. Freestanding like lib/core: no heap, no
// exceptions; everything is sized at compile time and set up once by start().
//
//   frame --codec--> SensorSample --SensorHealthTracker (one per sensor)--> fed samples
//     --Conditioner (one per sensor)--> acceleration in the statue frame (m/s2), kept in the
//     sensor's history (its last kSensorHistory samples)
//   the primary ground sensor's samples --an ensemble of PlanarEstimators per axis (x: statue
//     axis 1, y: axis 2; z feeds g + v_G''; member 0 the nominal statue, the others the corners
//     of the scene's declared uncertainty)--> phase, state per member --overturning_risk--> the
//     worst member's risk; --Forecaster per axis (forecast.h)--> the probability of a collapse
//     within the horizon, its worst member and time --AlarmPolicy--> level, events
//   events, and the status at status_interval_s --can_frames.h--> frames ready to send (with
//     each status, while forecasting, a CollapseForecast per axis that has a forecast)
//   the other ground sensors' samples --cross-check against the primary--> disagreement
//   the plate sensor's samples --compared with the model's base acceleration--> residual
//
// Sensors. Up to kMaxSensors accelerometers, each with its own node, role, health tracker and
// conditioner (unit, mounting rotation, offset). The single-sensor form (sensor_count = 0) is
// one ground sensor: ground_node, conditioning, sensor_health.
//  - Ground sensors (at least one): the primary drives the estimators. It is the first usable
//    ground sensor in configured order (usable: health not fault, conditioning ready) when the
//    estimators start; afterwards it stays primary until it faults (no switching back when an
//    earlier sensor recovers: every switch is a seam in the estimators' input). Then the first
//    usable ground sensor in configured order takes over (a failover): when the new primary's
//    history continues the stream within the bridge limit ((max_bridge_samples + 1) sample
//    periods after the last sample the estimators took), the estimators continue from their
//    state on its samples (a short seam is bridged by linear interpolation); otherwise they
//    start again at rest on its newest sample, as after a fault. With no usable ground sensor
//    left, the primary's fault is the fault level, as with one sensor.
//  - Cross-check: each other usable ground sensor's samples are paired with the primary's at
//    the same receive time (linear interpolation between the primary's two samples around it,
//    or its nearest sample within one period; samples of different nodes are not synchronous)
//    and the RMS of the difference (all three axes, m/s2) over redundancy.window_s is compared
//    with redundancy.tolerance_m_s2. Beyond it the sensors disagree: counted, reported, and the
//    alarm policy's fault input is raised with cause kSensorDisagreement (the estimators' input
//    is not trusted while two sensors of the same ground disagree; the alarm policy never hides
//    an alarm behind a fault). Which of the two is wrong is not decided.
//  - Plate sensor (at most one, on the isolation plate): its horizontal acceleration measures
//    the base's absolute acceleration u'' + u_G''. It never drives the estimators; it is paired
//    with the estimators' own u'' + u_G'' (Simulator::accelerations() of the current mode, plus
//    the ground's) and the RMS of the difference over plate.window_s is the model-mismatch
//    residual, beyond plate.threshold_m_s2 a mismatch: counted and reported (degraded), and
//    raising the fault level with kSensorDisagreement only when plate.raises_fault (impacts at
//    the stops and on the block make the residual jump while the model is right).
//  - A sensor other than the one driving the estimators in fault (a lost redundant or plate
//    sensor), a disagreement or a mismatch make the sensors' state degraded (status, summary).
//
// Time: monitor time is ns since the first sensor sample's receive time. The estimator starts
// (at rest, full contact) with the first sample that conditioning marks ready, and starts again
// at rest on a sample the health tracker marks `restart` (after a fault nothing is known of
// what happened meanwhile; the fault level shows it).
//
// Start-up rule (docs/monitor.md): the estimators' offset and initial state (at rest) are
// trusted only when a window that passed conditioning's quietness test ends at the sample they
// start on (`calibrated`). Any other start (after a sensor fault, a failover without
// continuity) leaves them uncalibrated: they run, but the primary's conditioner verifies a new
// window and they are calibrated when one passes. The level is never normal while the
// estimators do not run or are not calibrated: the alarm policy's fault, cause kNotCalibrated
// (an alarm still shows above it).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "plinth/core/ensemble.h"
#include "plinth/core/error.h"
#include "plinth/core/estimator.h"
#include "plinth/core/events.h"
#include "plinth/core/forecast.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/firmware/box_status.h"
#include "plinth/firmware/config.h"
#include "plinth/firmware/sensor_set.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/frame_io.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/conditioning.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// An update's alarm events: each update evaluates the alarm policy once.
inline constexpr std::size_t kMaxUpdateEvents = monitor::kMaxEventsPerUpdate;
// An AlarmEvent per event, then a MonitorStatus per axis, then a CollapseForecast per axis.
inline constexpr std::size_t kMaxFramesPerUpdate =
    kMaxUpdateEvents + 2 * static_cast<std::size_t>(kMaxAxes);

// What one input did: the status after it, its alarm events, and the frames to send for it, in
// order. The outputs read it alone.
struct MonitorUpdate {
  // The monitor's status after the input (Monitor::status(): valid until its next input).
  const BoxStatus* status = nullptr;
  std::array<monitor::AlarmEventRecord, kMaxUpdateEvents> events{};
  std::size_t event_count = 0;
  // A status is due (status_interval_s, an alarm change or the alarm policy's heartbeat): its
  // frames are in `frames`.
  bool status_due = false;
  // What came of an acknowledgement (Monitor::acknowledge); kNone for other inputs.
  monitor::AckOutcome acknowledgement = monitor::AckOutcome::kNone;
  std::array<hal::can::CanFrame, kMaxFramesPerUpdate> frames{};  // frames[0 .. frame_count)
  std::size_t frame_count = 0;
};

class Monitor {
 public:
  Monitor() = default;
  // The estimators refer to their own input streams: a Monitor stays where it was started.
  Monitor(const Monitor&) = delete;
  Monitor& operator=(const Monitor&) = delete;

  // `ensembles[i]` are the statues of axis i, the nominal one first (at most
  // kMaxEnsembleMembers); they must outlive the monitor.
  [[nodiscard]] Error start(const MonitorConfig& config,
                            const std::array<std::span<const Scene>, kMaxAxes>& ensembles);
  // One statue per axis: `scenes[i]` is the planar model of axis i.
  [[nodiscard]] Error start(const MonitorConfig& config,
                            const std::array<const Scene*, kMaxAxes>& scenes);

  // Phase changes and impacts of axis `axis` go to `sink` (nullptr: nowhere).
  void set_event_sink(int axis, EventSink* sink);

  // One decoded sample of the first sensor (the ground node of the single-sensor form; file
  // replay feeds these directly).
  [[nodiscard]] MonitorUpdate on_sample(const monitor::SensorSample& sample) {
    return on_sensor_sample(0, sample);
  }
  // One decoded sample of sensor `sensor` (its index in the configured order).
  [[nodiscard]] MonitorUpdate on_sensor_sample(int sensor, const monitor::SensorSample& sample);
  // Call periodically with the receive clock's time: sensor timeouts, heartbeats.
  [[nodiscard]] MonitorUpdate on_tick(std::int64_t receive_time_ns);
  // An operator acknowledges the latched level, quoting the latest alarm event (from the bus,
  // Modbus or MQTT): evaluated at once, at the current monitor time; the update says what came
  // of it (MonitorUpdate::acknowledgement).
  [[nodiscard]] MonitorUpdate acknowledge(const monitor::Acknowledgement& acknowledgement);
  // No input (a frame that is none of the monitor's): the status, if one is due; the alarm
  // policy's first evaluation if none happened since start() (so that no status says the
  // policy's initial `normal`).
  [[nodiscard]] MonitorUpdate poll();
  // Bus trouble reported by the frame source (bus-off, dropped frames): raises the fault level
  // until `active` is cleared.
  void set_bus_fault(bool active) { bus_fault_ = active; }

  [[nodiscard]] const BoxStatus& status() const { return status_; }
  // Frames to send that the codec refused (left out of their update) since start().
  [[nodiscard]] std::uint64_t frames_not_encoded() const { return frames_not_encoded_; }
  // The primary's conditioning (before the first primary: the first sensor's).
  [[nodiscard]] const monitor::ConditioningStatus& conditioning() const {
    return conditioning(status_.primary < 0 ? 0 : status_.primary);
  }
  [[nodiscard]] const monitor::ConditioningStatus& conditioning(int sensor) const {
    return sensors_.conditioning(sensor);
  }
  // The statues of `axis`: their estimators, forecaster and risk.
  [[nodiscard]] const Ensemble& ensemble(int axis) const {
    return ensembles_[static_cast<std::size_t>(axis)];
  }
  // The sensors as started (the single-sensor form resolved).
  [[nodiscard]] const SensorConfig& sensor_config(int sensor) const {
    return sensors_.config(sensor);
  }
  [[nodiscard]] const MonitorConfig& config() const { return config_; }

 private:
  // The estimators take the inputs the sensors have for them (SensorSet::next_input).
  void feed_estimators();
  void push_ensembles(const Vector3r& ground_m_s2);
  [[nodiscard]] bool quiet() const;
  [[nodiscard]] MonitorUpdate new_update() const;
  void take_sample(int sensor, const monitor::SensorSample& sample, MonitorUpdate& update);
  void update_axis(int axis_index, AxisStatus& axis) const;
  void update_axes_status();
  void evaluate(MonitorUpdate& update);
  void report(MonitorUpdate& update);
  void report_state(MonitorUpdate& update);
  template <typename Message>
  void add_frame(MonitorUpdate& update, const Message& message);
  [[nodiscard]] std::int64_t monitor_time(std::int64_t receive_time_ns);

  MonitorConfig config_;
  SensorSet sensors_;
  Vector3r last_ground_ = Vector3r::Zero();  // the estimators' newest input, m/s2
  std::array<Ensemble, kMaxAxes> ensembles_{};
  monitor::AlarmPolicy alarm_;
  BoxStatus status_;
  std::uint64_t frames_not_encoded_ = 0;
  bool have_epoch_ = false;
  std::int64_t epoch_ns_ = 0;  // receive time of the first sample
  bool bus_fault_ = false;
  bool evaluated_ = false;  // the alarm policy has evaluated an input since start()
  bool pending_ack_ = false;
  monitor::Acknowledgement ack_;
  std::int64_t status_interval_ns_ = 100'000'000;
  std::int64_t next_status_ns_ = 0;   // monitor time of the next status at the interval
  std::uint8_t status_sequence_ = 0;  // of the next MonitorStatus frames
};

}  // namespace plinth::firmware

// The box's loop, without the operating system: the monitor's inputs (a sensor's sample, a
// tick, an operator's acknowledgement) in; one update out for each, which the outputs read
// alone. Its rooms (docs/monitor-components.md, The monitor's rooms): the sensors (sensor_set.h),
// the statues of each axis (lib/core ensemble.h), the alarm inputs (alarm_inputs.h) and the
// alarm policy (lib/monitor), the frames to send (can_frames.h); the bus's frames come in
// through frame_decoder.h. Freestanding like lib/core: no heap, no exceptions; everything is
// sized at compile time and set up once by start().
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "plinth/core/ensemble.h"
#include "plinth/core/error.h"
#include "plinth/core/events.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/firmware/box_status.h"
#include "plinth/firmware/config.h"
#include "plinth/firmware/sensor_set.h"
#include "plinth/firmware/statue_sensor.h"
#include "plinth/hal/can_codec.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/conditioning.h"
#include "plinth/monitor/p_wave.h"
#include "plinth/monitor/regional_alert.h"
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
  // What came of a statement that the statue stands (Monitor::statue_stands); kNone otherwise.
  monitor::StandsOutcome statue_stands = monitor::StandsOutcome::kNone;
  int stands_source = -1;  // a bus statement's SourceId (on_frame); -1: not from the bus
  // Frames this update should have carried but could not (BoxStatus::frames_not_encoded).
  std::size_t frames_lost = 0;
  // What came of a regional alert (Monitor::on_regional_alert, regional_alert_malformed), when
  // the input was one (regional_received).
  bool regional_received = false;
  monitor::RegionalOutcome regional;
  std::array<hal::can::CanFrame, kMaxFramesPerUpdate> frames{};  // frames[0 .. frame_count)
  std::size_t frame_count = 0;
};

// Each input: the sensors take it (health, conditioning, failover, cross-checks), the
// estimators take what the primary sensor has for them, the axes' status is read from the
// ensembles, the alarm policy is told (alarm_inputs.h), and the update gets the alarm events
// and, when a status is due, the status frames.
//
// Time: monitor time is ns since the first sensor sample's receive time, never going back.
// The estimators start (at rest, full contact) on the primary's first conditioned sample, and
// again on a seam (a sensor fault ended, a failover that cannot continue the stream). They are
// calibrated only when they start right after a window that passed conditioning's quietness
// test; else the primary's conditioner verifies a new window, and until then the level is
// fault, cause not_calibrated (docs/monitor.md, Start-up and restart).
// What must outlive a restart of the box (Monitor::memory, restore): the alarm policy's latch
// and held collapse, and what that collapse was.
struct BoxMemory {
  monitor::AlarmMemory alarm;
  CollapseRecord collapse;
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
  // One gyroscope sample of the statue sensor (statue_sensor.h): its health and offset; the
  // estimators' next samples take it to each axis's StatueFilter. Ignored (a status, if due)
  // without a statue sensor configured.
  [[nodiscard]] MonitorUpdate on_statue_sample(const StatueSample& sample);
  // One accelerometer sample of the statue sensor (g, sensor frame): its stream's health, its
  // horizontal offsets while quiet; the estimators' next samples take it to each axis's
  // StatueFilter's sliding test.
  [[nodiscard]] MonitorUpdate on_statue_acceleration(const monitor::SensorSample& sample);
  // Call periodically with the receive clock's time: sensor timeouts, heartbeats.
  [[nodiscard]] MonitorUpdate on_tick(std::int64_t receive_time_ns);
  // An operator acknowledges the latched level, quoting the latest alarm event (from the bus,
  // Modbus or MQTT): evaluated at once, at the current monitor time; the update says what came
  // of it (MonitorUpdate::acknowledgement).
  [[nodiscard]] MonitorUpdate acknowledge(const monitor::Acknowledgement& acknowledgement);
  // A person on site states that the statue stands again (a command of its own, distinct from
  // an acknowledgement), quoting the latest alarm event's sequence as an acknowledgement does:
  // a held collapse clears unless a corroborated statue sensor still measures one;
  // the estimators then start again at rest, trusted after a quiet window as at start-up. The
  // update says what came of it (MonitorUpdate::statue_stands).
  [[nodiscard]] MonitorUpdate statue_stands(std::uint8_t event_sequence);
  // What a restart must not lose, and its return: restore() into a monitor just started,
  // before its first input; its first update shows the restored level, cause kRestored.
  [[nodiscard]] BoxMemory memory() const;
  void restore(const BoxMemory& memory);
  // A regional alert (docs/regional.md), its times relative to its receipt at
  // `receive_time_ns` (the bus's frames) or, without one, now (the newest input's time: an alert
  // from MQTT); the update says what came of it (MonitorUpdate::regional).
  [[nodiscard]] MonitorUpdate on_regional_alert(const monitor::RegionalAlert& alert,
                                                std::int64_t receive_time_ns);
  [[nodiscard]] MonitorUpdate on_regional_alert(const monitor::RegionalAlert& alert);
  // A regional alert the host could not read (counted as malformed; `field` names what).
  [[nodiscard]] MonitorUpdate regional_alert_malformed(const char* field);
  // One the host refused before reading it: malformed or unauthenticated (regional_alert.h).
  [[nodiscard]] MonitorUpdate regional_alert_refused(monitor::RegionalRefusal refusal,
                                                     const char* field);
  // No input (a frame that is none of the monitor's): the status, if one is due; the alarm
  // policy's first evaluation if none happened since start() (so that no status says the
  // policy's initial `normal`).
  [[nodiscard]] MonitorUpdate poll();
  // Bus trouble reported by the frame source (bus-off, dropped frames): raises the fault level
  // until `active` is cleared.
  void set_bus_fault(bool active) { bus_fault_ = active; }
  // A fault the host holds for a reason of its own (kCommissioningFailed: the box refuses to
  // vouch, docs/commissioning.md): the level is fault with this cause, ahead of every other
  // fault cause, until `cause` is kNone. start() clears it.
  void hold_fault(monitor::AlarmCause cause) { held_fault_ = cause; }

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
  // The statue sensor's filter of `axis` (started only with a statue sensor; a build without
  // one has none: kStatueSensorBuiltIn).
  [[nodiscard]] const StatueFilter& statue_filter(int axis) const {
    return statue_room_[0].filters[static_cast<std::size_t>(axis)];
  }

 private:
  // The estimators take the inputs the sensors have for them (SensorSet::next_input).
  void feed_estimators();
  void push_ensembles(const Vector3r& ground_m_s2, std::int64_t receive_time_ns);
  // The P-wave stage configured, in a build that has it (monitor::kPWaveStageBuiltIn).
  [[nodiscard]] bool pwave_present() const {
    const auto* pwave = monitor::built_part<monitor::PWaveSettings>(config_.pwave);
    return pwave != nullptr && pwave->enabled;
  }
  // The stage when configured (pwave_present()); nullptr otherwise.
  [[nodiscard]] monitor::PWaveStage* pwave_stage() {
    return pwave_present() ? monitor::built_part<monitor::PWaveStage>(pwave_) : nullptr;
  }
  [[nodiscard]] bool quiet() const;
  // A statue sensor configured, in a build that has it (kStatueSensorBuiltIn).
  [[nodiscard]] bool statue_present() const {
    return kStatueSensorBuiltIn && config_.statue_sensor.present;
  }
  void note_statue_health();
  [[nodiscard]] MonitorUpdate new_update() const;
  void take_sample(int sensor, const monitor::SensorSample& sample, MonitorUpdate& update);
  void update_axis(int axis_index, AxisStatus& axis) const;
  void update_axes_status();
  void note_statue_trouble();
  void feed_other_reading(int sensor);
  void follow_worst_reading();
  void note_collapse(const monitor::AlarmInput& input);
  void restart_estimators();
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
  // Every other ground sensor's reading, estimated as the primary's is (its own ensembles, fed
  // its own conditioned samples): while the sensors disagree the alarm follows the most
  // dangerous healthy one (docs/safety.md). Slot i is sensor i's (the primary's idle); none in
  // a build with one sensor.
  struct OtherReading {
    std::array<Ensemble, kMaxAxes> ensembles{};
    bool running = false;   // started on one of its samples since its last seam or fault
    std::uint64_t seen = 0;  // its conditioned samples taken
    std::int64_t start_ns = 0;  // monitor time of its ensembles' latest start
  };
  static constexpr int kOtherReadings = kMaxSensors > 1 ? kMaxSensors : 0;
  std::array<OtherReading, kOtherReadings> others_{};
  // The statue sensor and each axis's filter: none in a build without it, so that neither its
  // code nor its data take a microcontroller's room (statue_present() guards every use).
  struct StatueRoom {
    StatueSensor sensor;
    std::array<StatueFilter, kMaxAxes> filters{};
    std::array<bool, kMaxAxes> measured{};  // each filter took the newest estimator sample
    std::uint64_t restarts = 0;             // the statue stream's restarts the filters know
  };
  std::array<StatueRoom, kStatueSensorBuiltIn ? 1 : 0> statue_room_{};
  [[nodiscard]] StatueRoom& room() { return statue_room_[0]; }
  [[nodiscard]] const StatueRoom& room() const { return statue_room_[0]; }
  monitor::AlarmPolicy alarm_;
  // The regional alerts' room: nothing in a build without regional alerts.
  [[no_unique_address]] monitor::RegionalAlertRoom regional_;
  // The on-site P-wave stage, fed the samples the estimators take: none in a build without it,
  // so that neither its code nor its data take a microcontroller's room (pwave_stage()).
  [[no_unique_address]] monitor::OptionalPart<monitor::PWaveStage, monitor::kPWaveStageBuiltIn>
      pwave_{};
  BoxStatus status_;
  std::uint64_t frames_not_encoded_ = 0;
  bool have_epoch_ = false;
  std::int64_t epoch_ns_ = 0;  // receive time of the first sample
  bool bus_fault_ = false;
  monitor::AlarmCause held_fault_ = monitor::AlarmCause::kNone;  // hold_fault()
  bool evaluated_ = false;  // the alarm policy has evaluated an input since start()
  bool pending_ack_ = false;
  bool pending_stands_ = false;
  std::uint8_t stands_sequence_ = 0;
  monitor::Acknowledgement ack_;
  std::int64_t status_interval_ns_ = 100'000'000;
  std::int64_t next_status_ns_ = 0;   // monitor time of the next status at the interval
  std::uint8_t status_sequence_ = 0;  // of the next MonitorStatus frames
};

}  // namespace plinth::firmware

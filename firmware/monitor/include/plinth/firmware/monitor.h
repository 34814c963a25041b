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

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "plinth/core/error.h"
#include "plinth/core/estimator.h"
#include "plinth/core/events.h"
#include "plinth/core/forecast.h"
#include "plinth/core/name_table.h"
#include "plinth/core/real.h"
#include "plinth/core/risk.h"
#include "plinth/core/scene.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/frame_io.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/conditioning.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// Capacities, fixed at build time: CMake cache variables of the same names (firmware/monitor);
// the defaults are the host's. A microcontroller build with one ground sensor chooses 1 sensor,
// a short history and 2-sample windows to fit its RAM (docs/microcontroller.md).
#ifndef PLINTH_MONITOR_MAX_SENSORS
#define PLINTH_MONITOR_MAX_SENSORS 4
#endif
#ifndef PLINTH_MONITOR_SENSOR_HISTORY
#define PLINTH_MONITOR_SENSOR_HISTORY 128
#endif
#ifndef PLINTH_MONITOR_MAX_CHECK_WINDOW_SAMPLES
#define PLINTH_MONITOR_MAX_CHECK_WINDOW_SAMPLES 1000
#endif

inline constexpr int kMaxAxes = 2;
// Accelerometers, ground and plate together.
inline constexpr int kMaxSensors = PLINTH_MONITOR_MAX_SENSORS;
// Samples kept per sensor (conditioned, with receive times): the cross-checks' pairing and a
// failover's catch-up. A timeout is below 128 sample periods, so with 128 a silent primary's
// failover still finds the new primary's samples since the last one the estimators took.
inline constexpr int kSensorHistory = PLINTH_MONITOR_SENSOR_HISTORY;
// Longest cross-check window, samples (window_s times the sample rate).
inline constexpr int kMaxCheckWindowSamples = PLINTH_MONITOR_MAX_CHECK_WINDOW_SAMPLES;
static_assert(kMaxSensors >= 1, "at least the one ground sensor");
static_assert(kSensorHistory >= static_cast<int>(monitor::kMaxFedPerSample),
              "the history holds every sample one input can feed");
static_assert(kMaxCheckWindowSamples >= 2, "a window spans at least 2 samples");

enum class SensorRole : std::uint8_t {
  kGround = 0,  // on the ground (the foundation): may drive the estimators
  kPlate = 1,   // on the isolation plate: checks the model, never drives it
};
// The roles' names in the configuration file and the status lines.
inline constexpr NameTable<SensorRole, 2> kSensorRoleNames{{{
    {SensorRole::kGround, "ground"},
    {SensorRole::kPlate, "plate"},
}}};
[[nodiscard]] constexpr const char* sensor_role_name(SensorRole role) {
  return kSensorRoleNames.name(role);
}

struct SensorConfig {
  std::uint8_t node = 1;  // CAN node id, 1..15, one per sensor
  SensorRole role = SensorRole::kGround;
  monitor::ConditioningSettings conditioning;   // its sample period is the estimator's
  monitor::SensorHealthSettings sensor_health;  // its sample period is the estimator's
};

// Ground sensors against the primary.
struct RedundancySettings {
  // s: sliding window of the RMS difference, 2 to kMaxCheckWindowSamples samples
  double window_s = 0.5;
  double tolerance_m_s2 = 0.3;   // m/s2, > 0: an RMS difference beyond this is a disagreement
};

// The plate sensor against the model.
struct PlateCheckSettings {
  // s: sliding window of the RMS residual, 2 to kMaxCheckWindowSamples samples
  double window_s = 1.0;
  double threshold_m_s2 = 0.5;   // m/s2, > 0: an RMS residual beyond this is a mismatch
  bool raises_fault = false;     // a mismatch also raises the fault level (kSensorDisagreement)
};

struct MonitorConfig {
  int axis_count = 1;  // 1: the statue's first principal axis; 2: both
  // The single-sensor form, used when sensor_count = 0: one ground accelerometer.
  std::uint8_t ground_node = 1;  // CAN node id of the ground accelerometer, 1..15
  EstimatorSettings estimator;   // sample rate (= the sensor's) and solver steps per sample
  RiskSettings risk;
  ForecastSettings forecast;     // the ensemble's look ahead (forecast.h)
  monitor::ConditioningSettings conditioning;  // its sample period is the estimator's
  monitor::SensorHealthSettings sensor_health;  // its sample period is the estimator's
  monitor::AlarmPolicySettings alarm;
  // Quiet (offset tracking allowed): every axis at rest in full contact with risk below this.
  double quiet_risk = 1e-3;
  // s, > 0: a status (its frames, and the application's status line) goes out at least this
  // often, besides at every alarm change and at the alarm policy's heartbeat.
  double status_interval_s = 0.1;
  // The sensor list, sensors[0 .. sensor_count): replaces ground_node, conditioning and
  // sensor_health when sensor_count > 0. At least one ground sensor, at most one plate sensor,
  // distinct nodes; the configured order is the order of preference for the primary.
  int sensor_count = 0;
  std::array<SensorConfig, kMaxSensors> sensors{};
  RedundancySettings redundancy;
  PlateCheckSettings plate;
};

// Checks every part; the Error names the field ("monitor.axis_count", "estimator....", ...).
// A sensor's fields are "sensor.node", "sensor.role", "conditioning....", "sensor_health....";
// `sensor_index`, when given, receives the index of the sensor at fault (-1: none).
[[nodiscard]] Error validate(const MonitorConfig& config, int* sensor_index = nullptr);

// The sensors of `config`: its list, or the single-sensor form as one ground sensor. Returns
// the count.
[[nodiscard]] int resolved_sensors(const MonitorConfig& config,
                                   std::array<SensorConfig, kMaxSensors>& out);

struct AxisStatus {
  Mode mode;  // the nominal statue's (member 0)
  State state = State::Zero();
  Risk risk;             // the worst member's (the highest total)
  Risk nominal_risk;     // member 0's: the scene file's statue alone, as a box without ensemble
  int members = 1;       // the ensemble's size
  int worst_member = 0;  // whose risk that is
  // A member's estimate ended outside the model (Phase::kLiftedOff): the box cannot vouch for
  // this axis until its estimators start again (the alarm policy's outside_model).
  bool outside_model = false;
  ForecastOutcome forecast;  // the latest completed forecast (valid: false before the first)
  // Monitor time, s, of that forecast's first collapse (its worst member's); -1: none forecast.
  double collapse_forecast_s = -1.0;
};

// Frames that were not sensor samples of a configured node, or could not be decoded.
struct FrameCounters {
  std::uint64_t received = 0;
  std::uint64_t sensor_samples = 0;       // SensorAcceleration of a configured node, decoded
  std::uint64_t other_nodes = 0;          // SensorAcceleration of other nodes (not used)
  std::uint64_t heartbeats = 0;           // SensorHeartbeat of any node
  std::uint64_t acknowledgements = 0;     // Acknowledge frames, decoded
  std::uint64_t monitor_frames = 0;  // MonitorStatus / AlarmEvent / CollapseForecast (any box's)
  std::uint64_t rejected = 0;             // failed to decode (length, range, reserved bits)
  std::uint64_t unknown_identifiers = 0;  // not a plinth identifier
  can::CodecError last_error = can::CodecError::kOk;  // of the latest rejected frame
  const char* last_error_signal = "";
  std::uint64_t not_encoded = 0;  // frames to send that the codec refused (left out)
};

// One sensor's part of the status.
struct SensorStatus {
  std::uint8_t node = 1;
  SensorRole role = SensorRole::kGround;
  bool primary = false;  // drives the estimators
  bool ready = false;    // conditioning ready (offset estimated)
  monitor::SensorHealth health;
  // Cross-check (ground sensors but the primary: the RMS difference to the primary; the plate:
  // the model-mismatch residual), m/s2, over the sliding window; valid once the window is full.
  double rms_m_s2 = 0.0;
  bool window_full = false;
  bool disagreeing = false;   // rms_m_s2 beyond the tolerance (plate: the threshold)
  double max_rms_m_s2 = 0.0;  // the largest full-window RMS so far
  std::uint64_t pairs = 0;         // samples compared
  std::uint64_t unpaired = 0;      // samples with no reference sample within one period
  std::uint64_t disagreements = 0;  // entries into the disagreeing state
};

struct MonitorStatus {
  std::int64_t time_ns = 0;  // monitor time of the newest sample (or tick)
  bool estimating = false;   // conditioning ready and the estimators running
  // Their offset and initial state are trusted (the start-up rule, above); else the level is
  // fault, cause kNotCalibrated.
  bool calibrated = false;
  int axis_count = 1;
  std::array<AxisStatus, kMaxAxes> axes{};
  double risk = 0.0;  // the worst axis's total
  // The forecast: the highest probability of a collapse within the horizon over the axes, the
  // axis it is on (-1: no forecast yet), and the monitor time, s, at which the first member of
  // any axis is forecast to collapse (-1: none is).
  double probability = 0.0;
  int forecast_axis = -1;
  double collapse_forecast_s = -1.0;
  monitor::AlarmLevel alarm = monitor::AlarmLevel::kNormal;
  monitor::AlarmLevel latched = monitor::AlarmLevel::kNormal;
  monitor::SensorHealth sensor;
  std::uint64_t estimator_restarts = 0;  // starts of the estimators (the first one included)
  std::int64_t estimator_start_ns = 0;   // monitor time of the estimators' latest start (t = 0)
  std::int64_t newest_sample_time_ns = 0;  // monitor time of the newest sample fed
  // The sensors, in configured order; `sensor` above is the primary's health (before the
  // first primary: the first ground sensor's).
  int sensor_count = 1;
  std::array<SensorStatus, kMaxSensors> sensors{};
  int primary = -1;  // index of the sensor driving the estimators; -1 before the first
  std::uint64_t failovers = 0;            // switches of the primary after the first choice
  std::uint64_t failovers_continued = 0;  // of which the estimators continued from their state
  // ok; degraded: a sensor but the primary not ok (a redundant or the plate sensor lost), a
  // disagreement or a plate mismatch; fault: no usable ground sensor (the primary's fault).
  monitor::HealthState sensors_state = monitor::HealthState::kFault;
  bool disagreement = false;     // a ground sensor disagrees with the primary (fault input)
  bool plate_mismatch = false;   // the plate's residual is beyond its threshold
  int plate = -1;                // index of the plate sensor; -1: none
  double plate_residual_m_s2 = 0.0;  // the plate's RMS residual (valid when its window is full)
};

// An update's alarm events: each update evaluates the alarm policy once.
inline constexpr std::size_t kMaxUpdateEvents = monitor::kMaxEventsPerUpdate;
// An AlarmEvent per event, then a MonitorStatus per axis, then a CollapseForecast per axis.
inline constexpr std::size_t kMaxFramesPerUpdate =
    kMaxUpdateEvents + 2 * static_cast<std::size_t>(kMaxAxes);

// What one input did, and the frames to send for it, in order.
struct MonitorUpdate {
  std::array<monitor::AlarmEventRecord, kMaxUpdateEvents> events{};
  std::size_t event_count = 0;
  // A status is due (status_interval_s, an alarm change or the alarm policy's heartbeat): its
  // frames are in `frames`, and status() is what it reports.
  bool status_due = false;
  monitor::AckOutcome acknowledgement = monitor::AckOutcome::kNone;
  std::array<can::CanFrame, kMaxFramesPerUpdate> frames{};  // frames[0 .. frame_count)
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

  // One frame from the bus (or a candump log).
  [[nodiscard]] MonitorUpdate on_frame(const hal::TimedFrame& frame);
  // One decoded sample of the first sensor (the ground node of the single-sensor form; file
  // replay feeds these directly).
  [[nodiscard]] MonitorUpdate on_sample(const monitor::SensorSample& sample) {
    return on_sensor_sample(0, sample);
  }
  // One decoded sample of sensor `sensor` (its index in the configured order).
  [[nodiscard]] MonitorUpdate on_sensor_sample(int sensor, const monitor::SensorSample& sample);
  // Call periodically with the receive clock's time: sensor timeouts, heartbeats.
  [[nodiscard]] MonitorUpdate on_tick(std::int64_t receive_time_ns);
  // Bus trouble reported by the frame source (bus-off, dropped frames): raises the fault level
  // until `active` is cleared.
  void set_bus_fault(bool active) { bus_fault_ = active; }

  [[nodiscard]] const MonitorStatus& status() const { return status_; }
  [[nodiscard]] const FrameCounters& frames() const { return frames_; }
  // The primary's conditioning (before the first primary: the first sensor's).
  [[nodiscard]] const monitor::ConditioningStatus& conditioning() const {
    return conditioning(status_.primary < 0 ? 0 : status_.primary);
  }
  [[nodiscard]] const monitor::ConditioningStatus& conditioning(int sensor) const {
    return sensors_[static_cast<std::size_t>(sensor)].conditioner.status();
  }
  // The nominal statue's estimator of `axis`.
  [[nodiscard]] const PlanarEstimator& estimator(int axis) const { return member(axis, 0); }
  [[nodiscard]] const PlanarEstimator& member(int axis, int m) const {
    return ensembles_[static_cast<std::size_t>(axis)][static_cast<std::size_t>(m)];
  }
  [[nodiscard]] int members(int axis) const {
    return static_cast<int>(scenes_[static_cast<std::size_t>(axis)].size());
  }
  [[nodiscard]] const Forecaster& forecaster(int axis) const {
    return forecasters_[static_cast<std::size_t>(axis)];
  }
  // The sensors as started (the single-sensor form resolved).
  [[nodiscard]] const SensorConfig& sensor_config(int sensor) const {
    return sensor_configs_[static_cast<std::size_t>(sensor)];
  }
  [[nodiscard]] const MonitorConfig& config() const { return config_; }

 private:
  // A conditioned sample, statue frame, m/s2, at its receive time.
  struct HistoryEntry {
    std::int64_t time_ns = 0;  // receive clock
    Vector3r value = Vector3r::Zero();
    bool restart = false;  // the health tracker's restart mark
  };
  // The last kSensorHistory entries of a stream; entries [valid_from(), pushed) are kept.
  struct History {
    std::array<HistoryEntry, kSensorHistory> entries{};
    std::uint64_t pushed = 0;      // entries ever pushed; the newest is pushed - 1
    std::uint64_t first_kept = 0;  // entries before this were cleared (a seam in the stream)
    [[nodiscard]] std::uint64_t valid_from() const {
      const std::uint64_t held = pushed < kSensorHistory ? 0 : pushed - kSensorHistory;
      return first_kept > held ? first_kept : held;
    }
    [[nodiscard]] bool empty() const { return valid_from() >= pushed; }
    [[nodiscard]] const HistoryEntry& at(std::uint64_t n) const {
      return entries[static_cast<std::size_t>(n % kSensorHistory)];
    }
    [[nodiscard]] const HistoryEntry& newest() const { return at(pushed - 1); }
    void push(const HistoryEntry& e) { entries[static_cast<std::size_t>(pushed++ % kSensorHistory)] = e; }
    void clear() { first_kept = pushed; }
  };
  // The RMS of a sliding window of squared differences, m/s2, in Real (the sum is taken afresh
  // once per window, so a float build does not drift).
  struct RmsWindow {
    std::array<Real, kMaxCheckWindowSamples> squares{};
    int length = 2;   // samples
    int count = 0;    // samples held, up to length
    int next = 0;     // slot of the next one
    Real sum = 0;
    void reset() { count = 0; next = 0; sum = 0; }
    void add(Real square);
    [[nodiscard]] bool full() const { return count >= length; }
    [[nodiscard]] Real rms() const;
  };
  struct Sensor {
    monitor::SensorHealthTracker health;
    monitor::Conditioner conditioner;
    History history;
    RmsWindow window;
    std::uint64_t checked = 0;  // history entries cross-checked (or found unpairable)
  };

  void process(int sensor, const monitor::FedSample& sample);
  void update_primary();
  void drain_primary();
  void drive(const HistoryEntry& entry);
  void push_estimators(const Vector3r& ground_m_s2);
  void cross_check();
  void check_sensor(int sensor);
  [[nodiscard]] bool reference_at(const History& reference, std::int64_t time_ns,
                                  Vector3r& value) const;
  [[nodiscard]] bool usable(int sensor) const;
  [[nodiscard]] bool quiet() const;
  void take_sample(int sensor, const monitor::SensorSample& sample, MonitorUpdate& update);
  // Decodes one frame and acts on it; true when that evaluated the state (and reported).
  [[nodiscard]] bool take_frame(const hal::TimedFrame& timed, MonitorUpdate& update);
  // Decodes `frame`; a refusal is counted (rejected, last_error).
  template <typename Message>
  [[nodiscard]] bool decoded(const can::CanFrame& frame, Message& message);
  [[nodiscard]] int sensor_of_node(std::uint8_t node) const;  // -1: not configured
  void update_sensors_status();
  void update_axis(int axis_index, AxisStatus& axis) const;
  void update_axes_status(monitor::AlarmInput& input);
  void evaluate(MonitorUpdate& update);
  void report(MonitorUpdate& update);
  void report_state(MonitorUpdate& update);
  template <typename Message>
  void add_frame(MonitorUpdate& update, const Message& message);
  [[nodiscard]] std::int64_t monitor_time(std::int64_t receive_time_ns);

  MonitorConfig config_;
  std::array<SensorConfig, kMaxSensors> sensor_configs_{};
  int sensor_count_ = 1;
  std::array<Sensor, kMaxSensors> sensors_{};
  History estimate_;  // the model's base acceleration u'' + u_G'' per axis (the plate's reference)
  std::int64_t period_ns_ = 5'000'000;
  std::uint64_t consumed_ = 0;  // the primary's history entries the estimators took
  bool restart_pending_ = false;  // the next entry starts the estimators at rest
  bool align_pending_ = false;    // the next entry continues after a failover: align by time
  std::int64_t last_fed_ns_ = 0;  // receive time of the estimators' newest sample
  Vector3r last_ground_ = Vector3r::Zero();  // its value, m/s2
  std::array<std::span<const Scene>, kMaxAxes> scenes_{};
  std::array<std::array<PlanarEstimator, kMaxEnsembleMembers>, kMaxAxes> ensembles_{};
  std::array<Forecaster, kMaxAxes> forecasters_{};
  std::array<EventSink*, kMaxAxes> sinks_{};
  monitor::AlarmPolicy alarm_;
  MonitorStatus status_;
  FrameCounters frames_;
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

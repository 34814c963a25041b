// What the monitor knows after each input (Monitor::status(), MonitorUpdate::status): the
// time, the estimators and each axis's mode, state, risk and forecast, the alarm level, and
// each sensor's health and cross-check. The outputs (the status and alarm frames, the JSON
// lines, Modbus, MQTT, the relays) are written from it. Freestanding.
#pragma once

#include <array>
#include <cstdint>

#include "plinth/core/ensemble.h"
#include "plinth/core/forecast.h"
#include "plinth/core/risk.h"
#include "plinth/core/state.h"
#include "plinth/core/statue_filter.h"
#include "plinth/firmware/config.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/optional_part.h"
#include "plinth/monitor/p_wave.h"
#include "plinth/monitor/regional_alert.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// What the statue sensor makes of an axis (StatueFilter's estimate, statue_filter.h).
struct StatueAxisStatus {
  bool measured = false;     // the filter took the statue sensor's newest sample
  bool informative = false;  // the weights tell the members apart
  bool unexplained = false;  // no member explains the measured motion
  bool weighted = false;     // the risk is the weighted members' (informative and explained)
  Real effective_members = 0.0;
  Real best_score = 0.0;     // the best member's mean normalised innovation
  int best_member = 0;
  int ruled_out = 0;         // members the measured motion ruled out (their risk not counted)
  // The accelerometer's sample tested sliding (fresh, healthy, a scene that can slide); else the
  // phase is the gyroscope's alone.
  bool acceleration_used = false;
  // The ground sensors corroborate the statue sensor: its reading may lower the risk below the
  // box's without it (docs/safety.md). Else why not, and whether it would lower it now (then the
  // box shows the higher of the two and the trouble kStatueSensorFault or kStatueUnexplained).
  bool corroborated = true;
  StatueRefutation refutation = StatueRefutation::kNone;
  bool lowering_refused = false;
  Real risk_without = 0.0;  // the box's without the sensor (the ensemble's worst member's)
};

// The statue sensor's streams: its gyroscope's and accelerometer's health, its rate offset
// known.
struct StatueSensorStatus {
  monitor::SensorHealth rate;
  monitor::SensorHealth acceleration;
  bool ready = false;
};
using StatueSensorStatusField = monitor::OptionalPart<StatueSensorStatus, kStatueSensorBuiltIn>;
using StatueAxisStatusField = monitor::OptionalPart<StatueAxisStatus, kStatueSensorBuiltIn>;

// One axis: its ensemble's risk (the worst member's, the nominal statue's alone, as a box
// without ensemble) and the rest.
struct AxisStatus : EnsembleRisk {
  // The nominal statue's (member 0); with the statue sensor measuring, the measured phase,
  // tilt and rotation rate.
  Mode mode;
  State state = State::Zero();
  // The statue sensor's view (nothing in a build without it: built_part).
  [[no_unique_address]] StatueAxisStatusField statue;
  int members = 1;       // the ensemble's size
  ForecastOutcome forecast;  // the latest completed forecast (valid: false before the first)
  // Monitor time, s, of that forecast's first collapse (its worst member's); -1: none forecast.
  double collapse_forecast_s = -1.0;
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

// A collapse the alarm policy holds (sticky until a person says the statue stands again):
// what was seen, on which axis, and when.
struct CollapseRecord {
  bool held = false;
  int axis = 0;
  Mode mode;  // overturned or fell, and the corner
  // Monitor time it was seen, ns; after a restart (restored), the time in the run that saw it
  // is not this run's: the host keeps its wall-clock time beside it.
  std::int64_t time_ns = 0;
  bool restored = false;  // brought back from the box's saved state (Monitor::restore)
};

// The sensors' part of the box's status, which the SensorSet keeps (sensor_set.h).
struct SensorSetStatus {
  // The primary's health (before the first primary: the first sensor's).
  monitor::SensorHealth sensor;
  // The sensors, in configured order.
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

// The box: its sensors' part, the estimators' and the alarm policy's.
struct BoxStatus : SensorSetStatus {
  std::int64_t time_ns = 0;  // monitor time of the newest sample (or tick)
  bool estimating = false;   // conditioning ready and the estimators running
  // Their offset and initial state are trusted (the start-up rule, docs/monitor.md); else the
  // level is fault, cause kNotCalibrated.
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
  // The trouble shown beside the level (the alarm policy's; kNone: none), and the supplementary
  // input refused now (alarm_inputs.h: the statue sensor's trouble, a disagreement).
  monitor::AlarmCause trouble = monitor::AlarmCause::kNone;
  monitor::AlarmCause input_fault = monitor::AlarmCause::kNone;
  CollapseRecord collapse;
  // While ground sensors disagree: the sensor whose reading the risk follows (the most
  // dangerous healthy one; -1: the primary's, as without a disagreement).
  int risk_sensor = -1;
  // Frames the update could not carry (the codec refused one, or the update was full) since
  // start(); never silently: MonitorUpdate::frames_lost says which update lost them.
  std::uint64_t frames_not_encoded = 0;
  std::uint64_t estimator_restarts = 0;  // starts of the estimators (the first one included)
  std::int64_t estimator_start_ns = 0;   // monitor time of the estimators' latest start (t = 0)
  std::int64_t newest_sample_time_ns = 0;  // monitor time of the newest sample fed
  // The statue sensor (statue_sensor.h): configured, its streams (none in a build without it:
  // built_part), and unexplained: on some axis no member explains its motion (fault,
  // kStatueUnexplained).
  bool has_statue_sensor = false;
  [[no_unique_address]] StatueSensorStatusField statue_sensor;
  bool statue_unexplained = false;
  // Configured, the estimators calibrated and running, but its gyroscope unusable (a stream
  // fault, no offset, a stale sample): the box runs without it (kStatueSensorFault).
  bool statue_sensor_unusable = false;
  // Regional alerts: the worst held, its probability of collapse and time to the S arrival,
  // the counters (times in monitor time).
  // (Nothing in a build without regional alerts.)
  [[no_unique_address]] monitor::RegionalAlertStatusField regional;
  // The on-site P-wave stage (MonitorConfig::pwave): running, and its status after the newest
  // sample (its times count from estimator_start_ns: it restarts with the estimators). None in
  // a build without the stage.
  bool has_pwave = false;
  [[no_unique_address]] monitor::PWaveStatusField pwave;
};

}  // namespace plinth::firmware

// The monitor's configuration (firmware/monitor): its build-time capacities, the sensors (node,
// role, conditioning, health), the cross-checks' settings and the settings of the stages it
// runs (estimator, risk, forecast, alarm policy), and the checks start() makes of them.
// Freestanding.
#pragma once

#include <array>
#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/estimator.h"
#include "plinth/core/forecast.h"
#include "plinth/core/name_table.h"
#include "plinth/core/risk.h"
#include "plinth/firmware/statue_sensor.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/conditioning.h"
#include "plinth/monitor/p_wave.h"
#include "plinth/monitor/regional_alert.h"
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

// The largest tolerance of the ground sensors' cross-check and threshold of the plate's, m/s2.
inline constexpr double kMaxDisagreementToleranceM_S2 = 2.0;
inline constexpr double kMaxPlateThresholdM_S2 = 20.0;

// Ground sensors against the primary.
struct RedundancySettings {
  // s: sliding window of the RMS difference, 2 to kMaxCheckWindowSamples samples
  double window_s = 0.5;
  // m/s2, (0, kMaxDisagreementToleranceM_S2]: an RMS difference beyond this is a disagreement
  double tolerance_m_s2 = 0.3;
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
  // The IMU on the statue (statue_sensor.h): absent unless `present`; a build without the
  // statue sensor holds `present` alone (built_part<StatueSensorSettings> gives the rest).
  StatueSensorConfig statue_sensor;
  // Regional early-warning alerts (regional_alert.h): their checks and expiry, and the statue's
  // fragility (plinth-monitor takes it from the scene file's [fragility]).
  // (Nothing in a build without regional alerts.)
  [[no_unique_address]] monitor::RegionalAlertConfig regional;
  // The on-site P-wave stage (p_wave.h, docs/pwave.md): runs when enabled (the box file's
  // [pwave] table), on the primary's conditioned samples; its sample period is the estimator's,
  // its fragility the statue's (plinth-monitor: the scene file's [fragility], which it needs).
  // A build without the stage (PLINTH_PWAVE_STAGE=OFF) holds only `enabled`, and refuses it.
  [[no_unique_address]] monitor::PWaveConfig pwave = monitor::pwave_off();
};

// Checks every part; the Error names the field ("monitor.axis_count", "estimator....", ...).
// A sensor's fields are "sensor.node", "sensor.role", "conditioning....", "sensor_health....";
// `sensor_index`, when given, receives the index of the sensor at fault (-1: none).
[[nodiscard]] Error validate(const MonitorConfig& config, int* sensor_index = nullptr);

// The sensors of `config`: its list, or the single-sensor form as one ground sensor. Returns
// the count.
[[nodiscard]] int resolved_sensors(const MonitorConfig& config,
                                   std::array<SensorConfig, kMaxSensors>& out);

}  // namespace plinth::firmware

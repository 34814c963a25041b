#include "plinth/firmware/config.h"

#include <cmath>

#include "plinth/hal/can_codec.h"

namespace plinth::firmware {

// The CAN protocol (hal/can_codec).
namespace can = hal::can;

namespace {

#define PLINTH_TEXT_OF(x) #x
#define PLINTH_TEXT(x) PLINTH_TEXT_OF(x)

// The settings of a cross-check window: window_s at the sample rate in [2, max] samples, and a
// finite positive tolerance of at most `max_tolerance_m_s2`.
Error validate_check(double window_s, double tolerance_m_s2, double rate_hz,
                     const char* window_field, const char* tolerance_field,
                     double max_tolerance_m_s2) {
  const double samples = window_s * rate_hz;
  if (!std::isfinite(window_s) || samples < 2.0 ||
      samples > static_cast<double>(kMaxCheckWindowSamples)) {
    return {ErrorCode::kOutOfRange, window_field,
            "must span 2 to " PLINTH_TEXT(PLINTH_MONITOR_MAX_CHECK_WINDOW_SAMPLES)
            " sample periods at the sample rate"};
  }
  if (!std::isfinite(tolerance_m_s2) || tolerance_m_s2 <= 0.0) {
    return {ErrorCode::kOutOfRange, tolerance_field, "must be a positive acceleration, m/s2"};
  }
  if (tolerance_m_s2 > max_tolerance_m_s2) {
    return {ErrorCode::kOutOfRange, tolerance_field, "is beyond its largest, m/s2",
            max_tolerance_m_s2};
  }
  return ok_error();
}

}  // namespace

int resolved_sensors(const MonitorConfig& c, std::array<SensorConfig, kMaxSensors>& out) {
  if (c.sensor_count <= 0) {
    out[0].node = c.ground_node;
    out[0].role = SensorRole::kGround;
    out[0].conditioning = c.conditioning;
    out[0].sensor_health = c.sensor_health;
    return 1;
  }
  const int count = c.sensor_count > kMaxSensors ? kMaxSensors : c.sensor_count;
  for (int i = 0; i < count; ++i) {
    out[static_cast<std::size_t>(i)] = c.sensors[static_cast<std::size_t>(i)];
  }
  return count;
}

namespace {

// The [monitor] fields.
Error validate_monitor_fields(const MonitorConfig& c) {
  if (c.axis_count < 1 || c.axis_count > kMaxAxes) {
    return {ErrorCode::kOutOfRange, "monitor.axis_count", "must be 1 or 2"};
  }
  if (c.sensor_count < 0 || c.sensor_count > kMaxSensors) {
    return {ErrorCode::kOutOfRange, "monitor.sensor_count",
            "must lie in [0, " PLINTH_TEXT(PLINTH_MONITOR_MAX_SENSORS) "]"};
  }
  if (c.sensor_count == 0 &&
      (c.ground_node < can::kFirstSensorNode || c.ground_node > can::kLastSensorNode)) {
    return {ErrorCode::kOutOfRange, "monitor.ground_node", "must lie in [1, 15]"};
  }
  if (!std::isfinite(c.quiet_risk) || c.quiet_risk < 0.0 || c.quiet_risk > 1.0) {
    return {ErrorCode::kOutOfRange, "monitor.quiet_risk", "must lie in [0, 1]"};
  }
  // At least 1 ns, and room for hours of monitor time (int64 ns).
  if (!std::isfinite(c.status_interval_s) || c.status_interval_s < 1e-9 ||
      c.status_interval_s > 1e6) {
    return {ErrorCode::kOutOfRange, "monitor.status_interval_s", "must lie in [1e-9, 1e6] s"};
  }
  return ok_error();
}

// Every sensor: node, role, its conditioning and health at the estimator's sample period; at
// least one ground sensor. `sensor_index` receives the index of the sensor at fault.
Error validate_sensors(const MonitorConfig& c, int* sensor_index) {
  std::array<SensorConfig, kMaxSensors> sensors{};
  const int count = resolved_sensors(c, sensors);
  int grounds = 0;
  int plates = 0;
  for (int i = 0; i < count; ++i) {
    const SensorConfig& s = sensors[static_cast<std::size_t>(i)];
    if (sensor_index != nullptr) *sensor_index = c.sensor_count == 0 ? -1 : i;
    if (s.node < can::kFirstSensorNode || s.node > can::kLastSensorNode) {
      return {ErrorCode::kOutOfRange, "sensor.node", "must lie in [1, 15]"};
    }
    for (int j = 0; j < i; ++j) {
      if (sensors[static_cast<std::size_t>(j)].node == s.node) {
        return {ErrorCode::kInconsistent, "sensor.node", "is another sensor's node"};
      }
    }
    if (s.role == SensorRole::kGround) {
      ++grounds;
    } else if (s.role == SensorRole::kPlate) {
      if (++plates > 1) {
        return {ErrorCode::kInconsistent, "sensor.role", "a second plate sensor: at most one"};
      }
    } else {
      return {ErrorCode::kOutOfRange, "sensor.role", "must be ground or plate"};
    }
    monitor::ConditioningSettings conditioning = s.conditioning;
    conditioning.sample_period_s = c.estimator.sample_period();
    PLINTH_TRY(monitor::validate(conditioning));
    monitor::SensorHealthSettings health = s.sensor_health;
    health.sample_period_s = c.estimator.sample_period();
    PLINTH_TRY(monitor::validate(health));
  }
  if (grounds == 0) {
    if (sensor_index != nullptr) *sensor_index = 0;
    return {ErrorCode::kInconsistent, "sensor.role",
            "no ground sensor: at least one must drive the estimators"};
  }
  if (sensor_index != nullptr) *sensor_index = -1;
  return ok_error();
}

// The statue sensor's settings, its node apart from the accelerometers'. A build without it
// refuses one; its checks are left out at compile time (if constexpr), so that the Cortex-M4F
// image's validate() stays small enough to be inlined and folded on its constant settings.
Error validate_statue_sensor(const MonitorConfig& c) {
  if (!c.statue_sensor.present) return ok_error();
  if constexpr (!kStatueSensorBuiltIn) {
    return {ErrorCode::kOutOfRange, "statue_sensor",
            "this build has no statue sensor (PLINTH_STATUE_SENSOR=OFF)"};
  } else {
    const StatueSensorSettings& statue =
        *monitor::built_part<StatueSensorSettings>(c.statue_sensor);
    PLINTH_TRY(validate(statue, c.estimator.sample_period()));
    std::array<SensorConfig, kMaxSensors> sensors{};
    const int count = resolved_sensors(c, sensors);
    for (int i = 0; i < count; ++i) {
      if (sensors[static_cast<std::size_t>(i)].node == statue.node) {
        return {ErrorCode::kInconsistent, "statue_sensor.node",
                "is an accelerometer's node; each sensor has its own"};
      }
    }
    return ok_error();
  }
}

// The P-wave stage's settings at the estimator's sample period (a build without it holds none).
Error validate_pwave(const MonitorConfig& c) {
  const monitor::PWaveSettings* configured = monitor::built_part<monitor::PWaveSettings>(c.pwave);
  if (configured == nullptr || !configured->enabled) return ok_error();
  monitor::PWaveSettings settings = *configured;
  settings.sample_period_s = c.estimator.sample_period();
  return monitor::validate(settings);
}

}  // namespace

Error validate(const MonitorConfig& c, int* sensor_index) {
  if (sensor_index != nullptr) *sensor_index = -1;
  PLINTH_TRY(validate_monitor_fields(c));
  PLINTH_TRY(validate(c.risk));
  PLINTH_TRY(monitor::validate(c.alarm));
  if (const auto* regional = monitor::built_part<monitor::RegionalAlertSettings>(c.regional)) {
    PLINTH_TRY(monitor::validate(*regional));
  }
  // The sensor's period is the estimator's sample period: checked with the values start() uses.
  if (!std::isfinite(c.estimator.sample_rate_hz) || c.estimator.sample_rate_hz < 100.0 ||
      c.estimator.sample_rate_hz > 1000.0) {
    return {ErrorCode::kOutOfRange, "estimator.sample_rate_hz", "must lie in [100, 1000] Hz"};
  }
  PLINTH_TRY(validate(c.forecast, c.estimator.sample_rate_hz));
  // Ground sensors whose RMS difference stays below the tolerance are not followed to the worse
  // reading (docs/safety.md): beyond 2 m/s2 (0.2 g) a sensor turned on a strong quake's ground
  // would not count as disagreeing.
  PLINTH_TRY(validate_check(c.redundancy.window_s, c.redundancy.tolerance_m_s2,
                            c.estimator.sample_rate_hz, "redundancy.window_s",
                            "redundancy.tolerance_m_s2", kMaxDisagreementToleranceM_S2));
  PLINTH_TRY(validate_check(c.plate.window_s, c.plate.threshold_m_s2, c.estimator.sample_rate_hz,
                            "plate.window_s", "plate.threshold_m_s2", kMaxPlateThresholdM_S2));
  PLINTH_TRY(validate_pwave(c));
  PLINTH_TRY(validate_sensors(c, sensor_index));
  return validate_statue_sensor(c);
}

}  // namespace plinth::firmware

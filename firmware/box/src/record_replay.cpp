#include "plinth/firmware/record_replay.h"

#include <cmath>

namespace plinth::firmware {

namespace {
constexpr double kIdealSensorRangeG = 1e6;        // g: an ideal sensor neither saturates nor clips
constexpr double kNoTrackingTimeConstantS = 1e6;  // s: the offset is never tracked
}  // namespace

MonitorConfig box_defaults() {
  MonitorConfig config;
  config.conditioning.startup_window_s = kBoxStartupWindowS;
  config.forecast.enabled = kForecastBuiltIn;  // a microcontroller build may have none
  return config;
}

void configure_record_replay(MonitorConfig& config, double sample_rate_hz) {
  config.estimator.sample_rate_hz = sample_rate_hz;
  // One ideal ground sensor: a [[sensor]] list is reduced to its first ground sensor.
  for (int i = config.sensor_count - 1; i >= 0; --i) {
    const SensorConfig& sensor = config.sensors[static_cast<std::size_t>(i)];
    if (sensor.role != SensorRole::kGround) continue;
    config.ground_node = sensor.node;
    config.conditioning = sensor.conditioning;
    config.sensor_health = sensor.sensor_health;
  }
  config.sensor_count = 0;
  // The record is the ground's exact motion in m/s2, in the statue's frame: no bias to track,
  // no sensor noise (the stuck-value check needs noise), and the quiet lead-in estimates the
  // zero offset. The file's sensor settings describe the real sensor, not this one.
  config.conditioning.unit = monitor::AccelerationUnit::kMetresPerSecondSquared;
  config.conditioning.sensor_to_statue.setIdentity();
  config.conditioning.tracking_time_constant_s = kNoTrackingTimeConstantS;
  config.sensor_health.stuck_samples = 0;
  config.sensor_health.full_scale_g = kIdealSensorRangeG;
  config.sensor_health.max_valid_g = kIdealSensorRangeG;
}

std::int64_t record_replay_lead_in(const MonitorConfig& config) {
  return std::llround(config.conditioning.startup_window_s * config.estimator.sample_rate_hz) +
         config.sensor_health.recovery_samples - 1;
}

double record_replay_origin_s(const MonitorConfig& config) {
  return static_cast<double>(record_replay_lead_in(config)) / config.estimator.sample_rate_hz;
}

monitor::SensorSample record_replay_sample(const MonitorConfig& config, std::int64_t n,
                                           const Eigen::Vector3d& ground_m_s2, double gravity) {
  const double period = 1.0 / config.estimator.sample_rate_hz;
  monitor::SensorSample sample;
  sample.receive_time_ns = std::llround(static_cast<double>(n) * period * 1e9);
  sample.sequence = static_cast<std::uint8_t>(n & 0xFF);
  // The record's samples are double (a host's file); the monitor takes Real (plinth/core/real.h).
  sample.acceleration_g = n < record_replay_lead_in(config)
                              ? Vector3r(0, 0, static_cast<Real>(gravity))
                              : Vector3r(ground_m_s2.cast<Real>());
  return sample;
}

void configure_replay_statue_sensor(MonitorConfig& config) {
  config.statue_sensor.present = true;  // refused by a build without the statue sensor
  if (StatueSensorSettings* statue =
          monitor::built_part<StatueSensorSettings>(config.statue_sensor)) {
    statue->node = 2;
    statue->offset_window_s = config.conditioning.startup_window_s;
    statue->health.stuck_samples = 0;
  }
}

StatueSample replay_statue_sample(const MonitorConfig& config, std::int64_t n, Real theta_dot_x,
                                  Real theta_dot_y) {
  const monitor::SensorSample ground = record_replay_sample(config, n, Eigen::Vector3d::Zero(), 0);
  StatueSample sample;
  sample.receive_time_ns = ground.receive_time_ns;
  sample.sequence = ground.sequence;
  sample.rotation_rate_rad_s = Vector3r(theta_dot_y, -theta_dot_x, 0);
  return sample;
}

}  // namespace plinth::firmware

// The statue sensor's room: an IMU on the statue (a CAN node like the ground sensors) whose
// gyroscope measures the block's rotation. Its rate stream has its own health (gaps, stuck,
// saturation: lib/monitor's SensorHealthTracker, its values in rad/s), its offset estimated over
// a quiet window at start-up, its axes turned into the statue frame; each axis's rotation rate
// then goes to that axis's StatueFilter (lib/core statue_filter.h) beside the ensemble.
//
// Axes: the statue frame is x, y the first and second principal horizontal axes, z up. Axis 0's
// plane is x-z, its theta (> 0 about corner 1, the -x side: counter-clockwise with x right, z
// up) is a rotation about -y: theta'_0 = -omega_y. Axis 1's plane is y-z: theta'_1 = omega_x.
// Freestanding.
#pragma once

#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/real.h"
#include "plinth/core/statue_filter.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

struct StatueSensorSettings {
  bool present = false;
  std::uint8_t node = 2;  // CAN node id, 1..15, not a ground sensor's
  // Its mounting: the rotation from the sensor frame to the statue frame (orthonormal, det +1),
  // and where it sits: height above the block's base and horizontal offsets from its vertical
  // axis, m (the accelerometer's lever arm; the gyroscope reads the same anywhere on the block).
  Matrix3r sensor_to_statue = Matrix3r::Identity();
  Real height_m = 1.0;
  Real offset_x_m = 0.0;
  Real offset_y_m = 0.0;
  // The rate stream's health: its full_scale_g and max_valid_g are rad/s here (a BMI088's
  // 2000 deg/s range: 34.9 rad/s); its sample period is the estimator's.
  monitor::SensorHealthSettings health{.full_scale_g = Real(34.9), .max_valid_g = Real(35.0)};
  double offset_window_s = 2.0;  // s: the quiet start-up window that estimates the rate offset
  double max_age_s = 0.01;       // s: a rate older than this is not the statue's now
  StatueFilterSettings filter;
};

// Checks the settings; the Error names the field ("statue_sensor.node", ...).
[[nodiscard]] Error validate(const StatueSensorSettings& settings);

class StatueSensor {
 public:
  [[nodiscard]] Error start(const StatueSensorSettings& settings, double sample_period_s);
  // One rate sample (SensorSample's values in rad/s, sensor frame). `quiet`: the monitor's
  // quiet (the statue at rest, the ground quiet; true before the estimators run): the offset
  // is estimated only then, over a window whose rates spread by at most 0.05 rad/s.
  void on_sample(const monitor::SensorSample& sample, bool quiet);
  void tick(std::int64_t now_ns) { health_ = health_tracker_.tick(now_ns); }

  // Offset known, the stream not in fault, and a sample within max_age_s of `now_ns` (receive
  // clock).
  [[nodiscard]] bool usable(std::int64_t now_ns) const;
  // theta' of axis `axis` (0 or 1), rad/s: the newest rate, offset removed, statue frame.
  [[nodiscard]] Real axis_rate(int axis) const {
    return axis == 0 ? -rate_.y() : rate_.x();
  }
  [[nodiscard]] const monitor::SensorHealth& health() const { return health_; }
  [[nodiscard]] bool ready() const { return ready_; }
  [[nodiscard]] const Vector3r& offset() const { return offset_; }
  // Samples fed since the stream last restarted (a restart loses the tilt: the filter resets).
  [[nodiscard]] std::uint64_t restarts() const { return restarts_; }

 private:
  StatueSensorSettings settings_;
  monitor::SensorHealthTracker health_tracker_;
  monitor::SensorHealth health_;
  int window_samples_ = 1;
  int summed_ = 0;
  Vector3r sum_ = Vector3r::Zero();
  Vector3r low_ = Vector3r::Zero();  // the window's smallest and largest rates
  Vector3r high_ = Vector3r::Zero();
  Vector3r offset_ = Vector3r::Zero();
  Vector3r rate_ = Vector3r::Zero();  // statue frame, rad/s
  bool ready_ = false;
  bool have_sample_ = false;
  std::int64_t newest_ns_ = 0;
  std::uint64_t restarts_ = 0;
};

}  // namespace plinth::firmware

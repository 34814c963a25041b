// The statue sensor's room: an IMU on the statue (a CAN node like the ground sensors) whose
// gyroscope measures the block's rotation (StatueRotation frames) and whose accelerometer
// (SensorAcceleration frames of the same node) the block's specific force. Each stream has its
// own health (gaps, stuck, saturation), each stream's offset is estimated over a quiet window
// at start-up (the accelerometer's horizontal ones: at rest the statue's horizontal specific
// force is 0, whatever its bias and the mounting's small tilt), its axes turned into the statue
// frame; each axis's rotation rate and horizontal specific force (m/s2) then go to that axis's
// StatueFilter (lib/core statue_filter.h) beside the ensemble: the rate weighs the members and
// gives the rocking phases, the specific force tells sliding.
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
#include "plinth/monitor/optional_part.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// One sample of the statue sensor's gyroscope (a StatueRotation frame), sensor frame.
struct StatueSample {
  std::int64_t receive_time_ns = 0;
  std::uint8_t sequence = 0;
  std::uint8_t status = 0;                          // sensor_flags (alarm_level.h)
  Vector3r rotation_rate_rad_s = Vector3r::Zero();  // rad/s, right-handed about x, y, z
};

// The health of the statue sensor's two streams, each checked as a ground sensor's is
// (sensor_health.h: gaps bridged up to max_bridge_samples, timeouts, stuck values, saturation
// at full scale, values beyond the valid range rejected), at the estimator's sample rate.
struct StatueSensorHealthSettings {
  Time timeout_s = 0.05;     // s without an accepted sample: a timeout fault
  int max_bridge_samples = 3;  // samples: longest gap bridged
  int recovery_samples = 10;   // samples: consecutive clean ones that clear a condition
  int stuck_samples = 50;      // samples bit-identical on all axes: stuck (0: off)
  // The gyroscope: a BMI088 at its +-1000 deg/s range (17.45 rad/s) sends StatueRotation's
  // +-16.384 rad/s; full scale is where the frame clamps.
  Real rate_full_scale_rad_s = Real(16.38);
  Real rate_max_valid_rad_s = Real(16.384);
  Real acceleration_full_scale_g = Real(8.0);  // the accelerometer, as a ground sensor's
  Real acceleration_max_valid_g = Real(8.192);
};

struct StatueSensorSettings {
  bool present = false;
  std::uint8_t node = 2;  // CAN node id, 1..15, not a ground sensor's
  // Its mounting: the rotation from the sensor frame to the statue frame (orthonormal, det +1),
  // and where it sits: height above the block's base and horizontal offsets from the vertical
  // through its centre of mass, m (the accelerometer's lever arm, StatueAccelerometerMount; the
  // gyroscope reads the same anywhere on the block).
  Matrix3r sensor_to_statue = Matrix3r::Identity();
  Real height_m = 1.0;
  Real offset_x_m = 0.0;
  Real offset_y_m = 0.0;
  StatueSensorHealthSettings health;
  double offset_window_s = 2.0;  // s: the quiet start-up window that estimates the rate offset
  double max_age_s = 0.01;       // s: a sample older than this is not the statue's now
  StatueFilterSettings filter;   // its rate_noise_rad_s is the gyroscope's noise
};

// A build without the statue sensor (kStatueSensorBuiltIn false) keeps only whether one is
// configured (it refuses it); MonitorConfig holds StatueSensorConfig, the rest reached through
// built_part<StatueSensorSettings> (nullptr in such a build).
struct NoStatueSensorSettings {
  bool present = false;
};
using StatueSensorConfig =
    monitor::OptionalPart<StatueSensorSettings, kStatueSensorBuiltIn, NoStatueSensorSettings>;

// Checks the settings; the Error names the field ("statue_sensor.node", ...). The first
// leaves out the streams' health, which the second checks at the estimator's sample period.
[[nodiscard]] Error validate(const StatueSensorSettings& settings);
[[nodiscard]] Error validate(const StatueSensorSettings& settings, double sample_period_s);

// The mean of a stream's first quiet window (statue frame) whose values spread by at most
// `spread` on every axis: its offset.
class QuietWindowOffset {
 public:
  void start(int window_samples, Real spread) {
    window_samples_ = window_samples;
    spread_ = spread;
    summed_ = 0;
    sum_.setZero();
    offset_.setZero();
    ready_ = false;
  }
  // `value` statue frame; `quiet` as StatueSensor::on_sample's.
  void add(const Vector3r& value, bool quiet);
  [[nodiscard]] bool ready() const { return ready_; }
  [[nodiscard]] const Vector3r& offset() const { return offset_; }

 private:
  int window_samples_ = 2;
  Real spread_ = 0;
  int summed_ = 0;
  Vector3r sum_ = Vector3r::Zero();
  Vector3r low_ = Vector3r::Zero();  // the window's smallest and largest values
  Vector3r high_ = Vector3r::Zero();
  Vector3r offset_ = Vector3r::Zero();
  bool ready_ = false;
};

class StatueSensor {
 public:
  [[nodiscard]] Error start(const StatueSensorSettings& settings, double sample_period_s);
  // One gyroscope sample. `quiet`: the monitor's quiet (the statue at rest, the ground quiet;
  // true before the estimators run): the offset is estimated only then, over a window whose
  // rates spread by at most 0.05 rad/s.
  void on_sample(const StatueSample& sample, bool quiet);
  // One accelerometer sample (g, sensor frame): its stream's health and counters, its horizontal
  // offsets (estimated as the rate's, while `quiet`, on its difference to `ground_m_s2`, the
  // ground sensor's newest conditioned sample: a statue standing moves with the ground, so a
  // window of small shaking still gives the offset), the newest specific force.
  void on_acceleration(const monitor::SensorSample& sample, bool quiet,
                       const Vector3r& ground_m_s2 = Vector3r::Zero());
  void tick(std::int64_t now_ns) {
    rate_health_ = rate_tracker_.tick(now_ns);
    acceleration_health_ = acceleration_tracker_.tick(now_ns);
  }

  // Offset known, the gyroscope's stream not in fault, and a sample within max_age_s of
  // `now_ns` (receive clock).
  [[nodiscard]] bool usable(std::int64_t now_ns) const;
  // theta' of axis `axis` (0 or 1), rad/s: the newest rate, offset removed, statue frame.
  [[nodiscard]] Real axis_rate(int axis) const {
    return axis == 0 ? -rate_.y() : rate_.x();
  }
  // The accelerometer's horizontal offsets known, its stream not in fault, its newest sample
  // not saturated and within max_age_s of `now_ns`.
  [[nodiscard]] bool acceleration_usable(std::int64_t now_ns) const;
  // The horizontal specific force along axis `axis` (0: x, 1: y), m/s2: the newest, offset
  // removed, statue frame.
  [[nodiscard]] Real axis_specific_force(int axis) const {
    return axis == 0 ? specific_force_.x() : specific_force_.y();
  }
  // The gyroscope's stream (its counters count rate samples) and the accelerometer's.
  [[nodiscard]] const monitor::SensorHealth& rate_health() const { return rate_health_; }
  [[nodiscard]] const monitor::SensorHealth& acceleration_health() const {
    return acceleration_health_;
  }
  [[nodiscard]] bool ready() const { return rate_offset_.ready(); }
  [[nodiscard]] const Vector3r& offset_rad_s() const { return rate_offset_.offset(); }
  // The accelerometer's (x, y; z 0), m/s2.
  [[nodiscard]] const Vector3r& acceleration_offset_m_s2() const {
    return acceleration_offset_.offset();
  }
  // Samples fed since the stream last restarted (a restart loses the tilt: the filter resets).
  [[nodiscard]] std::uint64_t restarts() const { return restarts_; }

 private:
  Matrix3r sensor_to_statue_;  // set by start()
  double max_age_ns_ = 0.0;
  monitor::SensorHealthTracker rate_tracker_;
  monitor::SensorHealthTracker acceleration_tracker_;
  monitor::SensorHealth rate_health_;
  monitor::SensorHealth acceleration_health_;
  QuietWindowOffset rate_offset_;
  QuietWindowOffset acceleration_offset_;
  Vector3r rate_ = Vector3r::Zero();  // statue frame, rad/s
  Vector3r specific_force_ = Vector3r::Zero();  // statue frame, m/s2, horizontal offsets removed
  bool have_sample_ = false;
  bool have_acceleration_ = false;
  bool acceleration_saturated_ = false;  // the newest
  std::int64_t newest_ns_ = 0;
  std::int64_t newest_acceleration_ns_ = 0;
  std::uint64_t restarts_ = 0;
};

}  // namespace plinth::firmware

#include "plinth/firmware/statue_sensor.h"

#include <cmath>
#include <cstring>

#include "plinth/monitor/conditioning.h"

namespace plinth::firmware {

namespace {
// rad/s: the spread of a quiet window's rates (a BMI088's noise at 200 Hz is ~0.004 rad/s rms).
constexpr Real kQuietSpreadRadS = Real(0.05);
// m/s2: the same of the accelerometer's (a BMI088's noise at 200 Hz is ~0.02 m/s2 rms).
constexpr Real kQuietSpreadM_S2 = Real(0.3);

// lib/monitor's SensorHealthTracker compares a stream's three values with two limits; its names
// say g for the ground's accelerometers. The gyroscope's stream crosses into it here only: its
// values and limits in rad/s.
monitor::SensorHealthSettings tracker_settings(const StatueSensorHealthSettings& h,
                                               double sample_period_s, Real full_scale,
                                               Real max_valid) {
  monitor::SensorHealthSettings t;
  t.sample_period_s = sample_period_s;
  t.timeout_s = h.timeout_s;
  t.max_bridge_samples = h.max_bridge_samples;
  t.recovery_samples = h.recovery_samples;
  t.stuck_samples = h.stuck_samples;
  t.full_scale_g = full_scale;
  t.max_valid_g = max_valid;
  return t;
}

monitor::SensorSample tracker_sample(const StatueSample& s) {
  monitor::SensorSample t;
  t.receive_time_ns = s.receive_time_ns;
  t.sequence = s.sequence;
  t.status = s.status;
  t.acceleration_g = s.rotation_rate_rad_s;  // rad/s: tracker_settings' limits are too
  return t;
}

// The tracker's field names as the statue sensor's keys.
const char* health_field(const char* tracker_field, bool rate) {
  const struct {
    const char* tracker;
    const char* rate;
    const char* acceleration;
  } kFields[] = {
      {"sensor_health.timeout_s", "statue_sensor.health.timeout_s", nullptr},
      {"sensor_health.max_bridge_samples", "statue_sensor.health.max_bridge_samples", nullptr},
      {"sensor_health.recovery_samples", "statue_sensor.health.recovery_samples", nullptr},
      {"sensor_health.stuck_samples", "statue_sensor.health.stuck_samples", nullptr},
      {"sensor_health.full_scale_g", "statue_sensor.health.rate_full_scale_rad_s",
       "statue_sensor.health.acceleration_full_scale_g"},
      {"sensor_health.max_valid_g", "statue_sensor.health.rate_max_valid_rad_s",
       "statue_sensor.health.acceleration_max_valid_g"},
  };
  for (const auto& f : kFields) {
    if (std::strcmp(f.tracker, tracker_field) == 0) {
      return rate || f.acceleration == nullptr ? f.rate : f.acceleration;
    }
  }
  return "statue_sensor.health";
}

Error validate_health(const StatueSensorHealthSettings& h, double sample_period_s) {
  const struct {
    Real full_scale;
    Real max_valid;
    bool rate;
    const char* below;  // max_valid's reason, in the statue sensor's names
  } streams[] = {
      {h.rate_full_scale_rad_s, h.rate_max_valid_rad_s, true,
       "must not be below rate_full_scale_rad_s"},
      {h.acceleration_full_scale_g, h.acceleration_max_valid_g, false,
       "must not be below acceleration_full_scale_g"},
  };
  for (const auto& stream : streams) {
    const Error e = monitor::validate(
        tracker_settings(h, sample_period_s, stream.full_scale, stream.max_valid));
    if (e.ok()) continue;
    const bool below = std::strcmp(e.field, "sensor_health.max_valid_g") == 0 &&
                       e.code == ErrorCode::kInconsistent;
    return {e.code, health_field(e.field, stream.rate), below ? stream.below : e.reason,
            e.limit};
  }
  return ok_error();
}
}  // namespace

Error validate(const StatueSensorSettings& s) {
  if (s.node < 1 || s.node > 15) {
    return {ErrorCode::kOutOfRange, "statue_sensor.node", "must lie in 1..15"};
  }
  monitor::ConditioningSettings axes;
  axes.sensor_to_statue = s.sensor_to_statue;
  if (const Error e = monitor::validate(axes); !e.ok()) {
    return {e.code, "statue_sensor.sensor_to_statue", e.reason, e.limit};
  }
  if (!std::isfinite(s.height_m) || s.height_m < 0) {
    return {ErrorCode::kOutOfRange, "statue_sensor.height_m", "must be finite and >= 0"};
  }
  if (!std::isfinite(s.offset_x_m) || !std::isfinite(s.offset_y_m)) {
    return {ErrorCode::kNotFinite, "statue_sensor.offset_x_m", "the offsets must be finite"};
  }
  if (!std::isfinite(s.offset_window_s) || s.offset_window_s <= 0.0 || s.offset_window_s > 60.0) {
    return {ErrorCode::kOutOfRange, "statue_sensor.offset_window_s", "must lie in (0, 60] s",
            s.offset_window_s > 60.0 ? 60.0 : 0.0};
  }
  // A sample older than this is taken for the statue's now: beyond 0.1 s a stale reading could
  // say the statue stands while it rocks.
  if (!std::isfinite(s.max_age_s) || s.max_age_s <= 0.0 || s.max_age_s > 0.1) {
    return {ErrorCode::kOutOfRange, "statue_sensor.max_age_s", "must lie in (0, 0.1] s",
            s.max_age_s > 0.1 ? 0.1 : 0.0};
  }
  return validate(s.filter);
}

Error validate(const StatueSensorSettings& settings, double sample_period_s) {
  PLINTH_TRY(validate(settings));
  return validate_health(settings.health, sample_period_s);
}

Error StatueSensor::start(const StatueSensorSettings& settings, double sample_period_s) {
  PLINTH_TRY(validate(settings, sample_period_s));
  const StatueSensorHealthSettings& h = settings.health;
  PLINTH_TRY(monitor::SensorHealthTracker::create(
      tracker_settings(h, sample_period_s, h.rate_full_scale_rad_s, h.rate_max_valid_rad_s),
      rate_tracker_));
  PLINTH_TRY(monitor::SensorHealthTracker::create(
      tracker_settings(h, sample_period_s, h.acceleration_full_scale_g,
                       h.acceleration_max_valid_g),
      acceleration_tracker_));
  sensor_to_statue_ = settings.sensor_to_statue;
  max_age_ns_ = settings.max_age_s * 1e9;
  const double samples = std::ceil(settings.offset_window_s / sample_period_s);
  const int window = samples < 2.0 ? 2 : static_cast<int>(samples);
  rate_offset_.start(window, kQuietSpreadRadS);
  acceleration_offset_.start(window, kQuietSpreadM_S2);
  rate_.setZero();
  specific_force_.setZero();
  have_sample_ = false;
  have_acceleration_ = false;
  acceleration_saturated_ = false;
  newest_ns_ = 0;
  newest_acceleration_ns_ = 0;
  restarts_ = 0;
  rate_health_ = rate_tracker_.health();
  acceleration_health_ = acceleration_tracker_.health();
  return ok_error();
}

// The offset: the mean of the first quiet window (a start-up rate offset of a MEMS gyroscope is
// up to +-1 deg/s, an accelerometer's tens of mg; their drift in a museum's temperature is far
// smaller). A window whose values spread beyond `spread` on an axis is the statue moving: again.
void QuietWindowOffset::add(const Vector3r& value, bool quiet) {
  if (ready_) return;
  if (summed_ == 0) low_ = high_ = value;
  low_ = low_.cwiseMin(value);
  high_ = high_.cwiseMax(value);
  if (quiet && (high_ - low_).maxCoeff() <= spread_) {
    sum_ += value;
    if (++summed_ >= window_samples_) {
      offset_ = sum_ / static_cast<Real>(summed_);
      ready_ = true;
    }
  } else {
    summed_ = 0;
    sum_.setZero();
  }
}

void StatueSensor::on_acceleration(const monitor::SensorSample& sample, bool quiet,
                                   const Vector3r& ground_m_s2) {
  const monitor::SensorUpdate update = acceleration_tracker_.on_sample(sample);
  acceleration_health_ = update.health;
  for (std::size_t i = 0; i < update.fed_count; ++i) {
    const monitor::FedSample& fed = update.fed[i];
    const Vector3r statue = sensor_to_statue_ * fed.acceleration_g * kStandardGravity;  // m/s2
    // Standing, the horizontal specific force is the ground's: only x and y have an offset.
    acceleration_offset_.add(
        Vector3r(statue.x() - ground_m_s2.x(), statue.y() - ground_m_s2.y(), Real(0)), quiet);
    const Vector3r& offset = acceleration_offset_.offset();
    specific_force_ = Vector3r(statue.x() - offset.x(), statue.y() - offset.y(), statue.z());
    acceleration_saturated_ = fed.saturated;
    newest_acceleration_ns_ = fed.time_ns;
    have_acceleration_ = true;
  }
}

void StatueSensor::on_sample(const StatueSample& sample, bool quiet) {
  const monitor::SensorUpdate update = rate_tracker_.on_sample(tracker_sample(sample));
  rate_health_ = update.health;
  for (std::size_t i = 0; i < update.fed_count; ++i) {
    const monitor::FedSample& fed = update.fed[i];
    if (fed.restart) ++restarts_;
    // tracker_sample() put the rates where the tracker keeps its values.
    const Vector3r statue = sensor_to_statue_ * fed.acceleration_g;  // rad/s
    rate_offset_.add(statue, quiet);
    rate_ = statue - rate_offset_.offset();
    newest_ns_ = fed.time_ns;
    have_sample_ = true;
  }
}

bool StatueSensor::usable(std::int64_t now_ns) const {
  if (!rate_offset_.ready() || !have_sample_ ||
      rate_health_.state == monitor::HealthState::kFault) {
    return false;
  }
  const std::int64_t age = now_ns - newest_ns_;
  return static_cast<double>(age) <= max_age_ns_;
}

bool StatueSensor::acceleration_usable(std::int64_t now_ns) const {
  if (!acceleration_offset_.ready() || !have_acceleration_ || acceleration_saturated_ ||
      acceleration_health_.state == monitor::HealthState::kFault) {
    return false;
  }
  const std::int64_t age = now_ns - newest_acceleration_ns_;
  return static_cast<double>(age) <= max_age_ns_;
}

}  // namespace plinth::firmware

#include "plinth/firmware/statue_sensor.h"

#include <cmath>

#include "plinth/monitor/conditioning.h"

namespace plinth::firmware {

namespace {
// rad/s: the spread of a quiet window's rates (a BMI088's noise at 200 Hz is ~0.004 rad/s rms).
constexpr Real kQuietSpreadRadS = Real(0.05);
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
  if (!std::isfinite(s.offset_window_s) || s.offset_window_s <= 0.0) {
    return {ErrorCode::kOutOfRange, "statue_sensor.offset_window_s", "must be finite and > 0"};
  }
  if (!std::isfinite(s.max_age_s) || s.max_age_s <= 0.0) {
    return {ErrorCode::kOutOfRange, "statue_sensor.max_age_s", "must be finite and > 0"};
  }
  return validate(s.filter);
}

Error StatueSensor::start(const StatueSensorSettings& settings, double sample_period_s) {
  PLINTH_TRY(validate(settings));
  monitor::SensorHealthSettings health = settings.health;
  health.sample_period_s = sample_period_s;
  PLINTH_TRY(monitor::SensorHealthTracker::create(health, health_tracker_));
  settings_ = settings;
  const double samples = std::ceil(settings.offset_window_s / sample_period_s);
  window_samples_ = samples < 2.0 ? 2 : static_cast<int>(samples);
  summed_ = 0;
  sum_.setZero();
  offset_.setZero();
  rate_.setZero();
  ready_ = false;
  have_sample_ = false;
  newest_ns_ = 0;
  restarts_ = 0;
  health_ = health_tracker_.health();
  return ok_error();
}

void StatueSensor::on_sample(const monitor::SensorSample& sample, bool quiet) {
  const monitor::SensorUpdate update = health_tracker_.on_sample(sample);
  health_ = update.health;
  for (std::size_t i = 0; i < update.fed_count; ++i) {
    const monitor::FedSample& fed = update.fed[i];
    if (fed.restart) ++restarts_;
    const Vector3r statue = settings_.sensor_to_statue * fed.acceleration_g;  // rad/s
    // The offset: the mean of the first quiet window (a start-up rate offset of a MEMS
    // gyroscope is up to +-1 deg/s; its drift in a museum's temperature is far smaller).
    // A window whose rates spread beyond kQuietSpread on an axis is the statue moving: again.
    if (!ready_) {
      if (summed_ == 0) low_ = high_ = statue;
      low_ = low_.cwiseMin(statue);
      high_ = high_.cwiseMax(statue);
      if (quiet && (high_ - low_).maxCoeff() <= kQuietSpreadRadS) {
        sum_ += statue;
        if (++summed_ >= window_samples_) {
          offset_ = sum_ / static_cast<Real>(summed_);
          ready_ = true;
        }
      } else {
        summed_ = 0;
        sum_.setZero();
      }
    }
    rate_ = statue - offset_;
    newest_ns_ = fed.time_ns;
    have_sample_ = true;
  }
}

bool StatueSensor::usable(std::int64_t now_ns) const {
  if (!ready_ || !have_sample_ || health_.state == monitor::HealthState::kFault) return false;
  const std::int64_t age = now_ns - newest_ns_;
  return static_cast<double>(age) <= settings_.max_age_s * 1e9;
}

}  // namespace plinth::firmware

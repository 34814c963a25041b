// Synthetic input for the monitor's long-run tests: the ground sensor of a quiet site (noise
// and a slowly drifting bias, as temperature makes it drift), then a recorded earthquake.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "plinth/host/record_io.h"
#include "plinth/core/scene.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::testing {

class QuietThenQuake {
 public:
  static constexpr double kNoiseG = 3e-4;   // sensor noise, standard deviation, g
  static constexpr double kDriftGPerHour = 2e-3;  // bias drift, g per hour (x and z)

  // `quiet_s` of quiet, then `record` (resampled to `rate_hz`) times `gamma`. Sensor in g.
  QuietThenQuake(double rate_hz, double quiet_s, const host::Record& record, double gamma)
      : rate_hz_(rate_hz), quiet_samples_(static_cast<long>(std::llround(quiet_s * rate_hz))) {
    const SampledSignal h = record.horizontal_signal();
    const auto count = static_cast<long>(std::floor(record.duration() * rate_hz)) + 1;
    quake_g_.reserve(static_cast<std::size_t>(count));
    for (long n = 0; n < count; ++n) {
      quake_g_.push_back(gamma * h.at(static_cast<double>(n) / rate_hz) / record_gravity_);
    }
  }

  [[nodiscard]] long size() const { return quiet_samples_ + static_cast<long>(quake_g_.size()); }
  [[nodiscard]] long quiet_samples() const { return quiet_samples_; }
  [[nodiscard]] double time(long n) const { return static_cast<double>(n) / rate_hz_; }
  // The sensor's bias at sample n (it stops drifting when the quake starts), g.
  [[nodiscard]] Eigen::Vector3d bias_g(long n) const {
    const double drift = kDriftGPerHour * time(std::min(n, quiet_samples_)) / 3600.0;
    return Eigen::Vector3d(1e-3 + drift, -5e-4, 2e-3 + drift);
  }

  // Sample n; no allocation.
  [[nodiscard]] monitor::SensorSample sample(long n) {
    monitor::SensorSample s;
    s.receive_time_ns = std::llround(static_cast<double>(n) / rate_hz_ * 1e9);
    s.sequence = static_cast<std::uint8_t>(n & 0xFF);
    const double quake = n < quiet_samples_ ? 0.0 : quake_g_[static_cast<std::size_t>(n - quiet_samples_)];
    s.acceleration_g = Eigen::Vector3d(quake + noise(), noise(), 1.0 + noise()) + bias_g(n);
    return s;
  }

 private:
  double noise() { return kNoiseG * gauss_(rng_); }

  double rate_hz_;
  long quiet_samples_;
  double record_gravity_ = kStandardGravity;
  std::vector<double> quake_g_;
  std::mt19937_64 rng_{2026};
  std::normal_distribution<double> gauss_{0.0, 1.0};
};

}  // namespace plinth::testing

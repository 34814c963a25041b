#include "plinth/host/record_sampling.h"

#include <algorithm>
#include <cmath>

#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/units.h"

namespace plinth::host {
namespace {

// Sample counts come from products like 34.9827 s * 200 Hz: forgive rounding below a sample.
constexpr double kSampleCountTolerance = 1e-6;
// Relative: how close rate * dt must be to 1 for the record's own samples to be read as they are.
constexpr double kSameRateTolerance = 1e-9;
// Relative: how close to the record's last sample position (in samples) counts as on it.
constexpr double kLastSampleTolerance = 1e-9;

// SampledSignal::at, except that a time within rounding of the last sample reads that sample:
// k / rate may land on the record's end in exact arithmetic and just past it in floating point,
// where at() reads zero.
double interpolated_at(const SampledSignal& signal, double t) {
  if (signal.count > 0) {
    const auto last = static_cast<double>(signal.count - 1);
    if (std::fabs(t / signal.dt - last) <= kLastSampleTolerance * std::max(1.0, last)) {
      return signal.values[signal.count - 1];
    }
  }
  return signal.at(t);
}

}  // namespace

double record_scale(const Record& record, const std::string& record_path, const std::string& pga,
                    std::optional<double> scale, double gravity) {
  double vertical_peak = 0.0;
  for (const double a : record.vertical) vertical_peak = std::max(vertical_peak, std::fabs(a));
  const double peak = std::max(record.peak_horizontal(), vertical_peak);
  if (pga.empty()) {
    const double gamma = scale.value_or(1.0);
    if (scale) check_scaled_peak(gamma, peak, gravity, given("--scale", gamma));
    return gamma;
  }
  const double target = parse_acceleration(pga, gravity, "--pga");
  if (target <= 0.0) {
    throw InputError("--pga " + pga +
                     ": must be greater than zero (use --scale with a negative factor to mirror "
                     "the record)");
  }
  if (record.peak_horizontal() <= 0.0) {
    throw InputError(record_path + ": record is all zeros, cannot scale to --pga");
  }
  const double gamma = target / record.peak_horizontal();
  check_scaled_peak(gamma, peak, gravity, "--pga " + pga);
  return gamma;
}

std::size_t sample_count(double duration_s, double rate_hz) {
  return static_cast<std::size_t>(std::floor(duration_s * rate_hz + kSampleCountTolerance)) + 1;
}

std::vector<double> resample(const SampledSignal& signal, double rate_hz, std::size_t count) {
  std::vector<double> out(count, 0.0);
  if (signal.empty()) return out;
  if (std::fabs(rate_hz * signal.dt - 1.0) <= kSameRateTolerance) {
    std::copy_n(signal.values, std::min(count, signal.count), out.begin());
    return out;
  }
  for (std::size_t k = 0; k < count; ++k) {
    out[k] = interpolated_at(signal, static_cast<double>(k) / rate_hz);
  }
  return out;
}

}  // namespace plinth::host

#include "record_input.h"

#include "plinth/core/excitation.h"
#include "plinth/host/record_io.h"
#include "plinth/host/record_sampling.h"

namespace plinth::firmware {
namespace {
constexpr double kDefaultRecordRateHz = 200.0;  // for records outside the sensor rates
constexpr double kMinSensorRateHz = 100.0;
constexpr double kMaxSensorRateHz = 1000.0;
}  // namespace

RecordSamples record_samples(const RecordReplayOptions& opt, double gravity) {
  const host::Record h = host::read_record(opt.path, gravity);
  std::optional<host::Record> y;
  if (!opt.y_path.empty()) y = host::read_record(opt.y_path, gravity);
  std::optional<host::Record> v;
  if (!opt.vertical_path.empty()) v = host::read_record(opt.vertical_path, gravity);
  const double gamma = host::record_scale(h, opt.path, opt.pga, opt.scale, gravity);
  RecordSamples out;
  const double native = 1.0 / h.dt;
  out.rate_hz = opt.rate_hz                                                ? *opt.rate_hz
                : native >= kMinSensorRateHz && native <= kMaxSensorRateHz ? native
                                                                           : kDefaultRecordRateHz;
  const std::size_t count = host::sample_count(h.duration(), out.rate_hz);
  const auto read = [&](const SampledSignal& signal) {
    return host::resample(signal, out.rate_hz, count);
  };
  const std::vector<double> ax = read(h.horizontal_signal());
  const std::vector<double> ay = y ? read(y->horizontal_signal()) : std::vector<double>();
  const std::vector<double> az = v                    ? read(v->horizontal_signal())
                                 : h.vertical.empty() ? std::vector<double>()
                                                      : read(h.vertical_signal());
  out.vertical = !az.empty();
  out.samples.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    out.samples.emplace_back(gamma * ax[k], ay.empty() ? 0.0 : gamma * ay[k],
                             gravity + (az.empty() ? 0.0 : gamma * az[k]));
  }
  return out;
}

}  // namespace plinth::firmware

#include "record_input.h"

#include <cmath>

#include "plinth/core/excitation.h"
#include "plinth/host/input_error.h"
#include "plinth/host/record_io.h"
#include "plinth/host/units.h"

namespace plinth::firmware {

RecordSamples record_samples(const RecordInput& input, double gravity) {
  const host::Record h = host::read_record(input.path, gravity);
  std::optional<host::Record> y;
  if (!input.y_path.empty()) y = host::read_record(input.y_path, gravity);
  std::optional<host::Record> v;
  if (!input.vertical_path.empty()) v = host::read_record(input.vertical_path, gravity);
  RecordSamples out;
  if (input.scale) out.scale = *input.scale;
  if (!input.pga.empty()) {
    const double pga = host::parse_acceleration(input.pga, gravity, "--pga");
    if (h.peak_horizontal() <= 0.0)
      throw host::InputError(input.path + ": the record is all zeros");
    out.scale = pga / h.peak_horizontal();
  }
  const double gamma = out.scale;
  const double native = 1.0 / h.dt;
  out.rate_hz =
      input.rate_hz ? *input.rate_hz : (native >= 100.0 && native <= 1000.0 ? native : 200.0);
  const bool resample = std::fabs(out.rate_hz * h.dt - 1.0) > 1e-9;
  const auto signal_at = [&](const host::Record& r, std::size_t n, bool vertical) {
    const std::vector<double>& values = vertical && !r.vertical.empty() ? r.vertical : r.horizontal;
    if (!resample) return n < values.size() ? values[n] : 0.0;
    const SampledSignal s{values.data(), values.size(), r.dt};
    return s.at(static_cast<double>(n) / out.rate_hz);
  };
  const std::size_t count =
      static_cast<std::size_t>(std::floor(h.duration() * out.rate_hz + 1e-9)) + 1;
  out.samples.reserve(count);
  for (std::size_t n = 0; n < count; ++n) {
    Eigen::Vector3d a;
    a.x() = gamma * signal_at(h, n, false);
    a.y() = y ? gamma * signal_at(*y, n, false) : 0.0;
    double vertical = 0.0;
    if (v) {
      vertical = gamma * signal_at(*v, n, false);
    } else if (!h.vertical.empty()) {
      vertical = gamma * signal_at(h, n, true);
    }
    a.z() = gravity + vertical;
    out.samples.push_back(a);
  }
  return out;
}

}  // namespace plinth::firmware

// Records as the tools use them: scaled as the command line asks (--pga, --scale) and read at a
// sensor's rate (plinth-monitor's samples, plinth-replay's frames).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "plinth/core/excitation.h"
#include "plinth/host/record_io.h"

namespace plinth::host {

// The factor gamma the command line asks for: `pga` (an acceleration with its unit, "0.3g")
// over the record's peak horizontal acceleration, or `scale`, or 1 when neither is given.
// Throws InputError for a --pga that is not a positive acceleration, a scaled peak (horizontal
// or vertical) above kMaxScaledPeakG (limits.h), and for a record that is
// all zeros (named by `record_path`).
[[nodiscard]] double record_scale(const Record& record, const std::string& record_path,
                                  const std::string& pga, std::optional<double> scale,
                                  double gravity);

// The samples a sensor at `rate_hz` takes in `duration_s`: k = 0 .. floor(duration_s * rate_hz)
// (a product a millionth of a sample short of a whole number counts as that number).
[[nodiscard]] std::size_t sample_count(double duration_s, double rate_hz);

// `signal` read at t = k / rate_hz, k = 0 .. count - 1: its own samples when rate_hz is its own
// rate; otherwise linearly interpolated between them (SampledSignal::at, the solver's reading),
// a time within rounding of the last sample reading that sample. Zero after the last sample.
[[nodiscard]] std::vector<double> resample(const SampledSignal& signal, double rate_hz,
                                           std::size_t count);

}  // namespace plinth::host

#include "plinth/host/limits.h"

#include <cmath>
#include <cstdio>

#include "plinth/host/input_error.h"

namespace plinth::host {

std::string number_text(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

std::string given(const std::string& option, double value) {
  return option + " " + number_text(value);
}

std::int64_t bounded_count(double count, double limit, const std::string& subject,
                           const std::string& doing, const std::string& what) {
  if (!(count <= limit)) {  // also NaN
    throw InputError(subject + ": " + doing + " " + number_text(count, 3) + " " + what + ", limit " +
                     number_text(limit, 3));
  }
  return count <= 0.0 ? 0 : static_cast<std::int64_t>(count);
}

void check_scaled_peak(double gamma, double peak_mps2, double gravity, const std::string& subject) {
  const double peak_g = std::fabs(gamma) * peak_mps2 / gravity;
  if (!(peak_g <= kMaxScaledPeakG)) {
    throw InputError(subject + ": the scaled record's peak would be " + number_text(peak_g, 3) +
                     " g, limit " + number_text(kMaxScaledPeakG, 3) + " g");
  }
}

}  // namespace plinth::host

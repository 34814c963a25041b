#include "latency_log.h"

#include <algorithm>

#include "status_json.h"

namespace plinth::firmware {

namespace {

// The nearest-rank quantile q of sorted values, us.
double quantile_us(const std::vector<std::uint32_t>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const auto rank = static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1) + 0.5);
  return static_cast<double>(sorted[std::min(rank, sorted.size() - 1)]) * 1e-3;
}

}  // namespace

std::string LatencyLog::summary_json() {
  std::sort(values_ns_.begin(), values_ns_.end());
  return JsonObject()
      .count("samples", values_ns_.size())
      .fixed("median_us", quantile_us(values_ns_, 0.5), 3)
      .fixed("p99_us", quantile_us(values_ns_, 0.99), 3)
      .fixed("max_us", quantile_us(values_ns_, 1.0), 3)
      .count("not_kept", not_kept_)
      .close();
}

}  // namespace plinth::firmware

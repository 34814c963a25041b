// plinth-monitor --latency: each sample's time from its arrival (the input hands it to the loop)
// to its status being ready (the status line written, the outputs' snapshot posted), kept in
// memory reserved before the run and summarised at the end (docs/integration.md, "Latency").
// Host code.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace plinth::firmware {

class LatencyLog {
 public:
  // Keeps the first `capacity` samples' latencies; later ones are counted only.
  explicit LatencyLog(std::size_t capacity) { values_ns_.reserve(capacity); }
  void add(std::int64_t latency_ns) {
    if (values_ns_.size() == values_ns_.capacity()) {
      ++not_kept_;
      return;
    }
    values_ns_.push_back(static_cast<std::uint32_t>(latency_ns < 0            ? 0
                                                    : latency_ns > 0xFFFFFFFF ? 0xFFFFFFFF
                                                                              : latency_ns));
  }
  // {"samples": .., "median_us": .., "p99_us": .., "max_us": .., "not_kept": ..}; sorts.
  [[nodiscard]] std::string summary_json();

 private:
  std::vector<std::uint32_t> values_ns_;
  std::uint64_t not_kept_ = 0;
};

}  // namespace plinth::firmware

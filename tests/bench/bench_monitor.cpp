// plinth-bench-monitor: the box's loop per sensor sample, for each sensor rate and solver steps
// per sample: time per sample (median, p99, max) and the factor faster than real time, all
// measured in one run on the same input (a quiet minute, then Brienza scaled so the block
// rocks and overturns, then the block at rest). docs/monitor.md quotes its output.
//   plinth-bench-monitor [--quick]
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "monitor_input.h"
#include "plinth/firmware/monitor.h"
#include "plinth/host/record_io.h"
#include "test_support.h"

namespace {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace plinth;
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  const host::Record record = host::read_at2(
      std::string(PLINTH_SOURCE_DIR) + "/sim/data/records/irpinia1980_brienza_000.AT2",
      kStandardGravity);
  std::printf("| rate (Hz) | steps/sample | median (ns/sample) | p99 | max | x real time | "
              "one core at this rate |\n|---|---|---|---|---|---|---|\n");
  const std::vector<double> rates = quick ? std::vector<double>{200.0}
                                          : std::vector<double>{100.0, 200.0, 500.0, 1000.0};
  const std::vector<int> steps = quick ? std::vector<int>{4} : std::vector<int>{1, 2, 4, 8};
  for (const double rate : rates) {
    for (const int k : steps) {
      testing::QuietThenQuake input(rate, quick ? 15.0 : 60.0, record, 20.0);
      firmware::MonitorConfig config;
      config.estimator.sample_rate_hz = rate;
      config.estimator.steps_per_sample = k;
      config.conditioning.startup_window_s = 5.0;
      firmware::Monitor monitor;
      const Error e = monitor.start(config, {&scene, nullptr});
      if (!e.ok()) {
        std::fprintf(stderr, "rate %g, steps %d: %s %s\n", rate, k, e.field, e.reason);
        return 1;
      }
      // Samples are made before the clock starts: only the monitor is timed.
      std::vector<monitor::SensorSample> samples;
      const long total = input.size() + static_cast<long>(20.0 * rate);  // + 20 s at rest
      samples.reserve(static_cast<std::size_t>(total));
      for (long n = 0; n < total; ++n) samples.push_back(input.sample(std::min(n, input.size() - 1)));
      for (long n = input.size(); n < total; ++n) {
        samples[static_cast<std::size_t>(n)].receive_time_ns =
            std::llround(static_cast<double>(n) / rate * 1e9);
        samples[static_cast<std::size_t>(n)].sequence = static_cast<std::uint8_t>(n & 0xFF);
      }
      std::vector<std::int64_t> cost;
      cost.reserve(samples.size());
      std::int64_t sum = 0;
      for (const monitor::SensorSample& s : samples) {
        const std::int64_t t0 = now_ns();
        (void)monitor.on_sample(s);
        const std::int64_t dt = now_ns() - t0;
        cost.push_back(dt);
        sum += dt;
      }
      std::sort(cost.begin(), cost.end());
      const auto at = [&](double q) {
        return cost[static_cast<std::size_t>(q * static_cast<double>(cost.size() - 1))];
      };
      const double mean = static_cast<double>(sum) / static_cast<double>(cost.size());
      std::printf("| %g | %d | %lld | %lld | %lld | %.0f | %.3f %% |\n", rate, k,
                  static_cast<long long>(at(0.5)), static_cast<long long>(at(0.99)),
                  static_cast<long long>(cost.back()), 1e9 / rate / mean, mean * rate / 1e7);
    }
  }
  return 0;
}

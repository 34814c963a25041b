// plinth-bench-monitor: the box's loop per sensor sample, for each sensor rate and solver steps
// per sample: time per sample (median, p99, max) and the factor faster than real time, all
// measured in one run on the same input (a quiet minute, then Brienza scaled so the block
// rocks and overturns, then the block at rest). docs/monitor.md quotes its output. Then the
// ensemble and the forecast at 1000 Hz (docs/forecast.md): one statue without and with the
// forecast, 9 and 17 members without and with it, each as a share of one core and as a ratio
// to the first, measured in the same run.
//   plinth-bench-monitor [--quick]
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "monitor_input.h"
#include "plinth/firmware/monitor.h"
#include "plinth/host/record_io.h"
#include "plinth/host/scene_toml.h"
#include "test_support.h"

namespace {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The input: `quiet_s` of a quiet site, Brienza scaled so the block rocks, then 20 s at rest.
std::vector<plinth::monitor::SensorSample> make_samples(double rate, double quiet_s,
                                                        const plinth::host::Record& record) {
  plinth::testing::QuietThenQuake input(rate, quiet_s, record, 20.0);
  std::vector<plinth::monitor::SensorSample> samples;
  const long total = input.size() + static_cast<long>(20.0 * rate);
  samples.reserve(static_cast<std::size_t>(total));
  for (long n = 0; n < total; ++n) samples.push_back(input.sample(std::min(n, input.size() - 1)));
  for (long n = input.size(); n < total; ++n) {
    samples[static_cast<std::size_t>(n)].receive_time_ns =
        std::llround(static_cast<double>(n) / rate * 1e9);
    samples[static_cast<std::size_t>(n)].sequence = static_cast<std::uint8_t>(n & 0xFF);
  }
  return samples;
}

struct Cost {
  std::int64_t median_ns = 0, p99_ns = 0, max_ns = 0;
  double mean_ns = 0.0;
};

// The monitor's time per sample over `samples` (sorted costs, and their mean).
Cost time_samples(plinth::firmware::Monitor& monitor,
                  const std::vector<plinth::monitor::SensorSample>& samples) {
  std::vector<std::int64_t> cost;
  cost.reserve(samples.size());
  std::int64_t sum = 0;
  for (const plinth::monitor::SensorSample& s : samples) {
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
  return {at(0.5), at(0.99), cost.back(), static_cast<double>(sum) / static_cast<double>(cost.size())};
}

// An isolated statue with `keys` uncertain parameters (1 + the design's corners members).
constexpr const char* kEnsembleScene = R"(
[block]
half_width = 0.3
slenderness = 3.0
eccentricity_ratio = 0.0
density = 2000.0
depth = 1.0
[base]
mass_ratio = 1.0
period = 2.0
damping_ratio = 0.2
[base_stops]
max_displacement = 0.2
restitution = 0.7
[friction]
static = 0.8
kinetic = 0.7
[uncertainty.block]
slenderness = [2.79, 3.21]
eccentricity_ratio = [-0.08, 0.08]
density = [1800.0, 2200.0]
[uncertainty.base]
period = [1.7, 2.3]
)";
constexpr const char* kMoreKeys = R"(damping_ratio = [0.15, 0.25]
mass_ratio = [0.8, 1.2]
[uncertainty.base_stops]
restitution = [0.5, 0.9]
[uncertainty.friction]
static = [0.7, 0.9]
)";

int ensemble_table(const plinth::host::Record& record, bool quick) {
  using namespace plinth;
  const double rate = 1000.0;
  const std::vector<monitor::SensorSample> samples = make_samples(rate, quick ? 5.0 : 30.0, record);
  const host::UncertainScene nine =
      host::load_uncertain_scene_text(std::string(kEnsembleScene) + "damping_ratio = [0.15, 0.25]\n", "nine");
  const host::UncertainScene seventeen =
      host::load_uncertain_scene_text(std::string(kEnsembleScene) + kMoreKeys, "seventeen");
  std::printf("\n| members | forecast | median (ns/sample) | p99 | max | one core at 1000 Hz | "
              "ratio to one statue without |\n|---|---|---|---|---|---|---|\n");
  double base_mean = 0.0;
  for (const host::UncertainScene* scene : {&nine, &nine, &seventeen}) {
    const bool single = base_mean == 0.0;
    const std::span<const Scene> members =
        single ? std::span<const Scene>(scene->members.data(), 1) : std::span<const Scene>(scene->members);
    for (const bool forecast : {false, true}) {
      firmware::MonitorConfig config;
      config.estimator.sample_rate_hz = rate;
      config.estimator.steps_per_sample = 4;
      config.conditioning.startup_window_s = 5.0;
      config.forecast.enabled = forecast;
      auto monitor = std::make_unique<firmware::Monitor>();
      const Error e = monitor->start(config, {members, {}});
      if (!e.ok()) {
        std::fprintf(stderr, "%zu members: %s %s\n", members.size(), e.field, e.reason);
        return 1;
      }
      const Cost c = time_samples(*monitor, samples);
      if (base_mean == 0.0) base_mean = c.mean_ns;
      std::printf("| %zu | %s | %lld | %lld | %lld | %.3f %% | %.2f |\n", members.size(),
                  forecast ? "yes" : "no", static_cast<long long>(c.median_ns),
                  static_cast<long long>(c.p99_ns), static_cast<long long>(c.max_ns),
                  c.mean_ns * rate / 1e7, c.mean_ns / base_mean);
    }
  }
  return 0;
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
      firmware::MonitorConfig config;
      config.estimator.sample_rate_hz = rate;
      config.estimator.steps_per_sample = k;
      config.conditioning.startup_window_s = 5.0;
      config.forecast.enabled = false;  // today's box; the forecast's cost: the second table
      firmware::Monitor monitor;
      const Error e = monitor.start(config, {&scene, nullptr});
      if (!e.ok()) {
        std::fprintf(stderr, "rate %g, steps %d: %s %s\n", rate, k, e.field, e.reason);
        return 1;
      }
      // Samples are made before the clock starts: only the monitor is timed.
      const std::vector<monitor::SensorSample> samples =
          make_samples(rate, quick ? 15.0 : 60.0, record);
      const Cost c = time_samples(monitor, samples);
      std::printf("| %g | %d | %lld | %lld | %lld | %.0f | %.3f %% |\n", rate, k,
                  static_cast<long long>(c.median_ns), static_cast<long long>(c.p99_ns),
                  static_cast<long long>(c.max_ns), 1e9 / rate / c.mean_ns, c.mean_ns * rate / 1e7);
    }
  }
  return ensemble_table(record, quick);
}

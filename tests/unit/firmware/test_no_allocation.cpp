// The stepping path allocates nothing: the global allocation functions are replaced by
// counting ones, and a long run with many events must not call them.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include "bundled_records.h"
#include "monitor_input.h"
#include "plinth/firmware/monitor.h"
#include "plinth/host/record_io.h"
#include "test_support.h"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return operator new(size, tag);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace plinth {
namespace {

// Counts events without allocating.
class CountingSink final : public EventSink {
 public:
  void on_event(const Event& e) override { ++counts[static_cast<int>(e.kind)]; }
  long counts[32] = {};  // indexed by EventKind
};

TEST(NoAllocation, CounterSeesAllocations) {
  const long before = g_allocations.load();
  auto* p = new std::string(100, 'x');
  EXPECT_GT(g_allocations.load(), before);
  delete p;
}

TEST(NoAllocation, LongRunsWithEventsAllocateNothing) {
  const host::Record record = testing::brienza();
  SceneParams isolated = testing::paper_isolated(0.3, 1.0);
  isolated.has_base_stops = true;
  isolated.base_stops = {0.05, 0.7};
  const SceneParams grounded = testing::paper_block(0.0);
  for (const SceneParams& p : {isolated, grounded}) {
    const Scene s = testing::make(p);
    const Excitation ex = Excitation::record(record.horizontal_signal(), {},
                                             1.0 * kStandardGravity / record.peak_horizontal());
    SolverSettings settings;
    Simulator sim;
    ASSERT_TRUE(Simulator::create(s, ex, settings, sim).ok());
    CountingSink sink;
    sim.set_event_sink(&sink);
    const long before = g_allocations.load();
    sim.start_at_rest();
    long steps = 0;
    // Two minutes of simulated time: the record, then the block at rest on a still ground.
    for (; steps < 1'200'000 && !sim.mode().terminal(); ++steps) sim.step();
    EXPECT_FALSE(sim.mode().terminal()) << "the run must go the whole way";
    const long allocations = g_allocations.load() - before;
    EXPECT_EQ(allocations, 0);
    EXPECT_GT(sink.counts[static_cast<int>(EventKind::kRockingStart)], 0);
    EXPECT_GT(sink.counts[static_cast<int>(EventKind::kImpact)], 0);
    if (p.has_base_stops) {
      EXPECT_GT(sink.counts[static_cast<int>(EventKind::kBaseStopHit)], 0);
    }
  }
}

// The box's loop over an hour of input at 200 Hz (quiet noise with a drifting sensor bias,
// then Brienza scaled to overturn the block): nothing allocated after start-up, no alarm while
// quiet, the block at rest and the bias followed, the alarm in the earthquake.
TEST(NoAllocation, MonitorRunsAnHourWithoutAllocating) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  const host::Record record = testing::brienza();
  const double quiet_s = 3600.0;
  testing::QuietThenQuake input(200.0, quiet_s, record, 20.0);
  firmware::MonitorConfig config;
  config.estimator.sample_rate_hz = 200.0;
  firmware::Monitor monitor;
  ASSERT_TRUE(monitor.start(config, {&scene, nullptr}).ok());
  CountingSink sink;
  monitor.set_event_sink(0, &sink);
  const long before = g_allocations.load();
  long quiet_alarms = 0;
  double peak_quiet_u = 0.0;
  double alarm_t = -1.0;
  for (long n = 0; n < input.size() && !monitor.status().axes[0].mode.terminal(); ++n) {
    const firmware::MonitorUpdate u = monitor.on_sample(input.sample(n));
    if (n % 2 == 0) (void)monitor.on_tick(input.sample(n).receive_time_ns);
    const bool quiet = n < input.quiet_samples();
    for (std::size_t i = 0; i < u.event_count; ++i) {
      const monitor::AlarmLevel level = u.events[i].level;
      if (quiet && level != monitor::AlarmLevel::kNormal && level != monitor::AlarmLevel::kFault) {
        ++quiet_alarms;
      }
      if (!quiet && level == monitor::AlarmLevel::kAlarm && alarm_t < 0.0) alarm_t = input.time(n);
    }
    if (quiet) peak_quiet_u = std::fmax(peak_quiet_u, std::fabs(monitor.status().axes[0].state[kU]));
    if (n == input.quiet_samples() - 1) {
      const Eigen::Vector3d error =
          monitor.conditioning().offset_m_s2 - input.bias_g(n) * kStandardGravity;
      EXPECT_LT(error.cwiseAbs().maxCoeff(), 1e-3 * kStandardGravity);
      EXPECT_EQ(monitor.status().axes[0].mode.phase, Phase::kFullContact);
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(quiet_alarms, 0);
  EXPECT_LT(peak_quiet_u, 1e-3);
  EXPECT_GT(alarm_t, quiet_s);
  EXPECT_EQ(monitor.status().axes[0].mode.phase, Phase::kOverturned);
  EXPECT_GT(sink.counts[static_cast<int>(EventKind::kRockingStart)], 0);
  EXPECT_EQ(monitor.status().sensor.counters.faults, 0U);  // (the start-up state is not an entry)
}

}  // namespace
}  // namespace plinth

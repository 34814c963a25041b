// The stepping path allocates nothing: the global allocation functions are replaced by
// counting ones, and a long run with many events must not call them.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

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
  long counts[8] = {};
};

TEST(NoAllocation, CounterSeesAllocations) {
  const long before = g_allocations.load();
  auto* p = new std::string(100, 'x');
  EXPECT_GT(g_allocations.load(), before);
  delete p;
}

TEST(NoAllocation, LongRunsWithEventsAllocateNothing) {
  const host::Record record = host::read_at2(
      std::string(PLINTH_SOURCE_DIR) + "/sim/data/records/irpinia1980_brienza_000.AT2",
      kStandardGravity);
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

}  // namespace
}  // namespace plinth

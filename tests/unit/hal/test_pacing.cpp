// hal/pacing: the clocks, sleeping to absolute deadlines (never early, through signals), the
// Pacer's deadlines (absolute: no drift) and its lateness histogram. Only "not before" checks on
// time: a loaded machine may wake us late, never early.
#include <gtest/gtest.h>
#include <sys/time.h>

#include <csignal>
#include <cstdint>

#include "plinth/hal/pacing.h"

namespace plinth::hal {
namespace {

constexpr std::int64_t kNsPerMs = 1'000'000;

volatile std::sig_atomic_t g_alarm = 0;
extern "C" void on_alarm(int) { g_alarm = 1; }

// SIGALRM after `us` (no SA_RESTART: the sleep sees EINTR); the previous handler back at the end.
class AlarmIn {
 public:
  explicit AlarmIn(long us) {
    g_alarm = 0;
    struct sigaction action {};
    action.sa_handler = on_alarm;
    sigemptyset(&action.sa_mask);
    sigaction(SIGALRM, &action, &previous_);
    itimerval timer{};
    timer.it_value.tv_usec = us;
    setitimer(ITIMER_REAL, &timer, nullptr);
  }
  ~AlarmIn() {
    const itimerval off{};
    setitimer(ITIMER_REAL, &off, nullptr);
    sigaction(SIGALRM, &previous_, nullptr);
  }
  AlarmIn(const AlarmIn&) = delete;
  AlarmIn& operator=(const AlarmIn&) = delete;

 private:
  struct sigaction previous_ {};
};

TEST(Clocks, PositiveAndMonotonicNonDecreasing) {
  EXPECT_GT(realtime_now_ns(), 0);
  std::int64_t previous = monotonic_now_ns();
  EXPECT_GT(previous, 0);
  for (int i = 0; i < 10'000; ++i) {
    const std::int64_t now = monotonic_now_ns();
    ASSERT_GE(now, previous);
    previous = now;
  }
}

TEST(SleepUntil, NeverReturnsBeforeTheDeadline) {
  for (const std::int64_t ahead_ns : {-kNsPerMs, std::int64_t{0}, std::int64_t{1}, 3 * kNsPerMs}) {
    const std::int64_t deadline_ns = monotonic_now_ns() + ahead_ns;
    sleep_until_ns(deadline_ns);
    EXPECT_GE(monotonic_now_ns(), deadline_ns) << ahead_ns;
  }
}

TEST(SleepUntil, ASignalDoesNotEndTheSleepEarly) {
  const std::int64_t deadline_ns = monotonic_now_ns() + 20 * kNsPerMs;
  const AlarmIn alarm(1'000);
  sleep_until_ns(deadline_ns);
  EXPECT_GE(monotonic_now_ns(), deadline_ns);
}

TEST(SleepUntil, StopsOnTheFlag) {
  const volatile std::sig_atomic_t stopped = 1;
  EXPECT_FALSE(sleep_until_ns(monotonic_now_ns() + 3600'000 * kNsPerMs, stopped));

  const volatile std::sig_atomic_t running = 0;
  const std::int64_t deadline_ns = monotonic_now_ns() + kNsPerMs;
  EXPECT_TRUE(sleep_until_ns(deadline_ns, running));
  EXPECT_GE(monotonic_now_ns(), deadline_ns);

  // The signal's handler sets the flag: an hour's sleep ends.
  const AlarmIn alarm(1'000);
  EXPECT_FALSE(sleep_until_ns(monotonic_now_ns() + 3600'000 * kNsPerMs, g_alarm));
}

TEST(Pacer, DeadlinesAreAbsolute) {
  // Tick k's deadline is start + k * period / speed to the ns, however many ticks came before.
  constexpr std::int64_t kPeriodNs = 5 * kNsPerMs;  // 200 Hz
  struct Case {
    double speed;
    std::int64_t tick_ns;  // kPeriodNs / speed
  };
  for (const Case c : {Case{1.0, kPeriodNs}, Case{2.0, kPeriodNs / 2}, Case{4.0, kPeriodNs / 4},
                       Case{0.5, 2 * kPeriodNs}}) {
    Pacer pacer(c.speed);
    pacer.start();
    for (std::int64_t k = 0; k <= 100'000; ++k) {
      ASSERT_EQ(pacer.deadline_ns(k * kPeriodNs), pacer.start_ns() + k * c.tick_ns)
          << "speed " << c.speed << ", tick " << k;
    }
  }
}

TEST(Pacer, ALateWaitDoesNotShiftTheNextDeadlines) {
  Pacer pacer(1.0);
  pacer.start();
  const volatile std::sig_atomic_t running = 0;
  sleep_until_ns(pacer.start_ns() + 3 * kNsPerMs);  // late for the deadline at 1 ms
  ASSERT_TRUE(pacer.wait_until(kNsPerMs, running));
  pacer.record_send();
  EXPECT_EQ(pacer.lateness().count(), 1);
  EXPECT_GE(pacer.lateness().max_us(), 2'000.0);
  ASSERT_TRUE(pacer.wait_until(4 * kNsPerMs, running));
  EXPECT_GE(monotonic_now_ns(), pacer.start_ns() + 4 * kNsPerMs);
  EXPECT_EQ(pacer.deadline_ns(4 * kNsPerMs), pacer.start_ns() + 4 * kNsPerMs);
  EXPECT_GE(pacer.elapsed_s(), 0.004);
}

TEST(Pacer, UnpacedNeverWaitsAndStopWins) {
  const volatile std::sig_atomic_t running = 0;
  const volatile std::sig_atomic_t stopped = 1;
  Pacer unpaced(0.0);
  unpaced.start();
  EXPECT_FALSE(unpaced.paced());
  EXPECT_TRUE(unpaced.wait_until(3600'000 * kNsPerMs, running));
  unpaced.record_send();
  EXPECT_EQ(unpaced.lateness().count(), 0);
  EXPECT_FALSE(unpaced.wait_until(0, stopped));

  Pacer paced(1.0);
  paced.start();
  EXPECT_FALSE(paced.wait_until(3600'000 * kNsPerMs, stopped));
}

TEST(LatenessHistogram, PercentilesToTheBinsLowerEdge) {
  LatenessHistogram histogram;
  EXPECT_EQ(histogram.percentile_us(0.5), 0.0);
  for (std::int64_t us = 0; us < 1000; ++us) histogram.add(us * 1'000 + 500);
  histogram.add(-5);  // clock granularity: counted as 0
  EXPECT_EQ(histogram.count(), 1001);
  EXPECT_EQ(histogram.percentile_us(0.5), 499.0);
  EXPECT_EQ(histogram.max_us(), 999.5);
  // Above 1024 us: bins 0.1 % wide, each value in the bin whose lower edge is at most it.
  for (const std::int64_t us : {1024, 1025, 2047, 2048, 123'456, 9'876'543}) {
    const std::int64_t edge = LatenessHistogram::lower_edge_us(LatenessHistogram::bin_of(us));
    EXPECT_LE(edge, us);
    EXPECT_GT(static_cast<double>(edge), static_cast<double>(us) * 0.999);
  }
}

}  // namespace
}  // namespace plinth::hal

// Clocks, absolute sleeps, the lateness histogram and the pacer.
#include "plinth/hal/pacing.h"

#include <sys/prctl.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <ctime>

namespace plinth::hal {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;
constexpr std::int64_t kNsPerMicrosecond = 1'000;
// Longest single sleep while a stop flag is watched: a stop request that lands just before the
// sleep (not interrupting it) must not wait for the end of a long gap.
constexpr std::int64_t kLongestSleepNs = 100'000'000;
// Never set: sleep_until_ns without a flag.
const volatile std::sig_atomic_t kNeverStop = 0;

std::int64_t now_ns(clockid_t clock) {
  timespec now{};
  clock_gettime(clock, &now);
  return static_cast<std::int64_t>(now.tv_sec) * kNsPerSecond + now.tv_nsec;
}

}  // namespace

std::int64_t monotonic_now_ns() { return now_ns(CLOCK_MONOTONIC); }
std::int64_t realtime_now_ns() { return now_ns(CLOCK_REALTIME); }

void sleep_until_ns(std::int64_t deadline_ns) { (void)sleep_until_ns(deadline_ns, kNeverStop); }

bool sleep_until_ns(std::int64_t deadline_ns, const volatile std::sig_atomic_t& stop) {
  for (;;) {
    if (stop != 0) return false;
    const std::int64_t now = monotonic_now_ns();
    if (now >= deadline_ns) return true;
    const std::int64_t wake_ns = std::min(deadline_ns, now + kLongestSleepNs);
    const timespec wake{static_cast<time_t>(wake_ns / kNsPerSecond),
                        static_cast<long>(wake_ns % kNsPerSecond)};
    // Returns EINTR on a signal: the loop looks at `stop` again.
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr);
  }
}

std::size_t LatenessHistogram::bin_of(std::int64_t us) {
  if (us < kExactUs) return static_cast<std::size_t>(us);
  const auto value = static_cast<std::uint64_t>(us);
  const int exponent = static_cast<int>(std::bit_width(value)) - 1;  // >= 10
  const int shift = exponent - 10;
  return static_cast<std::size_t>(kExactUs) * static_cast<std::size_t>(exponent - 9) +
         static_cast<std::size_t>((value >> shift) - static_cast<std::uint64_t>(kExactUs));
}

std::int64_t LatenessHistogram::lower_edge_us(std::size_t bin) {
  if (bin < static_cast<std::size_t>(kExactUs)) return static_cast<std::int64_t>(bin);
  const std::size_t block = bin / static_cast<std::size_t>(kExactUs);  // exponent - 9
  const std::size_t mantissa = bin % static_cast<std::size_t>(kExactUs);
  const auto shift = static_cast<unsigned>(block - 1);
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(kExactUs) + mantissa) << shift);
}

void LatenessHistogram::add(std::int64_t lateness_ns) {
  // clock_nanosleep never wakes early; a negative value can only be clock granularity.
  const std::int64_t ns = std::max<std::int64_t>(0, lateness_ns);
  const std::size_t bin = bin_of(ns / kNsPerMicrosecond);
  if (bin >= bins_.size()) bins_.resize(bin + 1, 0);
  ++bins_[bin];
  ++count_;
  max_ns_ = std::max(max_ns_, ns);
}

double LatenessHistogram::percentile_us(double fraction) const {
  if (count_ == 0) return 0.0;
  const auto rank = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(std::ceil(fraction * static_cast<double>(count_))));
  std::int64_t seen = 0;
  for (std::size_t bin = 0; bin < bins_.size(); ++bin) {
    seen += bins_[bin];
    if (seen >= rank) return static_cast<double>(lower_edge_us(bin));
  }
  return max_us();
}

double LatenessHistogram::max_us() const {
  return static_cast<double>(max_ns_) / static_cast<double>(kNsPerMicrosecond);
}

Pacer::Pacer(double speed) : speed_(speed) {}

void Pacer::start() {
  // Linux delays a sleeper's wake-up by up to its timer slack (50 us by default) to batch
  // wake-ups; a pacer wants its deadlines.
  if (paced()) prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  start_ns_ = monotonic_now_ns();
  deadline_ns_ = start_ns_;
}

bool Pacer::wait_until(std::int64_t virtual_ns, const volatile std::sig_atomic_t& stop) {
  if (stop != 0) return false;
  if (!paced()) return true;
  deadline_ns_ = deadline_ns(virtual_ns);
  return sleep_until_ns(deadline_ns_, stop);
}

std::int64_t Pacer::deadline_ns(std::int64_t virtual_ns) const {
  return start_ns_ + std::llround(static_cast<double>(virtual_ns) / speed_);
}

void Pacer::record_send() {
  if (paced()) lateness_.add(monotonic_now_ns() - deadline_ns_);
}

double Pacer::elapsed_s() const {
  return static_cast<double>(monotonic_now_ns() - start_ns_) / static_cast<double>(kNsPerSecond);
}

}  // namespace plinth::hal

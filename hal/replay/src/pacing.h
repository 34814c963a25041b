// Sending frames on absolute deadlines, and how late each send was.
#pragma once

#include <csignal>
#include <cstdint>
#include <vector>

namespace plinth::replay {

// Lateness of sends (actual send time minus deadline) in a log-linear histogram of
// microseconds: exact below 1024 us, then 1024 bins per power of two (0.1 % resolution), so a
// long looped replay needs no memory per frame and a late one is still told right.
class LatenessHistogram {
 public:
  void add(std::int64_t lateness_ns);
  [[nodiscard]] std::int64_t count() const { return count_; }
  // Nearest-rank percentile in us (0 < fraction <= 1), to the bin's lower edge; 0 when empty.
  [[nodiscard]] double percentile_us(double fraction) const;
  [[nodiscard]] double max_us() const;

  static constexpr std::int64_t kExactUs = 1024;  // bins below this are 1 us wide
  [[nodiscard]] static std::size_t bin_of(std::int64_t us);
  [[nodiscard]] static std::int64_t lower_edge_us(std::size_t bin);

 private:
  std::vector<std::int64_t> bins_;
  std::int64_t count_ = 0;
  std::int64_t max_ns_ = 0;
};

// Deadlines on CLOCK_MONOTONIC: deadline = start + virtual time / speed, each one absolute
// (clock_nanosleep with TIMER_ABSTIME), so a late frame never delays the ones after it.
class Pacer {
 public:
  // speed: the replay's speed factor (1 = real time); 0 = as fast as possible (no waiting).
  explicit Pacer(double speed);

  // Takes the start time: virtual time 0 is now.
  void start();
  // Sleeps until the deadline of `virtual_ns`. Returns false, early, once `stop` is set (a
  // signal handler sets it; the signal interrupts the sleep).
  [[nodiscard]] bool wait_until(std::int64_t virtual_ns, const volatile std::sig_atomic_t& stop);
  // Records now minus the last deadline (call right before each send). Nothing when unpaced.
  void record_send();

  [[nodiscard]] bool paced() const { return speed_ > 0.0; }
  [[nodiscard]] const LatenessHistogram& lateness() const { return lateness_; }
  // Monotonic time since start(), s.
  [[nodiscard]] double elapsed_s() const;

 private:
  double speed_;
  std::int64_t start_ns_ = 0;
  std::int64_t deadline_ns_ = 0;
  LatenessHistogram lateness_;
};

// CLOCK_MONOTONIC and CLOCK_REALTIME in ns.
[[nodiscard]] std::int64_t monotonic_now_ns();
[[nodiscard]] std::int64_t realtime_now_ns();

}  // namespace plinth::replay

// Clocks in ns, sleeping to absolute deadlines, and a pacer that sends on virtual time: the one
// place the Linux tools (plinth-replay, plinth-monitor, the SocketCAN backend) read clocks.
// Linux only (clock_gettime, clock_nanosleep with TIMER_ABSTIME, prctl).
#pragma once

#include <csignal>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace plinth::hal {

// CLOCK_MONOTONIC and CLOCK_REALTIME in ns.
[[nodiscard]] std::int64_t monotonic_now_ns();
[[nodiscard]] std::int64_t realtime_now_ns();

// Sleeps until `deadline_ns` on CLOCK_MONOTONIC. The deadline is absolute, so a late caller
// does not push the next one back. Never returns before the deadline: a signal (EINTR) resumes
// the sleep.
void sleep_until_ns(std::int64_t deadline_ns);
// The same, but returns false, early, once `stop` is set (a signal handler sets it; the signal
// interrupts the sleep; set just before the sleep, it is seen within 100 ms). True at the
// deadline.
[[nodiscard]] bool sleep_until_ns(std::int64_t deadline_ns,
                                  const volatile std::sig_atomic_t& stop);

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
  // The deadline of `virtual_ns` on CLOCK_MONOTONIC, ns (paced only).
  [[nodiscard]] std::int64_t deadline_ns(std::int64_t virtual_ns) const;
  // CLOCK_MONOTONIC at start(), ns.
  [[nodiscard]] std::int64_t start_ns() const { return start_ns_; }
  // Monotonic time since start(), s.
  [[nodiscard]] double elapsed_s() const;

 private:
  double speed_;
  std::int64_t start_ns_ = 0;
  std::int64_t deadline_ns_ = 0;
  LatenessHistogram lateness_;
};

}  // namespace plinth::hal

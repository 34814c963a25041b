// Long runs of the command-line tools: a progress line on the terminal, and SIGINT/SIGTERM
// asking the run to stop cleanly (plinth-sweep, plinth-eval).
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>

namespace plinth::host {

// Installs SIGINT and SIGTERM handlers that raise the returned flag and print "TOOL: stopping
// after the runs under way (again to quit at once)"; they restore the default action, so a
// second signal ends the program at once. `tool` must outlive the program (a literal).
const std::atomic<bool>* install_stop_handlers(const char* tool);

// "[=======>      ] 12/50 rows  6.1 s, about 19 s left" on one terminal line, redrawn at most
// ten times a second; nothing when stderr is not a terminal. `done` counts resumed items, which
// the time left does not count. `unit` must outlive the bar (a literal).
class ProgressBar {
 public:
  ProgressBar(std::size_t total, std::size_t done, const char* unit);
  void update(std::size_t done) { draw(done, done == total_); }
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  void draw(std::size_t done, bool force);

  bool enabled_;
  std::size_t total_;
  std::size_t resumed_;
  const char* unit_;
  Clock::time_point start_;
  Clock::time_point last_{};
  bool drawn_ = false;
};

}  // namespace plinth::host

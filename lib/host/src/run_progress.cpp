#include "plinth/host/run_progress.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>

namespace plinth::host {
namespace {

std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler stores to it");
// The message, composed before the handlers are installed (a handler may only write(2)).
char g_stop_message[160] = "";

extern "C" void on_stop_signal(int signal_number) {
  g_stop_requested.store(true);
  (void)!::write(STDERR_FILENO, g_stop_message, std::strlen(g_stop_message));
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigaction(signal_number, &default_action, nullptr);
}

}  // namespace

const std::atomic<bool>* install_stop_handlers(const char* tool) {
  std::snprintf(g_stop_message, sizeof g_stop_message,
                "\n%s: stopping after the runs under way (again to quit at once)\n", tool);
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  return &g_stop_requested;
}

ProgressBar::ProgressBar(std::size_t total, std::size_t done, const char* unit)
    : enabled_(::isatty(STDERR_FILENO) == 1 && total > 0),
      total_(total),
      resumed_(done),
      unit_(unit),
      start_(Clock::now()) {
  draw(done, true);
}

void ProgressBar::finish() {
  if (enabled_ && drawn_) std::fprintf(stderr, "\r%*s\r", 79, "");
}

void ProgressBar::draw(std::size_t done, bool force) {
  if (!enabled_) return;
  const auto now = Clock::now();
  if (!force && drawn_ && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  drawn_ = true;
  constexpr std::size_t kWidth = 28;
  const std::size_t filled = kWidth * done / total_;
  char bar[kWidth + 1];
  for (std::size_t k = 0; k < kWidth; ++k) bar[k] = k < filled ? '=' : k == filled ? '>' : ' ';
  bar[kWidth] = '\0';
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const std::size_t run = done - resumed_;
  char left[48] = "";
  if (run > 0 && done < total_) {
    std::snprintf(left, sizeof left, ", about %.0f s left",
                  elapsed / static_cast<double>(run) * static_cast<double>(total_ - done));
  }
  std::fprintf(stderr, "\r[%s] %zu/%zu %s  %.1f s%s   ", bar, done, total_, unit_, elapsed, left);
  std::fflush(stderr);
}

}  // namespace plinth::host

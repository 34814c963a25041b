// What plinth-monitor's outputs say on stderr about what others sent them: the text made
// printable (a payload cannot forge a journal line) and the lines bounded in a burst
// (docs/integration.md, "What each surface trusts"). Host code: allocates.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace plinth::firmware {

// `text` as one line of printable ASCII: bytes 0x20-0x7E as they are (a backslash doubled),
// every other byte (newline, ESC, DEL, each byte of UTF-8, valid or not) as \xNN; at most
// `max_bytes` of `text`, then "... (N bytes)".
[[nodiscard]] std::string printable(std::string_view text, std::size_t max_bytes = 200);

// Whether `text` is well-formed UTF-8 (RFC 3629: no overlong form, no surrogate, <= U+10FFFF).
[[nodiscard]] bool valid_utf8(std::string_view text);

// stderr lines about one kind of event from outside ("plinth-monitor: PREFIX: ..."), at most
// `burst` of them each `period_s`; those beyond are counted, and the next line printed says how
// many were not. Not thread-safe: one per thread.
class LogLimiter {
 public:
  LogLimiter(std::string prefix, int burst, double period_s);

  // Prints "plinth-monitor: PREFIX: MESSAGE" unless the burst is spent; `now_ns` on one
  // monotonic clock. True when printed.
  bool say(const std::string& message, std::int64_t now_ns);
  [[nodiscard]] std::uint64_t not_shown() const { return not_shown_total_; }

 private:
  std::string prefix_;
  int burst_;
  std::int64_t period_ns_;
  std::int64_t window_start_ns_ = 0;
  int said_in_window_ = 0;
  bool started_ = false;
  std::uint64_t not_shown_ = 0;        // since the last line printed
  std::uint64_t not_shown_total_ = 0;  // in the run
};

}  // namespace plinth::firmware

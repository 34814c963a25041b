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

// At most `burst` lines each `period_s` about one kind of event from outside; those beyond are
// counted, for the next line shown to say how many were not. Not thread-safe: one per thread.
class BurstLimit {
 public:
  BurstLimit(int burst, double period_s);
  // Whether a line at `now_ns` (one monotonic clock) may be shown; counted when not.
  [[nodiscard]] bool allow(std::int64_t now_ns);
  // Lines not shown since the last call (the next line shown says so).
  [[nodiscard]] std::uint64_t take_not_shown();
  [[nodiscard]] std::uint64_t not_shown_total() const { return not_shown_total_; }

 private:
  int burst_;
  std::int64_t period_ns_;
  std::int64_t window_start_ns_ = 0;
  int shown_in_window_ = 0;
  bool started_ = false;
  std::uint64_t not_shown_ = 0;
  std::uint64_t not_shown_total_ = 0;
};

// stderr lines "plinth-monitor: PREFIX: MESSAGE" under a BurstLimit; the first line after some
// were not shown says how many. MESSAGE must be printable (printable() the outside's text).
class LogLimiter {
 public:
  LogLimiter(std::string prefix, int burst, double period_s);
  // True when printed.
  bool say(const std::string& message, std::int64_t now_ns);
  [[nodiscard]] std::uint64_t not_shown() const { return limit_.not_shown_total(); }

 private:
  std::string prefix_;
  BurstLimit limit_;
};

}  // namespace plinth::firmware

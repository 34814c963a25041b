#include "log_text.h"

#include <cstdio>
#include <utility>

namespace plinth::firmware {

std::string printable(std::string_view text, std::size_t max_bytes) {
  std::string out;
  const std::size_t shown = text.size() < max_bytes ? text.size() : max_bytes;
  out.reserve(shown + 16);
  for (std::size_t i = 0; i < shown; ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte == '\\') {
      out += "\\\\";
    } else if (byte >= 0x20 && byte <= 0x7E) {
      out += static_cast<char>(byte);
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", byte);
      out += escaped;
    }
  }
  if (shown < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

bool valid_utf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto lead = static_cast<unsigned char>(text[i]);
    std::size_t extra = 0;
    std::uint32_t code = 0;
    std::uint32_t least = 0;  // the smallest code point of this length (no overlong form)
    if (lead < 0x80) {
      ++i;
      continue;
    } else if ((lead & 0xE0) == 0xC0) {
      extra = 1, code = lead & 0x1Fu, least = 0x80;
    } else if ((lead & 0xF0) == 0xE0) {
      extra = 2, code = lead & 0x0Fu, least = 0x800;
    } else if ((lead & 0xF8) == 0xF0) {
      extra = 3, code = lead & 0x07u, least = 0x10000;
    } else {
      return false;
    }
    if (i + extra >= text.size()) return false;
    for (std::size_t k = 1; k <= extra; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xC0) != 0x80) return false;
      code = code << 6 | (next & 0x3Fu);
    }
    if (code < least || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return false;
    i += extra + 1;
  }
  return true;
}

BurstLimit::BurstLimit(int burst, double period_s)
    : burst_(burst), period_ns_(static_cast<std::int64_t>(period_s * 1e9)) {}

bool BurstLimit::allow(std::int64_t now_ns) {
  if (!started_ || now_ns - window_start_ns_ >= period_ns_) {
    started_ = true;
    window_start_ns_ = now_ns;
    shown_in_window_ = 0;
  }
  if (shown_in_window_ >= burst_) {
    ++not_shown_;
    ++not_shown_total_;
    return false;
  }
  ++shown_in_window_;
  return true;
}

std::uint64_t BurstLimit::take_not_shown() {
  const std::uint64_t n = not_shown_;
  not_shown_ = 0;
  return n;
}

LogLimiter::LogLimiter(std::string prefix, int burst, double period_s)
    : prefix_(std::move(prefix)), limit_(burst, period_s) {}

bool LogLimiter::say(const std::string& message, std::int64_t now_ns) {
  if (!limit_.allow(now_ns)) return false;
  const std::uint64_t not_shown = limit_.take_not_shown();
  if (not_shown > 0) {
    std::fprintf(stderr, "plinth-monitor: %s: %s (%llu like it not shown before this one)\n",
                 prefix_.c_str(), message.c_str(), static_cast<unsigned long long>(not_shown));
  } else {
    std::fprintf(stderr, "plinth-monitor: %s: %s\n", prefix_.c_str(), message.c_str());
  }
  return true;
}

}  // namespace plinth::firmware

// printf into a std::string, for plinth-commission's messages (at most 511 characters).
#pragma once

#include <cstdarg>
#include <cstdio>
#include <string>

namespace plinth::firmware {

[[gnu::format(printf, 1, 2)]] inline std::string format_text(const char* pattern, ...) {
  char text[512];
  std::va_list args;
  va_start(args, pattern);
  std::vsnprintf(text, sizeof text, pattern, args);
  va_end(args);
  return text;
}

}  // namespace plinth::firmware

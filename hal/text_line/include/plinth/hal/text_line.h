// A line of text in a fixed buffer: characters, strings, integers in decimal (optionally
// zero-padded, or as a fixed-point fraction) and hex digits. For targets without stdio (newlib's
// printf allocates); once anything does not fit, the line is marked failed and stays as it was.
#pragma once

#include <cstddef>
#include <cstdint>

namespace plinth::hal {

class TextLine {
 public:
  // `buffer` holds `capacity` bytes, the terminating NUL included.
  TextLine(char* buffer, std::size_t capacity) : buffer_(buffer), capacity_(capacity) {
    if (capacity_ > 0) buffer_[0] = '\0';
  }

  TextLine& put(char c);
  TextLine& put(const char* text);
  // `value` in decimal, at least `width` digits (zero-padded).
  TextLine& decimal(std::uint64_t value, int width = 1);
  TextLine& decimal(std::int64_t value);
  // value / 10^decimals with `decimals` digits after the point, e.g. (-12345, 3) -> "-12.345".
  TextLine& fixed(std::int64_t value, int decimals);
  // The low `digits` hex digits of `value`, uppercase.
  TextLine& hex(std::uint32_t value, int digits);

  [[nodiscard]] bool failed() const { return failed_; }
  [[nodiscard]] std::size_t length() const { return length_; }
  [[nodiscard]] const char* c_str() const { return buffer_; }

 private:
  char* buffer_;
  std::size_t capacity_;
  std::size_t length_ = 0;
  bool failed_ = false;
};

}  // namespace plinth::hal

#include "plinth/hal/text_line.h"

namespace plinth::hal {

TextLine& TextLine::put(char c) {
  if (failed_ || length_ + 1 >= capacity_) {
    failed_ = true;
    return *this;
  }
  buffer_[length_++] = c;
  buffer_[length_] = '\0';
  return *this;
}

TextLine& TextLine::put(const char* text) {
  while (*text != '\0') put(*text++);
  return *this;
}

TextLine& TextLine::decimal(std::uint64_t value, int width) {
  char digits[20];
  int n = 0;
  do {
    digits[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0);
  for (int i = n; i < width; ++i) put('0');
  while (n > 0) put(digits[--n]);
  return *this;
}

TextLine& TextLine::decimal(std::int64_t value) {
  if (value < 0) put('-');
  // The magnitude of INT64_MIN does not fit an int64: negate in unsigned arithmetic.
  const std::uint64_t magnitude =
      value < 0 ? ~static_cast<std::uint64_t>(value) + 1 : static_cast<std::uint64_t>(value);
  return decimal(magnitude);
}

TextLine& TextLine::fixed(std::int64_t value, int decimals) {
  std::uint64_t scale = 1;
  for (int i = 0; i < decimals; ++i) scale *= 10;
  if (value < 0) put('-');
  const std::uint64_t magnitude =
      value < 0 ? ~static_cast<std::uint64_t>(value) + 1 : static_cast<std::uint64_t>(value);
  decimal(magnitude / scale);
  if (decimals > 0) put('.').decimal(magnitude % scale, decimals);
  return *this;
}

TextLine& TextLine::hex(std::uint32_t value, int digits) {
  static constexpr char kHexDigits[] = "0123456789ABCDEF";
  for (int i = digits - 1; i >= 0; --i) put(kHexDigits[(value >> (4 * i)) & 0xF]);
  return *this;
}

}  // namespace plinth::hal

#include "plinth/hal/candump_format.h"

namespace plinth::hal {
namespace {

constexpr char kHexDigits[] = "0123456789ABCDEF";

// Appends to a fixed buffer; `failed` once anything did not fit (the NUL included).
struct LineWriter {
  char* out;
  std::size_t capacity;
  std::size_t length = 0;
  bool failed = false;

  void put(char c) {
    if (length + 1 >= capacity) {
      failed = true;
      return;
    }
    out[length++] = c;
  }
  // `value` in decimal, at least `width` digits (zero-padded).
  void decimal(std::uint64_t value, int width) {
    char digits[20];
    int n = 0;
    do {
      digits[n++] = static_cast<char>('0' + value % 10);
      value /= 10;
    } while (value != 0);
    for (int i = n; i < width; ++i) put('0');
    while (n > 0) put(digits[--n]);
  }
  // The low `digits` hex digits of `value`.
  void hex(std::uint32_t value, int digits) {
    for (int i = digits - 1; i >= 0; --i) put(kHexDigits[(value >> (4 * i)) & 0xF]);
  }
};

}  // namespace

std::size_t format_candump_line(char* out, std::size_t capacity, std::int64_t timestamp_ns,
                                const char* interface_name, const can::CanFrame& frame) {
  if (capacity == 0) return 0;
  out[0] = '\0';
  std::size_t name_length = 0;
  while (interface_name[name_length] != '\0' && name_length <= kCandumpMaxInterfaceLength) {
    ++name_length;
  }
  if (timestamp_ns < 0 || name_length == 0 || name_length > kCandumpMaxInterfaceLength) return 0;
  const auto micros = static_cast<std::uint64_t>(timestamp_ns) / 1000;
  LineWriter w{out, capacity};
  w.put('(');
  w.decimal(micros / 1'000'000, 10);
  w.put('.');
  w.decimal(micros % 1'000'000, 6);
  w.put(')');
  w.put(' ');
  for (std::size_t i = 0; i < name_length; ++i) w.put(interface_name[i]);
  w.put(' ');
  w.hex(frame.id, 3);
  w.put('#');
  const std::size_t length = frame.length <= 8 ? frame.length : 8;
  for (std::size_t i = 0; i < length; ++i) w.hex(frame.data[i], 2);
  if (w.failed) {
    out[0] = '\0';
    return 0;
  }
  out[w.length] = '\0';
  return w.length;
}

}  // namespace plinth::hal

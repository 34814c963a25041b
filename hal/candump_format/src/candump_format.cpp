#include "plinth/hal/candump_format.h"

#include "plinth/hal/text_line.h"

namespace plinth::hal {
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
  TextLine line(out, capacity);
  line.put('(').decimal(micros / 1'000'000, 10).put('.').decimal(micros % 1'000'000, 6);
  line.put(") ").put(interface_name).put(' ').hex(frame.id, 3).put('#');
  const std::size_t length = frame.length <= 8 ? frame.length : 8;
  for (std::size_t i = 0; i < length; ++i) line.hex(frame.data[i], 2);
  if (line.failed()) {
    out[0] = '\0';
    return 0;
  }
  return line.length();
}

}  // namespace plinth::hal

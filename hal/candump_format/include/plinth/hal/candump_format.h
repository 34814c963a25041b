// One line of a candump log (can-utils' `candump -l`, read by `canplayer -I`), written into a
// caller's buffer: no heap, no stdio. plinth/hal/candump_log.h (host) reads and writes whole
// log files with it; the microcontroller's semihosting CAN stand-in prints its frames with it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "plinth/hal/can_codec.h"

namespace plinth::hal {

inline constexpr std::size_t kCandumpMaxInterfaceLength = 15;  // IFNAMSIZ - 1
// Room for the longest classic line and its NUL: "(" 19 digits "." 6 ") " 15 " " 3 "#" 16.
inline constexpr std::size_t kCandumpLineCapacity = 72;

// Writes the log line of a classic frame with a standard identifier, as candump -l writes it
// (uppercase hex, at least ten digits of seconds, no newline), NUL-terminated, e.g.
// "(1700000000.123456) vcan0 301#0011223344556677". The timestamp (ns) is truncated to whole
// microseconds. Returns the line's length; 0 (and an empty string when capacity > 0) when the
// timestamp is negative, the interface name is empty or longer than 15 characters, or the line
// does not fit in `capacity` bytes. A length above 8 is written as 8 bytes.
std::size_t format_candump_line(char* out, std::size_t capacity, std::int64_t timestamp_ns,
                                const char* interface_name, const can::CanFrame& frame);

}  // namespace plinth::hal

// libFuzzer target: candump log lines, hal/candump_log (parse_candump_line, which the log reader
// applies to every line). Thin on purpose: the reader's API is being reworked.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.h"
#include "plinth/hal/candump_log.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using plinth::fuzz::check;
  namespace hal = plinth::hal;
  std::string_view text = plinth::fuzz::as_text(data, size);
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
    hal::CandumpLine parsed;
    if (!hal::parse_candump_line(line, parsed).empty()) continue;
    check(parsed.timestamp_ns >= 0 && parsed.timestamp_ns % 1000 == 0, "timestamp in whole us");
    check(parsed.length <= hal::kCandumpMaxFdLength, "length at most 64");
    if (parsed.kind == hal::CandumpFrameKind::kDropCount) {
      // A socket name as candump wrote it (the interface, or its command-line argument).
      check(parsed.dropped_frames >= 1 && !parsed.interface_name.empty() &&
                parsed.interface_name.find('\'') == std::string::npos,
            "DROPCOUNT: frames lost, a socket name");
      continue;
    }
    check(parsed.interface_name.size() <= hal::kCandumpMaxInterfaceLength, "interface name");
    if (parsed.kind == hal::CandumpFrameKind::kClassic) {
      check(parsed.id <= hal::kStandardIdMask && parsed.length <= 8, "classic frame");
    }
    check(parsed.id <= hal::kExtendedIdMask, "identifier within 29 bits");
  }
  return 0;
}

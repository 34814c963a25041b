// libFuzzer target: the box's configuration loader (TOML), firmware/linux/monitor_config.cpp.
// A configuration it returns must pass validate(), as its header promises.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "monitor_config.h"
#include "plinth/host/input_error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using plinth::fuzz::check;
  const std::string text(plinth::fuzz::as_text(data, size));
  try {
    const plinth::firmware::MonitorFile file = plinth::firmware::load_monitor_text(
        text, "/etc/plinth/fuzz.toml", plinth::firmware::MonitorConfig{});
    check(plinth::firmware::validate(file.config).ok(), "a loaded configuration validates");
  } catch (const plinth::host::InputError& error) {
    check(std::string(error.what()).starts_with("/etc/plinth/fuzz.toml"), "message names the file");
  }
  return 0;
}

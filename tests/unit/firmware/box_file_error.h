#pragma once
// The message a box file's text is refused with (firmware/linux/monitor_config.h), "" when it
// is accepted; `path` is the name the messages give the file.
#include <string>

#include "monitor_config.h"
#include "plinth/host/input_error.h"

namespace plinth::testing {

inline std::string box_file_error(const std::string& text,
                                  const std::string& path = "/etc/plinth/box.toml") {
  try {
    (void)firmware::load_monitor_text(text, path, firmware::MonitorConfig{});
  } catch (const host::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace plinth::testing

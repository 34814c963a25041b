// The box's configuration file (TOML): the tunables of plinth::firmware::MonitorConfig under
// the names its validation reports (docs/monitor.md, "Configuration file"). Host code: may
// allocate and throw.
#pragma once

#include <string>

#include "plinth/firmware/monitor.h"

namespace plinth::firmware {

struct MonitorFile {
  MonitorConfig config;
  std::string second_scene_path;  // monitor.second_scene, resolved against the file's folder
};

// Reads `path` over `defaults`. Throws host::InputError naming the file, the line and the key
// for: a missing file, TOML syntax, unknown tables or keys, wrong types, and every value that
// validate(MonitorConfig) refuses (its field is the file's key).
[[nodiscard]] MonitorFile load_monitor_file(const std::string& path, const MonitorConfig& defaults);

// The same from text; `origin` names it in messages and resolves relative paths.
[[nodiscard]] MonitorFile load_monitor_text(const std::string& text, const std::string& origin,
                                            const MonitorConfig& defaults);

}  // namespace plinth::firmware

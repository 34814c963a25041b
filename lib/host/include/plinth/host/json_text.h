// Text in the tools' JSON output (plinth-monitor's lines, plinth-eval's report).
#pragma once

#include <string>
#include <string_view>

namespace plinth::host {

// `text` as a JSON string: quoted, with '"' and '\' escaped and control characters as \u00XX.
[[nodiscard]] std::string json_quoted(std::string_view text);

}  // namespace plinth::host

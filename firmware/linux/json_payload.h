// A JSON message from outside the box (an MQTT command, a regional alert), read strictly: one
// JSON value of at most kMaxJsonPayloadBytes, no member twice in one object (JSON leaves a
// repeated name's meaning open: a filter that reads the first and a box that keeps the last
// would see two messages in one). Host code: allocates.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace plinth::firmware {

inline constexpr std::size_t kMaxJsonPayloadBytes = 4096;

struct JsonPayload {
  nlohmann::json value;  // when `problem` is empty
  std::string problem;   // "not JSON", "longer than 4096 bytes", "member \"x\" given twice"
};

[[nodiscard]] JsonPayload parse_json_payload(std::string_view text);

}  // namespace plinth::firmware

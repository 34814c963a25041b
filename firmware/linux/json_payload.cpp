#include "json_payload.h"

#include <set>
#include <vector>

#include "log_text.h"

namespace plinth::firmware {

JsonPayload parse_json_payload(std::string_view text) {
  JsonPayload out;
  if (text.size() > kMaxJsonPayloadBytes) {
    out.problem = "longer than " + std::to_string(kMaxJsonPayloadBytes) + " bytes (" +
                  std::to_string(text.size()) + ")";
    return out;
  }
  // The members of each object open at this point of the parse.
  std::vector<std::set<std::string>> open;
  std::string repeated;
  const nlohmann::json::parser_callback_t each = [&](int, nlohmann::json::parse_event_t event,
                                                     nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start) {
      open.emplace_back();
    } else if (event == Event::object_end && !open.empty()) {
      open.pop_back();
    } else if (event == Event::key && !open.empty() &&
               !open.back().insert(parsed.get<std::string>()).second && repeated.empty()) {
      repeated = parsed.get<std::string>();
    }
    return true;
  };
  out.value = nlohmann::json::parse(text.begin(), text.end(), each, false);
  if (out.value.is_discarded()) {
    out.problem = "not JSON";
  } else if (!repeated.empty()) {
    out.problem = "member \"" + printable(repeated, 64) + "\" given twice";
  }
  return out;
}

}  // namespace plinth::firmware

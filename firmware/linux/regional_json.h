// A regional alert as the bridge publishes it on MQTT (docs/regional.md, "MQTT"): a JSON object
// whose times are UTC (s since the Unix epoch), read into the regional room's RegionalAlert with
// its times relative to the receipt. Host code: allocates.
#pragma once

#include <cstdint>
#include <string>

#include "plinth/monitor/regional_alert.h"

namespace plinth::firmware {

// The members: event_id (integer 0 .. 2^32-1), version (integer 0 .. 255), magnitude,
// origin_time (UTC s), distance_km, pga_g, sigma_ln, s_arrival_time (UTC s), all required;
// cancelled (true or false) optional. Nothing else.
struct RegionalJson {
  bool ok = false;
  monitor::RegionalAlert alert;  // when ok: times relative to `now_utc_ns`
  // When not ok: the member at fault (a string literal: the room keeps the pointer) and why.
  const char* field = "";
  std::string problem;
};

// Reads `payload` received at `now_utc_ns` (CLOCK_REALTIME). Values are checked by the room
// (ranges, future-dated, stale); this refuses what is not an alert at all: not JSON, not an
// object, a member missing, of the wrong type, unknown or given twice (json_payload.h).
[[nodiscard]] RegionalJson parse_regional_json(const std::string& payload,
                                               std::int64_t now_utc_ns);

}  // namespace plinth::firmware

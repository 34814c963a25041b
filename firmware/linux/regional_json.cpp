#include "regional_json.h"

#include <array>
#include <cmath>
#include <limits>

#include "json_payload.h"
#include "log_text.h"

namespace plinth::firmware {

namespace {

constexpr std::array<const char*, 9> kMembers{"event_id",   "version", "cancelled",
                                              "magnitude",  "origin_time", "distance_km",
                                              "pga_g",      "sigma_ln", "s_arrival_time"};

RegionalJson refused(const char* field, std::string problem) {
  RegionalJson out;
  out.field = field;
  out.problem = std::move(problem);
  return out;
}

}  // namespace

RegionalJson parse_regional_json(const std::string& payload, std::int64_t now_utc_ns) {
  const JsonPayload parsed = parse_json_payload(payload);
  if (!parsed.problem.empty()) return refused("payload", parsed.problem);
  const nlohmann::json& j = parsed.value;
  if (!j.is_object()) return refused("payload", "expected a JSON object");
  for (const auto& [key, value] : j.items()) {
    bool known = false;
    for (const char* m : kMembers) known = known || key == m;
    if (!known) return refused("payload", "unknown member \"" + printable(key, 64) + "\"");
  }
  RegionalJson out;
  const auto integer = [&](const char* name, std::uint64_t max, std::uint64_t& value) {
    if (!j.contains(name)) {
      out = refused(name, std::string(name) + ": missing");
      return false;
    }
    const nlohmann::json& v = j[name];
    if (!v.is_number_unsigned() || v.get<std::uint64_t>() > max) {
      out = refused(name, std::string(name) + ": expected an integer from 0 to " +
                              std::to_string(max));
      return false;
    }
    value = v.get<std::uint64_t>();
    return true;
  };
  // Numbers: JSON has no NaN; the room checks the ranges.
  const auto number = [&](const char* name, double& value) {
    if (!j.contains(name)) {
      out = refused(name, std::string(name) + ": missing");
      return false;
    }
    const nlohmann::json& v = j[name];
    if (!v.is_number()) {
      out = refused(name, std::string(name) + ": expected a number");
      return false;
    }
    value = v.get<double>();
    return true;
  };
  std::uint64_t id = 0;
  std::uint64_t version = 0;
  double magnitude = 0, origin = 0, distance = 0, pga = 0, sigma = 0, arrival = 0;
  if (!integer("event_id", std::numeric_limits<std::uint32_t>::max(), id) ||
      !integer("version", monitor::kMaxRegionalVersion, version) ||
      !number("magnitude", magnitude) || !number("origin_time", origin) ||
      !number("distance_km", distance) || !number("pga_g", pga) ||
      !number("sigma_ln", sigma) || !number("s_arrival_time", arrival)) {
    return out;
  }
  bool cancelled = false;
  if (j.contains("cancelled")) {
    if (!j["cancelled"].is_boolean()) {
      return refused("cancelled", "cancelled: expected true or false");
    }
    cancelled = j["cancelled"].get<bool>();
  }
  const double now_s = static_cast<double>(now_utc_ns) * 1e-9;
  out.ok = true;
  out.alert.event_id = static_cast<std::uint32_t>(id);
  out.alert.version = static_cast<std::uint32_t>(version);
  out.alert.cancelled = cancelled;
  out.alert.magnitude = magnitude;
  out.alert.distance_km = distance;
  out.alert.origin_age_s = now_s - origin;
  out.alert.pga_g = pga;
  out.alert.sigma_ln = sigma;
  out.alert.s_arrival_in_s = arrival - now_s;
  return out;
}

}  // namespace plinth::firmware

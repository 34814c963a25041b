#include "monitor_config.h"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/text_file.h"
#include "plinth/host/toml_names.h"
#include "address_prefix.h"
#include "log_text.h"
#include "status_outputs.h"

namespace plinth::firmware {

namespace {

using host::InputError;

// Concatenation by appending (GCC 12 warns falsely on `"literal" + std::string`).
template <typename... Parts>
std::string cat(const Parts&... parts) {
  std::string out;
  (out.append(parts), ...);
  return out;
}

// One key of the file: its dotted name (the same as the Error field validate() reports) and
// how to store its node.
struct Binding {
  std::string key;
  std::function<bool(const toml::node&)> store;  // false: wrong type
  const char* expected;                          // "a number", ...
};

std::function<bool(const toml::node&)> number_into(double& target) {
  return [&target](const toml::node& n) {
    if (!n.is_number()) return false;
    target = n.value<double>().value_or(0.0);
    return true;
  };
}

std::function<bool(const toml::node&)> integer_into(int& target) {
  return [&target](const toml::node& n) {
    if (!n.is_integer()) return false;
    const std::int64_t v = n.value<std::int64_t>().value_or(0);
    if (v < -1'000'000'000 || v > 1'000'000'000) return false;
    target = static_cast<int>(v);
    return true;
  };
}

// A count or size: an integer from 0 to 2^53.
std::function<bool(const toml::node&)> count_into(std::uint64_t& target) {
  return [&target](const toml::node& n) {
    if (!n.is_integer()) return false;
    const std::int64_t v = n.value<std::int64_t>().value_or(-1);
    if (v < 0 || v > (std::int64_t{1} << 53)) return false;
    target = static_cast<std::uint64_t>(v);
    return true;
  };
}

std::function<bool(const toml::node&)> flag_into(bool& target) {
  return [&target](const toml::node& n) {
    if (!n.is_boolean()) return false;
    target = n.value<bool>().value_or(false);
    return true;
  };
}

std::function<bool(const toml::node&)> string_into(std::string& target) {
  return [&target](const toml::node& n) {
    if (!n.is_string()) return false;
    target = n.value<std::string>().value_or("");
    return true;
  };
}

// An array of strings (possibly empty).
std::function<bool(const toml::node&)> strings_into(std::vector<std::string>& target) {
  return [&target](const toml::node& n) {
    const toml::array* items = n.as_array();
    if (items == nullptr) return false;
    std::vector<std::string> values;
    for (const toml::node& item : *items) {
      if (!item.is_string()) return false;
      values.push_back(item.value<std::string>().value_or(""));
    }
    target = std::move(values);
    return true;
  };
}

// A stepper's name (steppers.h: stepper_name).
std::function<bool(const toml::node&)> stepper_into(Stepper& target) {
  return [&target](const toml::node& n) {
    return n.is_string() && parse_stepper(n.value<std::string>().value_or(""), target);
  };
}

std::function<bool(const toml::node&)> continuation_into(Continuation& target) {
  return [&target](const toml::node& n) {
    return n.is_string() && kContinuationNames.parse(n.value<std::string>().value_or(""), target);
  };
}

std::function<bool(const toml::node&)> rotation_into(Eigen::Matrix3d& target) {
  return [&target](const toml::node& n) {
    const toml::array* rows = n.as_array();
    if (rows == nullptr || rows->size() != 3) return false;
    for (std::size_t i = 0; i < 3; ++i) {
      const toml::array* row = (*rows)[i].as_array();
      if (row == nullptr || row->size() != 3) return false;
      for (std::size_t j = 0; j < 3; ++j) {
        if (!(*row)[j].is_number()) return false;
        target(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
            (*row)[j].value<double>().value_or(0.0);
      }
    }
    return true;
  };
}

constexpr const char* kRotationExpected = "three rows of three numbers (statue = R sensor)";

// The keys of a sensor's conditioning and health. `mounting` prefixes unit, sensor_to_statue
// and rotation_tolerance ("conditioning." at the top, "" in a [[sensor]] table); `prefix` the
// others ("" at the top, the table's keys then start with conditioning. / sensor_health.).
void sensor_bindings(std::vector<Binding>& b, const std::string& mounting,
                     monitor::ConditioningSettings& cond, monitor::SensorHealthSettings& health,
                     std::string& unit) {
  b.push_back({cat(mounting, "unit"), string_into(unit), "a string, \"g\" or \"m/s2\""});
  b.push_back({cat(mounting, "sensor_to_statue"), rotation_into(cond.sensor_to_statue),
               kRotationExpected});
  b.push_back({cat(mounting, "rotation_tolerance"), number_into(cond.rotation_tolerance),
               "a number"});
  const std::pair<const char*, double*> numbers[] = {
      {"conditioning.startup_window_s", &cond.startup_window_s},
      {"conditioning.startup_max_std_m_s2", &cond.startup_max_std_m_s2},
      {"conditioning.startup_max_offset_m_s2", &cond.startup_max_offset_m_s2},
      {"conditioning.startup_max_drift_m_s2", &cond.startup_max_drift_m_s2},
      {"conditioning.startup_gravity_tolerance_m_s2", &cond.startup_gravity_tolerance_m_s2},
      {"conditioning.tracking_time_constant_s", &cond.tracking_time_constant_s},
      {"conditioning.tracking_gate_m_s2", &cond.tracking_gate_m_s2},
      {"sensor_health.timeout_s", &health.timeout_s},
      {"sensor_health.full_scale_g", &health.full_scale_g},
      {"sensor_health.max_valid_g", &health.max_valid_g},
  };
  for (const auto& [key, target] : numbers) b.push_back({key, number_into(*target), "a number"});
  const std::pair<const char*, int*> integers[] = {
      {"sensor_health.max_bridge_samples", &health.max_bridge_samples},
      {"sensor_health.recovery_samples", &health.recovery_samples},
      {"sensor_health.stuck_samples", &health.stuck_samples},
  };
  for (const auto& [key, target] : integers) {
    b.push_back({key, integer_into(*target), "an integer"});
  }
}

// [statue_sensor] (its mounting, its streams' health) and [statue_filter] (the gyroscope's noise,
// the weighing of the members, the accelerometer's sliding test, the corroboration): statue_sensor.h,
// statue_filter.h. The table's presence configures the sensor (load_monitor_text).
void statue_bindings(std::vector<Binding>& b, StatueSensorSettings& statue, int& node) {
  b.push_back({"statue_sensor.node", integer_into(node), "an integer"});
  b.push_back({"statue_sensor.sensor_to_statue", rotation_into(statue.sensor_to_statue),
               kRotationExpected});
  StatueSensorHealthSettings& h = statue.health;
  StatueFilterSettings& f = statue.filter;
  const std::pair<const char*, double*> numbers[] = {
      {"statue_sensor.height_m", &statue.height_m},
      {"statue_sensor.offset_x_m", &statue.offset_x_m},
      {"statue_sensor.offset_y_m", &statue.offset_y_m},
      {"statue_sensor.offset_window_s", &statue.offset_window_s},
      {"statue_sensor.max_age_s", &statue.max_age_s},
      {"statue_sensor.health.timeout_s", &h.timeout_s},
      {"statue_sensor.health.rate_full_scale_rad_s", &h.rate_full_scale_rad_s},
      {"statue_sensor.health.rate_max_valid_rad_s", &h.rate_max_valid_rad_s},
      {"statue_sensor.health.acceleration_full_scale_g", &h.acceleration_full_scale_g},
      {"statue_sensor.health.acceleration_max_valid_g", &h.acceleration_max_valid_g},
      {"statue_filter.rate_noise_rad_s", &f.rate_noise_rad_s},
      {"statue_filter.model_tolerance", &f.model_tolerance},
      {"statue_filter.rest_rate_rad_s", &f.rest_rate_rad_s},
      {"statue_filter.rest_tilt_rad", &f.rest_tilt_rad},
      {"statue_filter.rest_time_s", &f.rest_time_s},
      {"statue_filter.interval_s", &f.interval_s},
      {"statue_filter.memory_s", &f.memory_s},
      {"statue_filter.score_memory_s", &f.score_memory_s},
      {"statue_filter.informative_fraction", &f.informative_fraction},
      {"statue_filter.credible_weight", &f.credible_weight},
      {"statue_filter.unexplained_score", &f.unexplained_score},
      {"statue_filter.ruled_out_fraction", &f.ruled_out_fraction},
      {"statue_filter.acceleration_noise_m_s2", &f.acceleration_noise_m_s2},
      {"statue_filter.acceleration_bias_m_s2", &f.acceleration_bias_m_s2},
      {"statue_filter.slide_tolerance", &f.slide_tolerance},
      {"statue_filter.slide_filter_s", &f.slide_filter_s},
      {"statue_filter.slide_onset_s", &f.slide_onset_s},
      {"statue_filter.slide_end_s", &f.slide_end_s},
      {"statue_filter.follow_tolerance", &f.follow_tolerance},
      {"statue_filter.follow_onset_s", &f.follow_onset_s},
      {"statue_filter.contradiction_rate_rad_s", &f.contradiction_rate_rad_s},
      {"statue_filter.contradiction_s", &f.contradiction_s},
      {"statue_filter.trust_again_s", &f.trust_again_s},
  };
  for (const auto& [key, target] : numbers) b.push_back({key, number_into(*target), "a number"});
  b.push_back({"statue_filter.slide_on_isolated_base", flag_into(f.slide_on_isolated_base),
               "true or false"});
  const std::pair<const char*, int*> integers[] = {
      {"statue_sensor.health.max_bridge_samples", &h.max_bridge_samples},
      {"statue_sensor.health.recovery_samples", &h.recovery_samples},
      {"statue_sensor.health.stuck_samples", &h.stuck_samples},
  };
  for (const auto& [key, target] : integers) {
    b.push_back({key, integer_into(*target), "an integer"});
  }
}

// [relays]: the chip, every line's default polarity, and per relay its offset, either
// `warning = 5` or `warning = { line = 5, active_low = true }`.
void relay_bindings(std::vector<Binding>& b, RelaySettings& relays,
                    std::array<bool, kRelayCount>& active_low) {
  b.push_back({"relays.chip", string_into(relays.chip), "a string (a gpiochip name or path)"});
  b.push_back({"relays.active_low", flag_into(active_low[0]), "true or false"});
  for (std::size_t i = 0; i < kRelayCount; ++i) {
    const std::string key = cat("relays.", kRelayNames[i]);
    b.push_back({key, integer_into(relays.lines[i].offset), "an integer (a line offset)"});
    b.push_back(
        {cat(key, ".line"), integer_into(relays.lines[i].offset), "an integer (a line offset)"});
    b.push_back({cat(key, ".active_low"), flag_into(relays.lines[i].active_low), "true or false"});
  }
}

// The outputs' keys ([modbus], [mqtt]; docs/integration.md).
void output_bindings(std::vector<Binding>& b, ModbusSettings& modbus, MqttSettings& mqtt) {
  constexpr const char* kEndpoint = "a string, \"HOST:PORT\"";
  b.push_back({"modbus.listen", string_into(modbus.listen), kEndpoint});
  b.push_back({"modbus.writes", flag_into(modbus.writes), "true or false"});
  b.push_back({"modbus.write_from", strings_into(modbus.write_from),
               "an array of strings (addresses, \"10.0.4.7\" or \"10.0.4.0/24\")"});
  b.push_back({"modbus.max_clients", integer_into(modbus.max_clients), "an integer"});
  b.push_back({"modbus.idle_timeout_s", number_into(modbus.idle_timeout_s), "a number"});
  b.push_back({"mqtt.broker", string_into(mqtt.broker), kEndpoint});
  const std::pair<const char*, std::string*> strings[] = {
      {"mqtt.box_id", &mqtt.box_id},
      {"mqtt.topic_prefix", &mqtt.topic_prefix},
      {"mqtt.username", &mqtt.username},
      {"mqtt.password", &mqtt.password},
      {"mqtt.password_file", &mqtt.password_file},
      {"mqtt.tls_ca_file", &mqtt.ca_file},
      {"mqtt.tls_cert_file", &mqtt.cert_file},
      {"mqtt.tls_key_file", &mqtt.key_file},
  };
  for (const auto& [key, target] : strings) b.push_back({key, string_into(*target), "a string"});
  b.push_back({"mqtt.keepalive_s", integer_into(mqtt.keepalive_s), "an integer"});
  b.push_back({"mqtt.event_queue", integer_into(mqtt.event_queue), "an integer"});
  b.push_back({"mqtt.state_interval_s", number_into(mqtt.state_interval_s), "a number"});
  b.push_back({"mqtt.reconnect_min_s", number_into(mqtt.reconnect_min_s), "a number"});
  b.push_back({"mqtt.reconnect_max_s", number_into(mqtt.reconnect_max_s), "a number"});
  b.push_back({"mqtt.commands", flag_into(mqtt.commands), "true or false"});
  b.push_back({"mqtt.regional_alerts", flag_into(mqtt.regional_alerts), "true or false"});
  b.push_back({"mqtt.regional_topic", string_into(mqtt.regional_topic), "a string (a topic)"});
  b.push_back({"mqtt.discovery", flag_into(mqtt.discovery), "true or false"});
  b.push_back({"mqtt.discovery_prefix", string_into(mqtt.discovery_prefix),
               "a string (topic levels)"});
}

// The [regional_alert] table's keys (a build without regional alerts has none).
void regional_bindings(std::vector<Binding>& b, monitor::RegionalAlertSettings& r) {
  const std::pair<const char*, double*> numbers[] = {
      {"regional_alert.max_origin_age_s", &r.max_origin_age_s},
      {"regional_alert.future_tolerance_s", &r.future_tolerance_s},
      {"regional_alert.expiry_margin_s", &r.expiry_margin_s},
      {"regional_alert.stress_drop_bar", &r.stress_drop_bar},
      {"regional_alert.shear_wave_speed_km_s", &r.shear_wave_speed_km_s},
      {"regional_alert.path_duration_s_per_km", &r.path_duration_s_per_km},
  };
  for (const auto& [key, value] : numbers) b.push_back({key, number_into(*value), "a number"});
}

// A key read apart (read_sensors, read_pwave_predictor), which checks its value's type; its
// binding's `expected` names that type for the messages about keys under it.
std::function<bool(const toml::node&)> read_apart() {
  return [](const toml::node&) { return true; };
}
constexpr const char* kSensorsExpected = "[[sensor]] tables (an array of tables)";
constexpr const char* kPredictorExpected =
    "an array of tables { window_s, ln_pga_over_pa, tau_c_exponent, sigma_ln } (plinth-eval "
    "pwave-fit prints one)";

// The [pwave] table's keys but its predictor (read_pwave_predictor); `channel` its name.
void pwave_bindings(std::vector<Binding>& b, monitor::PWaveSettings& p, std::string& channel) {
  b.push_back({"pwave.channel", string_into(channel), "a string, \"vertical\" or \"horizontal\""});
  b.push_back({"pwave.predictor", read_apart(), kPredictorExpected});
  const std::pair<const char*, double*> numbers[] = {
      {"pwave.highpass_hz", &p.highpass_hz},
      {"pwave.lowpass_hz", &p.lowpass_hz},
      {"pwave.sta_s", &p.sta_s},
      {"pwave.lta_s", &p.lta_s},
      {"pwave.trigger_ratio", &p.trigger_ratio},
      {"pwave.detrigger_ratio", &p.detrigger_ratio},
      {"pwave.noise_floor_m_s2", &p.noise_floor_m_s2},
      {"pwave.min_amplitude_m_s2", &p.min_amplitude_m_s2},
      {"pwave.confirm_s", &p.confirm_s},
      {"pwave.max_retry_s", &p.max_retry_s},
      {"pwave.min_tau_p_s", &p.min_tau_p_s},
      {"pwave.max_tau_c_s", &p.max_tau_c_s},
      {"pwave.min_vertical_ratio", &p.min_vertical_ratio},
      {"pwave.s_wave_ratio", &p.s_wave_ratio},
      {"pwave.max_window_s", &p.max_window_s},
      {"pwave.hold_s", &p.hold_s},
  };
  for (const auto& [key, target] : numbers) b.push_back({key, number_into(*target), "a number"});
}

// [commissioning] (commission_settings.h).
void commissioning_bindings(std::vector<Binding>& b, CommissioningSettings& c) {
  b.push_back({"commissioning.required", flag_into(c.required), "true or false"});
  b.push_back({"commissioning.report", string_into(c.report), "a string (a report's path)"});
  b.push_back({"commissioning.override", string_into(c.override_reason), "a string (the reason)"});
  const std::pair<const char*, double*> numbers[] = {
      {"commissioning.wedge_deg", &c.wedge_deg},
      {"commissioning.wedge_tolerance_deg", &c.wedge_tolerance_deg},
      {"commissioning.heading_tolerance_deg", &c.heading_tolerance_deg},
      {"commissioning.gravity_tolerance", &c.gravity_tolerance},
      {"commissioning.level_tolerance_deg", &c.level_tolerance_deg},
      {"commissioning.statue_min_tilt_deg", &c.statue_min_tilt_deg},
      {"commissioning.gyro_tolerance", &c.gyro_tolerance},
      {"commissioning.seat_tolerance_deg", &c.seat_tolerance_deg},
      {"commissioning.rest_s", &c.rest_s},
      {"commissioning.hold_s", &c.hold_s},
  };
  for (const auto& [key, target] : numbers) b.push_back({key, number_into(*target), "a number"});
}

std::vector<Binding> bindings(MonitorFile& f, int& node, int& statue_node, std::string& unit,
                              std::array<bool, kRelayCount>& relay_active_low,
                              monitor::PWaveSettings& pwave, std::string& pwave_channel) {
  MonitorConfig& c = f.config;
  monitor::AlarmPolicySettings& alarm = c.alarm;
  std::vector<Binding> b = {
      {"sensor", read_apart(), kSensorsExpected},
      {"monitor.ground_node", integer_into(node), "an integer"},
      {"monitor.quiet_risk", number_into(c.quiet_risk), "a number"},
      {"monitor.status_interval_s", number_into(c.status_interval_s), "a number"},
      {"monitor.second_scene", string_into(f.second_scene_path), "a string (a scene file)"},
      {"estimator.sample_rate_hz", number_into(c.estimator.sample_rate_hz), "a number"},
      {"estimator.steps_per_sample", integer_into(c.estimator.steps_per_sample), "an integer"},
      {"estimator.stepper", stepper_into(c.estimator.solver.stepper),
       "\"rk4_located\", \"rk4_step_end\", \"heun_located\" or \"semi_implicit_euler\""},
      {"estimator.exact_full_contact", flag_into(c.estimator.solver.exact_full_contact),
       "true or false"},
      {"risk.base_stop_weight", number_into(c.risk.base_stop_weight), "a number"},
      {"forecast.enabled", flag_into(c.forecast.enabled), "true or false"},
      {"forecast.continuation", continuation_into(c.forecast.continuation),
       "\"recent_window\" or \"strongest_window\""},
      {"forecast.horizon_s", number_into(c.forecast.horizon_s), "a number"},
      {"forecast.window_s", number_into(c.forecast.window_s), "a number"},
      {"forecast.growth", number_into(c.forecast.growth), "a number"},
      {"forecast.memory_s", number_into(c.forecast.memory_s), "a number"},
      {"forecast.interval_s", number_into(c.forecast.interval_s), "a number"},
      {"forecast.rate_hz", number_into(c.forecast.rate_hz), "a number"},
      {"forecast.steps_per_period", integer_into(c.forecast.steps_per_period), "an integer"},
      {"forecast.work_steps_per_s", number_into(c.forecast.work_steps_per_s), "a number"},
      {"redundancy.window_s", number_into(c.redundancy.window_s), "a number"},
      {"redundancy.tolerance_m_s2", number_into(c.redundancy.tolerance_m_s2), "a number"},
      {"plate.window_s", number_into(c.plate.window_s), "a number"},
      {"plate.threshold_m_s2", number_into(c.plate.threshold_m_s2), "a number"},
      {"plate.raises_fault", flag_into(c.plate.raises_fault), "true or false"},
      {"alarm_policy.raise_hold_s", number_into(alarm.raise_hold_s), "a number"},
      {"alarm_policy.lower_hold_s", number_into(alarm.lower_hold_s), "a number"},
      {"alarm_policy.latch_warning", flag_into(alarm.latch_warning), "true or false"},
      {"alarm_policy.latch_alarm", flag_into(alarm.latch_alarm), "true or false"},
      {"alarm_policy.heartbeat_period_s", number_into(alarm.heartbeat_period_s), "a number"},
  };
  if (auto* regional = monitor::built_part<monitor::RegionalAlertSettings>(c.regional)) {
    regional_bindings(b, *regional);
    b.push_back({"regional_alert.key_file", string_into(f.regional_key_file),
                 "a string (a file path)"});
  }
  sensor_bindings(b, "conditioning.", c.conditioning, c.sensor_health, unit);
  statue_bindings(b, c.statue_sensor, statue_node);
  relay_bindings(b, f.relays, relay_active_low);
  b.push_back({"watchdog.notify", flag_into(f.watchdog.notify), "true or false"});
  b.push_back({"watchdog.test_stall_after_s", number_into(f.watchdog.test_stall_after_s),
               "a number (s; test only)"});
  b.push_back({"recorder.max_captures", count_into(f.recorder.retention.max_captures),
               "an integer from 0 (no limit) to 2^53"});
  b.push_back({"recorder.max_bytes", count_into(f.recorder.retention.max_bytes),
               "an integer from 0 (no limit) to 2^53"});
  b.push_back({"recorder.bus_frames_hz", number_into(f.recorder.bus_frames_hz),
               "a number (frames/s)"});
  b.push_back({"recorder.test_pause_mid_write_s", number_into(f.recorder.test_pause_mid_write_s),
               "a number (s; test only)"});
  output_bindings(b, f.modbus, f.mqtt);
  commissioning_bindings(b, f.commissioning);
  pwave_bindings(b, pwave, pwave_channel);
  using monitor::built_part;
  using monitor::RiskThresholds;
  for (auto [name, thresholds] : {std::pair<const char*, monitor::RiskThresholds*>{"advisory", &alarm.advisory},
                                  {"warning", &alarm.warning},
                                  {"alarm", &alarm.alarm},
                                  {"advisory_forecast", &alarm.advisory_forecast},
                                  {"warning_forecast", &alarm.warning_forecast},
                                  {"alarm_forecast", &alarm.alarm_forecast},
                                  {"warning_pwave",
                                   built_part<RiskThresholds>(alarm.warning_pwave)},
                                  {"warning_regional",
                                   built_part<RiskThresholds>(alarm.warning_regional)}}) {
    if (thresholds == nullptr) continue;  // a part this build has not: its keys are unknown
    b.push_back({cat("alarm_policy.", name, ".on"), number_into(thresholds->on), "a number"});
    b.push_back({cat("alarm_policy.", name, ".off"), number_into(thresholds->off), "a number"});
  }
  return b;
}

// Every leaf of the document with its dotted key.
void flatten(const toml::table& table, const std::string& prefix,
             std::vector<std::pair<std::string, const toml::node*>>& out) {
  for (const auto& [key, node] : table) {
    const std::string name = prefix.empty() ? std::string(key.str()) : cat(prefix, ".", key.str());
    if (const toml::table* sub = node.as_table()) {
      flatten(*sub, name, out);
    } else {
      out.emplace_back(name, &node);
    }
  }
}

// The file's keys and where each stands, for messages: "box.toml:12".
class KeyLines {
 public:
  explicit KeyLines(std::string origin) : origin_(std::move(origin)) {}
  void note(const std::string& key, std::uint32_t line) { lines_[key] = line; }
  [[nodiscard]] bool has(const std::string& key) const { return lines_.count(key) > 0; }
  // "origin:line" of `key`, or the origin alone when the key is not in the file.
  [[nodiscard]] std::string where(const std::string& key) const {
    const auto it = lines_.find(key);
    return it != lines_.end() && it->second > 0 ? cat(origin_, ":", std::to_string(it->second))
                                                : origin_;
  }
  // Stores `value` through `key`'s binding; `name` is how messages call it.
  void store(std::vector<Binding>& table, const std::string& key, const std::string& name,
             const toml::node& value) const {
    const auto binding =
        std::find_if(table.begin(), table.end(), [&](const Binding& b) { return b.key == key; });
    if (binding == table.end()) {
      // A value where a table of settings belongs (alarm_policy.advisory = 0.1) is the wrong
      // type, not an unknown key.
      const std::string inside = key + ".";
      if (std::any_of(table.begin(), table.end(),
                      [&](const Binding& b) { return b.key.rfind(inside, 0) == 0; })) {
        throw InputError(cat(where(name), ": ", name, ": expected a table (", name,
                             ".<key> = ...), got ", host::toml_type_name(value.type())));
      }
      // A table where a value belongs (estimator.sample_rate_hz = { ... }): the same.
      const auto holder = std::find_if(table.begin(), table.end(), [&](const Binding& b) {
        return key.rfind(b.key + ".", 0) == 0;
      });
      if (holder != table.end()) {
        const std::string held = name.substr(0, name.size() - (key.size() - holder->key.size()));
        throw InputError(
            cat(where(name), ": ", held, ": expected ", holder->expected, ", got a table"));
      }
      throw InputError(cat(where(name), ": ", name, ": unknown key (docs/monitor.md lists them)"));
    }
    if (!binding->store(value)) {
      throw InputError(cat(where(name), ": ", name, ": expected ", binding->expected));
    }
  }
  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw InputError(cat(where(key), ": ", message));
  }
  // Every key of the file and where it stands.
  [[nodiscard]] std::map<std::string, std::string> all_where() const {
    std::map<std::string, std::string> out;
    for (const auto& [key, line] : lines_) out[key] = where(key);
    return out;
  }

 private:
  std::string origin_;
  std::map<std::string, std::uint32_t> lines_;
};

toml::table parse_toml(const std::string& text, const std::string& origin) {
  try {
    return toml::parse(text, origin);
  } catch (const toml::parse_error& error) {
    const toml::source_position where = error.source().begin;
    throw InputError(cat(origin, ":", std::to_string(where.line), ":", std::to_string(where.column),
                         ": TOML syntax error: ", error.description()));
  }
}

// The unit's name (conditioning.h), into `target` when not empty.
void store_unit(const std::string& text, const KeyLines& lines, const std::string& key,
                monitor::AccelerationUnit& target) {
  if (!text.empty() && !monitor::kAccelerationUnitNames.parse(text, target)) {
    lines.fail(key, cat(key, ": expected \"g\" or \"m/s2\", got \"", text, "\""));
  }
}

// One [[sensor]] table (sensor[index]) over the file's top-level sensor settings.
SensorConfig read_sensor(const toml::table& table, int index, const MonitorConfig& config,
                         KeyLines& lines) {
  const std::string head = cat("sensor[", std::to_string(index), "]");
  lines.note(head, table.source().begin.line);
  SensorConfig sc;
  sc.conditioning = config.conditioning;
  sc.sensor_health = config.sensor_health;
  int node = 0;
  std::string role = "ground";
  std::string unit;
  std::vector<Binding> keys = {
      {"node", integer_into(node), "an integer"},
      {"role", string_into(role), "a string, \"ground\" or \"plate\""},
  };
  sensor_bindings(keys, "", sc.conditioning, sc.sensor_health, unit);
  std::vector<std::pair<std::string, const toml::node*>> leaves;
  flatten(table, "", leaves);
  for (const auto& [key, node_ptr] : leaves) {
    const std::string name = cat(head, ".", key);
    lines.note(name, node_ptr->source().begin.line);
    lines.store(keys, key, name, *node_ptr);
  }
  const std::string node_key = cat(head, ".node");
  if (!lines.has(node_key)) {
    lines.fail(head, cat(head, ": no node (each [[sensor]] gives its CAN node)"));
  }
  if (node < 1 || node > 15) lines.fail(node_key, cat(node_key, ": must lie in [1, 15]"));
  sc.node = static_cast<std::uint8_t>(node);
  for (int j = 0; j < index; ++j) {
    if (config.sensors[static_cast<std::size_t>(j)].node == sc.node) {
      lines.fail(node_key, cat(node_key, ": node ", std::to_string(node), " is already sensor[",
                               std::to_string(j), "]'s"));
    }
  }
  if (!kSensorRoleNames.parse(role, sc.role)) {
    lines.fail(cat(head, ".role"),
               cat(head, ".role: expected \"ground\" or \"plate\", got \"", role, "\""));
  }
  store_unit(unit, lines, cat(head, ".unit"), sc.conditioning.unit);
  return sc;
}

// The [[sensor]] tables, read after the top-level tables (whose [conditioning] and
// [sensor_health] are every sensor's defaults).
void read_sensors(const toml::node& list, MonitorConfig& config, KeyLines& lines) {
  const toml::array* tables = list.as_array();
  if (tables == nullptr || !tables->is_array_of_tables()) {
    lines.fail("sensor", cat("sensor: expected ", kSensorsExpected, ", got ",
                             tables != nullptr && tables->empty()
                                 ? std::string_view("an empty array")
                                 : host::toml_type_name(list.type())));
  }
  if (lines.has("monitor.ground_node")) {
    lines.fail("monitor.ground_node",
               "monitor.ground_node: not with [[sensor]] tables (each gives its node)");
  }
  if (tables->size() > static_cast<std::size_t>(kMaxSensors)) {
    const std::string name = cat("sensor[", std::to_string(kMaxSensors), "]");
    lines.note(name, (*tables)[static_cast<std::size_t>(kMaxSensors)].source().begin.line);
    lines.fail(name, cat(name, ": at most ", std::to_string(kMaxSensors), " sensors"));
  }
  config.sensor_count = static_cast<int>(tables->size());
  for (std::size_t i = 0; i < tables->size(); ++i) {
    config.sensors[i] = read_sensor(*(*tables)[i].as_table(), static_cast<int>(i), config, lines);
  }
}

// [statue_sensor] configures the statue sensor, which needs its node; [statue_filter] alone
// tunes a sensor the file does not have.
void read_statue_sensor(const toml::table& doc, int node, StatueSensorSettings& statue,
                        KeyLines& lines) {
  for (const char* name : {"statue_sensor", "statue_filter"}) {
    if (const toml::node* t = doc.get(name)) lines.note(name, t->source().begin.line);
  }
  const bool table = doc.get("statue_sensor") != nullptr;
  if (!table && doc.get("statue_filter") != nullptr) {
    lines.fail("statue_filter",
               "statue_filter: no [statue_sensor] table (the filter weighs its measurements)");
  }
  if (!table) return;
  if (!lines.has("statue_sensor.node")) {
    lines.fail("statue_sensor",
               "statue_sensor: no node (statue_sensor.node gives the IMU's CAN node)");
  }
  if (node < 1 || node > 15) {
    lines.fail("statue_sensor.node", "statue_sensor.node: must lie in [1, 15]");
  }
  statue.present = true;
  statue.node = static_cast<std::uint8_t>(node);
}

// The file's key of a field validate() reports for sensor `index` of a [[sensor]] list.
std::string sensor_key(int index, const std::string& field) {
  const std::string head = cat("sensor[", std::to_string(index), "].");
  for (const char* mounting : {"unit", "sensor_to_statue", "rotation_tolerance"}) {
    if (field == cat("conditioning.", mounting)) return cat(head, mounting);
  }
  if (field.rfind("sensor.", 0) == 0) return cat(head, field.substr(7));
  return cat(head, field);
}

// The [relays] table as a whole: polarity defaults, offsets in range and distinct, a chip for
// the lines and lines for the chip.
void check_relays(RelaySettings& relays, bool default_active_low, const KeyLines& lines) {
  constexpr int kMaxLineOffset = 1023;  // far beyond any chip's lines; the chip checks its own
  bool any = false;
  for (std::size_t i = 0; i < kRelayCount; ++i) {
    RelayLine& line = relays.lines[i];
    const std::string key = cat("relays.", kRelayNames[i]);
    const std::string at = lines.has(key) ? key : cat(key, ".line");
    if (!lines.has(cat(key, ".active_low"))) line.active_low = default_active_low;
    if (!lines.has(key) && !lines.has(cat(key, ".line"))) {
      if (lines.has(cat(key, ".active_low")))
        lines.fail(cat(key, ".active_low"), cat(key, ": no line"));
      line.offset = -1;
      continue;
    }
    if (line.offset < 0 || line.offset > kMaxLineOffset) {
      lines.fail(at,
                 cat(key, ": line offset must lie in [0, ", std::to_string(kMaxLineOffset), "]"));
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (relays.lines[j].offset == line.offset) {
        lines.fail(at, cat(key, ": line ", std::to_string(line.offset), " is already relays.",
                           kRelayNames[j], "'s"));
      }
    }
    any = true;
  }
  if (any && relays.chip.empty()) lines.fail("relays", "relays: lines without relays.chip");
  if (!any && !relays.chip.empty()) {
    lines.fail("relays.chip", "relays.chip: no relay lines (advisory, warning, alarm, fault)");
  }
}

// The keys of the regional alerts: refused by a build without them (kRegionalAlertBuiltIn).
bool regional_key(const std::string& key) {
  return key.rfind("regional_alert.", 0) == 0 ||
         key.rfind("alarm_policy.warning_regional", 0) == 0 || key == "mqtt.regional_alerts" ||
         key == "mqtt.regional_topic";
}

// validate(MonitorConfig), its field named as the file's key.
void check(const MonitorConfig& config, const KeyLines& lines) {
  int sensor_index = -1;
  const Error e = validate(config, &sensor_index);
  if (e.ok()) return;
  if (sensor_index < 0) lines.fail(e.field, cat(e.field, ": ", e.reason));
  // A sensor's field: its own key if the [[sensor]] table sets it, else the default's line.
  const std::string key = sensor_key(sensor_index, e.field);
  const std::string head = cat("sensor[", std::to_string(sensor_index), "]");
  const std::string at = lines.has(key) ? key : lines.has(e.field) ? e.field : head;
  lines.fail(at, cat(key, ": ", e.reason));
}

// [pwave]'s predictor: 1 to kMaxPWavePredictorPoints tables { window_s, ln_pga_over_pa,
// tau_c_exponent (0 when left out), sigma_ln }, as plinth-eval pwave-fit prints them.
void read_pwave_predictor(const toml::node& node, monitor::PWaveSettings& pwave,
                          const KeyLines& lines) {
  const char* key = "pwave.predictor";
  const toml::array* points = node.as_array();
  if (points == nullptr || (!points->empty() && !points->is_array_of_tables())) {
    lines.fail(key, cat(key, ": expected ", kPredictorExpected, ", got ",
                        host::toml_type_name(node.type())));
  }
  if (points->empty() || points->size() > monitor::kMaxPWavePredictorPoints) {
    lines.fail(key, cat(key, ": must have 1 to ",
                        std::to_string(monitor::kMaxPWavePredictorPoints), " points, has ",
                        std::to_string(points->size())));
  }
  pwave.predictor_points = points->size();
  for (std::size_t i = 0; i < points->size(); ++i) {
    monitor::PWavePredictorPoint& point = pwave.predictor[i];
    point = {};
    const std::string head = cat(key, "[", std::to_string(i), "]");
    std::vector<Binding> keys = {
        {"window_s", number_into(point.window_s), "a number"},
        {"ln_pga_over_pa", number_into(point.ln_pga_over_pa), "a number"},
        {"tau_c_exponent", number_into(point.tau_c_exponent), "a number"},
        {"sigma_ln", number_into(point.sigma_ln), "a number"},
    };
    std::vector<std::pair<std::string, const toml::node*>> leaves;
    flatten(*(*points)[i].as_table(), "", leaves);
    for (const char* required : {"window_s", "ln_pga_over_pa", "sigma_ln"}) {
      if (std::none_of(leaves.begin(), leaves.end(),
                       [&](const auto& leaf) { return leaf.first == required; })) {
        lines.fail(key, cat(head, ": no ", required));
      }
    }
    for (const auto& [leaf, leaf_node] : leaves) lines.store(keys, leaf, cat(head, ".", leaf), *leaf_node);
  }
}

// validate(PWaveSettings) at the estimator's rate, its field named as the file's key (a
// predictor point's with its index) and its limit given.
void check_pwave(monitor::PWaveSettings pwave, double sample_period_s, const KeyLines& lines) {
  pwave.sample_period_s = sample_period_s;
  const Error e = monitor::validate(pwave);
  if (e.ok()) return;
  std::string key = e.field;
  const std::string point_field = "pwave.predictor.";
  if (key.rfind(point_field, 0) == 0) {
    // The first point at fault: the shortest table that fails the same way.
    std::size_t index = 0;
    for (monitor::PWaveSettings prefix = pwave; prefix.predictor_points >= 1;) {
      const std::size_t n = prefix.predictor_points;
      prefix.predictor_points = n - 1;
      if (n == 1 || monitor::validate(prefix).ok()) {
        index = n - 1;
        break;
      }
    }
    key = cat("pwave.predictor[", std::to_string(index), "].", key.substr(point_field.size()));
  }
  std::string message = cat(key, ": ", e.reason);
  if (e.limit != 0.0 && std::isfinite(e.limit)) {
    message += cat(" (limit ", host::number_text(e.limit), ")");
  }
  lines.fail(lines.has(key) ? key : lines.has(e.field) ? e.field : "pwave", message);
}

// The [pwave] table: the stage on, its channel (and that channel's fitted table unless it gives
// a predictor), checked; a build without the stage refuses it.
void read_pwave(const toml::node& table, monitor::PWaveSettings& pwave, const std::string& channel,
                MonitorConfig& config, KeyLines& lines) {
  lines.note("pwave", table.source().begin.line);
  if (!table.is_table()) lines.fail("pwave", "pwave: expected a table ([pwave])");
  if (!channel.empty() && !monitor::kPWaveChannelNames.parse(channel, pwave.channel)) {
    lines.fail("pwave.channel",
               cat("pwave.channel: expected \"vertical\" or \"horizontal\", got \"", channel, "\""));
  }
  if (const toml::node* predictor = table.as_table()->get("predictor")) {
    read_pwave_predictor(*predictor, pwave, lines);
  } else if (!channel.empty()) {
    const auto& fitted = monitor::default_predictor(pwave.channel);
    std::copy(fitted.begin(), fitted.end(), pwave.predictor.begin());
    pwave.predictor_points = fitted.size();
  }
  pwave.enabled = true;
  monitor::PWaveSettings* built = monitor::built_part<monitor::PWaveSettings>(config.pwave);
  if (built == nullptr) {
    lines.fail("pwave", "pwave: this build has no P-wave stage (PLINTH_PWAVE_STAGE=OFF)");
    return;
  }
  check_pwave(pwave, config.estimator.sample_period(), lines);
  pwave.fragility_known = built->fragility_known;  // the scene's, set by the application
  pwave.fragility = built->fragility;
  *built = pwave;
}

// recorder.bus_frames_hz's bound: a classic CAN bus's most frames/s, with room.
constexpr double kMaxRecorderBusFramesHz = 25000.0;

std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

// A file key's path, relative to the file's folder.
void resolve_path(std::string& path, const std::string& origin) {
  const std::filesystem::path p(path);
  if (!path.empty() && p.is_relative()) {
    path = (std::filesystem::path(origin).parent_path() / p).string();
  }
}

// What is wrong with `text` as part of a topic name (mqtt_publisher.h), "" when nothing is: not
// empty, at most `max_bytes`, UTF-8 without control characters (a NUL would cut the topic short:
// another box's), no wildcard, no empty level; `levels`: may hold several ("a/b").
std::string topic_problem(const std::string& text, bool levels, std::size_t max_bytes) {
  if (text.empty()) return "empty";
  if (text.size() > max_bytes) {
    return cat("longer than ", std::to_string(max_bytes), " bytes (", std::to_string(text.size()),
               ")");
  }
  if (std::any_of(text.begin(), text.end(), [](char c) {
        return static_cast<unsigned char>(c) < 0x20 || c == 0x7F;
      })) {
    return "a control character (NUL, newline, ESC, ...)";
  }
  if (!valid_utf8(text)) return "not UTF-8";
  if (text.find_first_of("+#") != std::string::npos) return "a wildcard ('+' or '#')";
  if (!levels && text.find('/') != std::string::npos) return "a '/' (one topic level only)";
  if (text.front() == '/' || text.back() == '/' || text.find("//") != std::string::npos) {
    return "an empty topic level";
  }
  return "";
}

// regional_alert.key_file: its first line, 64 hex digits (32 bytes), is the key every regional
// alert's HMAC must be made with (regional_alert.h, RegionalAuthentication).
void read_regional_key(MonitorFile& file, const KeyLines& lines, const std::string& origin) {
  auto* regional = monitor::built_part<monitor::RegionalAlertSettings>(file.config.regional);
  if (regional == nullptr || !lines.has("regional_alert.key_file")) return;
  resolve_path(file.regional_key_file, origin);
  std::string text = host::read_text_file(file.regional_key_file, 4096,
                                          "regional_alert.key_file (the alerts' HMAC key)");
  text = text.substr(0, text.find_first_of("\r\n"));
  monitor::RegionalAuthentication& auth = regional->authentication;
  const auto fail = [&] {
    lines.fail("regional_alert.key_file",
               cat("regional_alert.key_file: ", file.regional_key_file,
                   ": expected 64 hex digits (32 bytes, e.g. from `openssl rand -hex 32`) on its "
                   "first line"));
  };
  if (text.size() != 2 * auth.key.size()) fail();
  for (std::size_t i = 0; i < auth.key.size(); ++i) {
    const std::string two = text.substr(2 * i, 2);
    if (two.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos) fail();
    auth.key[i] = static_cast<std::uint8_t>(std::stoul(two, nullptr, 16));
  }
  auth.required = true;
}

// The [modbus] and [mqtt] keys: addresses, ranges, topic parts; paths resolved.
void check_outputs(MonitorFile& file, const KeyLines& lines, const std::string& origin) {
  ModbusSettings& modbus = file.modbus;
  MqttSettings& mqtt = file.mqtt;
  if (lines.has("modbus.listen")) {
    modbus.listen_where = cat(lines.where("modbus.listen"), ": modbus.listen");
    (void)parse_endpoint(modbus.listen, modbus.listen_where);
  }
  if (modbus.max_clients < 1 || modbus.max_clients > 64) {
    lines.fail("modbus.max_clients", "modbus.max_clients: must lie in [1, 64]");
  }
  if (lines.has("mqtt.broker")) {
    mqtt.broker_where = cat(lines.where("mqtt.broker"), ": mqtt.broker");
    (void)parse_endpoint(mqtt.broker, mqtt.broker_where);
  }
  if (lines.has("mqtt.box_id")) {
    const std::string problem = topic_problem(mqtt.box_id, false, kMaxBoxIdBytes);
    if (!problem.empty()) {
      lines.fail("mqtt.box_id", cat("mqtt.box_id: expected one topic level (no '/', '+' or '#'), ",
                                    "printable UTF-8 of at most ", std::to_string(kMaxBoxIdBytes),
                                    " bytes: ", problem));
    }
  }
  for (const auto& [key, value] :
       {std::pair<const char*, const std::string*>{"mqtt.topic_prefix", &mqtt.topic_prefix},
        {"mqtt.discovery_prefix", &mqtt.discovery_prefix}}) {
    const std::string problem = topic_problem(*value, true, kMaxTopicPrefixBytes);
    if (!problem.empty()) {
      lines.fail(key, cat(key, ": expected topic levels (no '+' or '#', no empty level): ",
                          problem));
    }
  }
  if (lines.has("mqtt.regional_topic")) {
    const std::string problem = topic_problem(mqtt.regional_topic, true, kMaxTopicPrefixBytes);
    if (!problem.empty()) {
      lines.fail("mqtt.regional_topic",
                 cat("mqtt.regional_topic: expected one topic, without wildcards (the box takes "
                     "alerts from one bridge's topic): ",
                     problem));
    }
    if (!mqtt.regional_alerts) {
      lines.fail("mqtt.regional_topic",
                 "mqtt.regional_topic: names the regional alerts' topic, and mqtt.regional_alerts "
                 "is false (set it to true to take them)");
    }
  }
  for (const std::string& text : modbus.write_from) {
    if (!parse_address_prefix(text)) {
      lines.fail("modbus.write_from",
                 cat("modbus.write_from: \"", printable(text),
                     "\" is not an address (\"10.0.4.7\", \"::1\") or a prefix (\"10.0.4.0/24\") ",
                     "with no host bit past it"));
    }
  }
  if (!(modbus.idle_timeout_s >= 1.0 && modbus.idle_timeout_s <= 86400.0)) {
    lines.fail("modbus.idle_timeout_s", "modbus.idle_timeout_s: must lie in [1, 86400]");
  }
  const auto range = [&](const char* key, double value, double low, double high) {
    if (!(value >= low && value <= high)) {
      lines.fail(key, cat(key, ": must lie in [", number_text(low), ", ", number_text(high), "]"));
    }
  };
  range("mqtt.keepalive_s", mqtt.keepalive_s, 5, 3600);
  range("mqtt.event_queue", mqtt.event_queue, 1, 100000);
  range("mqtt.state_interval_s", mqtt.state_interval_s, 0.001, 3600);
  range("mqtt.reconnect_min_s", mqtt.reconnect_min_s, 0.01, 3600);
  range("mqtt.reconnect_max_s", mqtt.reconnect_max_s, mqtt.reconnect_min_s, 3600);
  if (!mqtt.password.empty() && !mqtt.password_file.empty()) {
    lines.fail("mqtt.password",
               "mqtt.password: give mqtt.password or mqtt.password_file, not both");
  }
  for (std::string* path : {&mqtt.password_file, &mqtt.ca_file, &mqtt.cert_file, &mqtt.key_file}) {
    resolve_path(*path, origin);
  }
  mqtt.files_where = origin;
}

}  // namespace

MonitorFile load_monitor_text(const std::string& text, const std::string& origin,
                              const MonitorConfig& defaults) {
  const toml::table doc = parse_toml(text, origin);
  MonitorFile file;
  file.config = defaults;
  int node = defaults.ground_node;
  int statue_node = defaults.statue_sensor.node;
  std::string unit;
  std::array<bool, kRelayCount> relay_active_low{};  // [0]: relays.active_low
  monitor::PWaveSettings pwave;  // [pwave], over the defaults' when the build has the stage
  if (const auto* given = monitor::built_part<monitor::PWaveSettings>(defaults.pwave)) {
    pwave = *given;
  }
  std::string pwave_channel;
  std::vector<Binding> known =
      bindings(file, node, statue_node, unit, relay_active_low, pwave, pwave_channel);
  const toml::node* sensor_list = doc.get("sensor");
  std::vector<std::pair<std::string, const toml::node*>> leaves;
  flatten(doc, "", leaves);
  KeyLines lines(origin);
  for (const auto& [key, node_ptr] : leaves) {
    lines.note(key, node_ptr->source().begin.line);
    lines.store(known, key, key, *node_ptr);
    if (!monitor::kRegionalAlertBuiltIn && regional_key(key)) {
      lines.fail(key, cat(key, ": ", monitor::kRegionalAlertNotBuilt));
    }
  }
  if (node < 1 || node > 15) {
    lines.fail("monitor.ground_node", "monitor.ground_node: must lie in [1, 15]");
  }
  file.config.ground_node = static_cast<std::uint8_t>(node);
  read_statue_sensor(doc, statue_node, file.config.statue_sensor, lines);
  store_unit(unit, lines, "conditioning.unit", file.config.conditioning.unit);
  if (sensor_list != nullptr) read_sensors(*sensor_list, file.config, lines);
  if (!file.second_scene_path.empty()) {
    const std::filesystem::path p(file.second_scene_path);
    if (p.is_relative()) {
      file.second_scene_path = (std::filesystem::path(origin).parent_path() / p).string();
    }
    file.config.axis_count = 2;
  }
  check_relays(file.relays, relay_active_low[0], lines);
  if (!std::isfinite(file.watchdog.test_stall_after_s) || file.watchdog.test_stall_after_s < 0.0) {
    lines.fail("watchdog.test_stall_after_s",
               "watchdog.test_stall_after_s: must be a finite number of seconds >= 0");
  }
  if (!std::isfinite(file.recorder.test_pause_mid_write_s) ||
      file.recorder.test_pause_mid_write_s < 0.0 || file.recorder.test_pause_mid_write_s > 600.0) {
    lines.fail("recorder.test_pause_mid_write_s",
               "recorder.test_pause_mid_write_s: must be a number of seconds in [0, 600]");
  }
  if (!std::isfinite(file.recorder.bus_frames_hz) || file.recorder.bus_frames_hz < 0.0 ||
      file.recorder.bus_frames_hz > kMaxRecorderBusFramesHz) {
    lines.fail("recorder.bus_frames_hz",
               cat("recorder.bus_frames_hz: must be a number of frames/s in [0, ",
                   number_text(kMaxRecorderBusFramesHz), "] (a CAN bus at 1 Mbit/s carries at "
                   "most about 21,000 frames/s)"));
  }
  if (const toml::node* table = doc.get("pwave")) read_pwave(*table, pwave, pwave_channel, file.config, lines);
  check(file.config, lines);
  check_outputs(file, lines, origin);
  if (const std::optional<SettingError> e = validate(file.commissioning)) {
    lines.fail(e->key, e->message);
  }
  if (lines.has("commissioning.override") && file.commissioning.override_reason.empty()) {
    lines.fail("commissioning.override",
               "commissioning.override: give the reason the box monitors without a passing "
               "commissioning (it is logged at each start)");
  }
  resolve_path(file.commissioning.report, origin);
  read_regional_key(file, lines, origin);
  file.key_where = lines.all_where();
  return file;
}

double recorder_frame_rate_hz(const MonitorFile& file) {
  const MonitorConfig& c = file.config;
  const int sensors = std::max(c.sensor_count, 1);  // the single ground sensor: one
  const int statue = c.statue_sensor.present ? 1 : 0;
  const double frames_a_sample = sensors + 2.0 * statue;
  const double heartbeats_hz = sensors + statue;
  return kRecorderClockMargin * frames_a_sample * c.estimator.sample_rate_hz + heartbeats_hz +
         file.recorder.bus_frames_hz;
}

MonitorFile load_monitor_file(const std::string& path, const MonitorConfig& defaults) {
  // Bounded, and a directory, FIFO or device refused rather than read as an empty file.
  constexpr std::size_t kMaxConfigBytes = std::size_t{1} << 20;  // 1 MiB
  return load_monitor_text(host::read_text_file(path, kMaxConfigBytes, "configuration file"), path,
                           defaults);
}

namespace {

// The keys that turn something on, refused while what they turn on is off (the file's line, or
// the flag, named): a box file that says `writes = true` and serves no Modbus, or lets coils be
// written by nobody, is a mistake, not a setting.
void check_enabling_keys(const MonitorFile& file, const MonitorOverrides& o) {
  const auto named = [&](const char* key, const char* flag, bool flag_given) {
    if (flag_given) return std::string(flag);
    const auto it = file.key_where.find(key);
    return it == file.key_where.end() ? std::string(key) : cat(it->second, ": ", key);
  };
  const ModbusSettings& modbus = file.modbus;
  if (modbus.listen.empty() && modbus.writes) {
    throw InputError(cat(named("modbus.writes", "--modbus-writes", o.modbus_writes),
                         ": lets the Modbus server's coils be written; the server is off "
                         "(--modbus, or modbus.listen)"));
  }
  if (!modbus.write_from.empty() && !modbus.writes) {
    throw InputError(cat(named("modbus.write_from", "--modbus-write-from",
                               !o.modbus_write_from.empty()),
                         ": names who may write the Modbus coils, and writes are off "
                         "(modbus.writes, --modbus-writes)"));
  }
  if (modbus.writes && modbus.write_from.empty()) {
    throw InputError(cat(named("modbus.writes", "--modbus-writes", o.modbus_writes),
                         ": needs modbus.write_from (or --modbus-write-from), the addresses that "
                         "may write the coils: Modbus has no authentication, and a write "
                         "acknowledges or resets the box's alarm (docs/integration.md)"));
  }
  const MqttSettings& mqtt = file.mqtt;
  if (mqtt.broker.empty()) {
    for (const auto& [key, on] : {std::pair<const char*, bool>{"mqtt.commands", mqtt.commands},
                                  {"mqtt.regional_alerts", mqtt.regional_alerts}}) {
      if (on) {
        throw InputError(cat(named(key, key, false),
                             ": turns on a part of the MQTT client, which is off (--mqtt, or "
                             "mqtt.broker)"));
      }
    }
  }
}

// The [modbus] and [mqtt] flags over the file's keys.
void apply_output_overrides(MonitorFile& file, const MonitorOverrides& o) {
  if (!o.modbus_listen.empty()) {
    file.modbus.listen = o.modbus_listen;
    file.modbus.listen_where = "--modbus";
    (void)parse_endpoint(o.modbus_listen, "--modbus");
  }
  if (o.modbus_writes) file.modbus.writes = true;
  if (!o.modbus_write_from.empty()) {
    for (const std::string& text : o.modbus_write_from) {
      if (!parse_address_prefix(text)) {
        throw InputError(cat("--modbus-write-from: \"", printable(text),
                             "\" is not an address (\"10.0.4.7\", \"::1\") or a prefix "
                             "(\"10.0.4.0/24\") with no host bit past it"));
      }
    }
    file.modbus.write_from = o.modbus_write_from;
  }
  MqttSettings& mqtt = file.mqtt;
  if (!o.mqtt_broker.empty()) {
    mqtt.broker = o.mqtt_broker;
    mqtt.broker_where = "--mqtt";
    (void)parse_endpoint(o.mqtt_broker, "--mqtt");
  }
  if (!o.mqtt_box_id.empty()) {
    const std::string problem = topic_problem(o.mqtt_box_id, false, kMaxBoxIdBytes);
    if (!problem.empty()) {
      throw InputError(cat("--mqtt-box-id: expected one topic level (no '/', '+' or '#'), ",
                           "printable UTF-8 of at most ", std::to_string(kMaxBoxIdBytes),
                           " bytes: ", problem, ", got \"", printable(o.mqtt_box_id, 80), "\""));
    }
    mqtt.box_id = o.mqtt_box_id;
  }
  if (!o.mqtt_username.empty()) mqtt.username = o.mqtt_username;
  if (!o.mqtt_password_file.empty()) {
    mqtt.password_file = o.mqtt_password_file;
    mqtt.password.clear();
  }
  if (!o.mqtt_ca_file.empty()) mqtt.ca_file = o.mqtt_ca_file;
  if (!o.mqtt_cert_file.empty()) mqtt.cert_file = o.mqtt_cert_file;
  if (!o.mqtt_key_file.empty()) mqtt.key_file = o.mqtt_key_file;
  // An output's options while the output is off have no effect: refused, saying so.
  if (o.modbus_writes && file.modbus.listen.empty()) {
    throw InputError("--modbus-writes: lets the Modbus server's coils be written; the server is "
                     "off (--modbus, or modbus.listen in the configuration file)");
  }
  check_enabling_keys(file, o);
  for (const auto& [option, value] :
       {std::pair<const char*, const std::string*>{"--mqtt-box-id", &o.mqtt_box_id},
        {"--mqtt-username", &o.mqtt_username},
        {"--mqtt-password-file", &o.mqtt_password_file},
        {"--mqtt-ca", &o.mqtt_ca_file},
        {"--mqtt-cert", &o.mqtt_cert_file},
        {"--mqtt-key", &o.mqtt_key_file}}) {
    if (!value->empty() && mqtt.broker.empty()) {
      throw InputError(std::string(option) + ": sets the MQTT publisher, which is off (--mqtt, "
                                             "or mqtt.broker in the configuration file)");
    }
  }
}

}  // namespace

void apply_overrides(MonitorFile& file, const MonitorOverrides& o) {
  MonitorConfig& config = file.config;
  if (!o.scene_y_path.empty()) file.second_scene_path = o.scene_y_path;
  if (o.steps) config.estimator.steps_per_sample = *o.steps;
  if (o.rate_hz) config.estimator.sample_rate_hz = *o.rate_hz;
  if (o.status_interval_s) config.status_interval_s = *o.status_interval_s;
  if (o.no_relays) file.relays = RelaySettings{};
  if (o.relay_chip && !o.no_relays) {
    if (!file.relays.enabled()) {
      throw InputError(cat("--relay-chip ", *o.relay_chip,
                           ": no relay lines ([relays] in the configuration file names them)"));
    }
    file.relays.chip = *o.relay_chip;
  }
  if (o.node) {
    if (config.sensor_count > 0) {
      throw InputError(cat("--node names the single ground sensor; ", o.config_path,
                           " lists [[sensor]] tables (give the nodes there)"));
    }
    config.ground_node = static_cast<std::uint8_t>(*o.node);
  }
  // The command line's sensor settings apply to every sensor.
  const auto each_sensor = [&config](auto apply) {
    apply(config.conditioning, config.sensor_health);
    for (int i = 0; i < config.sensor_count && i < kMaxSensors; ++i) {
      SensorConfig& sensor = config.sensors[static_cast<std::size_t>(i)];
      apply(sensor.conditioning, sensor.sensor_health);
    }
  };
  if (o.startup_window_s) {
    each_sensor([&](monitor::ConditioningSettings& c, monitor::SensorHealthSettings&) {
      c.startup_window_s = *o.startup_window_s;
    });
  }
  if (o.no_forecast) config.forecast.enabled = false;
  if (o.stuck_samples) {
    each_sensor([&](monitor::ConditioningSettings&, monitor::SensorHealthSettings& h) {
      h.stuck_samples = *o.stuck_samples;
    });
  }
  apply_output_overrides(file, o);
}

MonitorFile configure_monitor(const MonitorOverrides& overrides) {
  MonitorFile file;
  file.config = box_defaults();
  if (!overrides.config_path.empty()) file = load_monitor_file(overrides.config_path, file.config);
  apply_overrides(file, overrides);
  return file;
}

}  // namespace plinth::firmware

#include "monitor_config.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <toml++/toml.h>
#include <vector>

#include "plinth/host/input_error.h"

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

std::function<bool(const toml::node&)> flag_into(bool& target) {
  return [&target](const toml::node& n) {
    if (!n.is_boolean()) return false;
    target = n.value<bool>().value_or(false);
    return true;
  };
}

std::vector<Binding> bindings(MonitorFile& f, int& node, std::string& unit) {
  MonitorConfig& c = f.config;
  monitor::ConditioningSettings& cond = c.conditioning;
  monitor::SensorHealthSettings& health = c.sensor_health;
  monitor::AlarmPolicySettings& alarm = c.alarm;
  std::vector<Binding> b = {
      {"monitor.ground_node", integer_into(node), "an integer"},
      {"monitor.quiet_risk", number_into(c.quiet_risk), "a number"},
      {"monitor.second_scene",
       [&f](const toml::node& n) {
         if (!n.is_string()) return false;
         f.second_scene_path = n.value<std::string>().value_or("");
         return true;
       },
       "a string (a scene file)"},
      {"estimator.sample_rate_hz", number_into(c.estimator.sample_rate_hz), "a number"},
      {"estimator.steps_per_sample", integer_into(c.estimator.steps_per_sample), "an integer"},
      {"risk.base_stop_weight", number_into(c.risk.base_stop_weight), "a number"},
      {"conditioning.unit",
       [&unit](const toml::node& n) {
         if (!n.is_string()) return false;
         unit = n.value<std::string>().value_or("");
         return true;
       },
       "a string, \"g\" or \"m/s2\""},
      {"conditioning.sensor_to_statue",
       [&cond](const toml::node& n) {
         const toml::array* rows = n.as_array();
         if (rows == nullptr || rows->size() != 3) return false;
         for (std::size_t i = 0; i < 3; ++i) {
           const toml::array* row = (*rows)[i].as_array();
           if (row == nullptr || row->size() != 3) return false;
           for (std::size_t j = 0; j < 3; ++j) {
             if (!(*row)[j].is_number()) return false;
             cond.sensor_to_statue(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
                 (*row)[j].value<double>().value_or(0.0);
           }
         }
         return true;
       },
       "three rows of three numbers (statue = R sensor)"},
      {"conditioning.rotation_tolerance", number_into(cond.rotation_tolerance), "a number"},
      {"conditioning.startup_window_s", number_into(cond.startup_window_s), "a number"},
      {"conditioning.startup_max_std_m_s2", number_into(cond.startup_max_std_m_s2), "a number"},
      {"conditioning.startup_max_offset_m_s2", number_into(cond.startup_max_offset_m_s2),
       "a number"},
      {"conditioning.tracking_time_constant_s", number_into(cond.tracking_time_constant_s),
       "a number"},
      {"conditioning.tracking_gate_m_s2", number_into(cond.tracking_gate_m_s2), "a number"},
      {"sensor_health.timeout_s", number_into(health.timeout_s), "a number"},
      {"sensor_health.max_bridge_samples", integer_into(health.max_bridge_samples), "an integer"},
      {"sensor_health.recovery_samples", integer_into(health.recovery_samples), "an integer"},
      {"sensor_health.stuck_samples", integer_into(health.stuck_samples), "an integer"},
      {"sensor_health.full_scale_g", number_into(health.full_scale_g), "a number"},
      {"sensor_health.max_valid_g", number_into(health.max_valid_g), "a number"},
      {"alarm_policy.raise_hold_s", number_into(alarm.raise_hold_s), "a number"},
      {"alarm_policy.lower_hold_s", number_into(alarm.lower_hold_s), "a number"},
      {"alarm_policy.latch_warning", flag_into(alarm.latch_warning), "true or false"},
      {"alarm_policy.latch_alarm", flag_into(alarm.latch_alarm), "true or false"},
      {"alarm_policy.heartbeat_period_s", number_into(alarm.heartbeat_period_s), "a number"},
  };
  for (auto [name, thresholds] : {std::pair<const char*, monitor::RiskThresholds*>{"advisory", &alarm.advisory},
                                  {"warning", &alarm.warning},
                                  {"alarm", &alarm.alarm}}) {
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

}  // namespace

MonitorFile load_monitor_text(const std::string& text, const std::string& origin,
                              const MonitorConfig& defaults) {
  toml::table doc;
  try {
    doc = toml::parse(text, origin);
  } catch (const toml::parse_error& error) {
    const toml::source_position where = error.source().begin;
    throw InputError(cat(origin, ":", std::to_string(where.line), ":", std::to_string(where.column),
                         ": TOML syntax error: ", error.description()));
  }
  MonitorFile file;
  file.config = defaults;
  int node = defaults.ground_node;
  std::string unit;
  std::vector<Binding> known = bindings(file, node, unit);
  std::vector<std::pair<std::string, const toml::node*>> leaves;
  flatten(doc, "", leaves);
  std::map<std::string, std::uint32_t> lines;
  const auto where = [&](const std::string& key) {
    const auto it = lines.find(key);
    return it != lines.end() && it->second > 0 ? cat(origin, ":", std::to_string(it->second)) : origin;
  };
  for (const auto& [key, node_ptr] : leaves) {
    lines[key] = node_ptr->source().begin.line;
    const auto binding = std::find_if(known.begin(), known.end(),
                                      [&](const Binding& b) { return b.key == key; });
    if (binding == known.end()) {
      throw InputError(cat(where(key), ": ", key, ": unknown key (docs/monitor.md lists them)"));
    }
    if (!binding->store(*node_ptr)) {
      throw InputError(cat(where(key), ": ", key, ": expected ", binding->expected));
    }
  }
  if (node < 1 || node > 15) {
    throw InputError(cat(where("monitor.ground_node"), ": monitor.ground_node: must lie in [1, 15]"));
  }
  file.config.ground_node = static_cast<std::uint8_t>(node);
  if (!unit.empty()) {
    if (unit == "g") {
      file.config.conditioning.unit = monitor::AccelerationUnit::kStandardGravity;
    } else if (unit == "m/s2") {
      file.config.conditioning.unit = monitor::AccelerationUnit::kMetresPerSecondSquared;
    } else {
      throw InputError(cat(where("conditioning.unit"),
                           ": conditioning.unit: expected \"g\" or \"m/s2\", got \"", unit, "\""));
    }
  }
  if (!file.second_scene_path.empty()) {
    const std::filesystem::path p(file.second_scene_path);
    if (p.is_relative()) {
      file.second_scene_path = (std::filesystem::path(origin).parent_path() / p).string();
    }
    file.config.axis_count = 2;
  }
  if (const Error e = validate(file.config); !e.ok()) {
    throw InputError(cat(where(e.field), ": ", e.field, ": ", e.reason));
  }
  return file;
}

MonitorFile load_monitor_file(const std::string& path, const MonitorConfig& defaults) {
  std::ifstream in(path);
  if (!in) throw InputError(cat(path, ": cannot open file"));
  std::ostringstream text;
  text << in.rdbuf();
  return load_monitor_text(text.str(), path, defaults);
}

}  // namespace plinth::firmware

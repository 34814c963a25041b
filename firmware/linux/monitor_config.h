// The box's configuration file (TOML): the tunables of plinth::firmware::MonitorConfig under
// the names its validation reports (docs/monitor.md, "Configuration file"). Host code: may
// allocate and throw.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "capture_store.h"
#include "commission_settings.h"
#include "plinth/firmware/monitor.h"
#include "plinth/firmware/record_replay.h"
#include "modbus_server.h"
#include "mqtt_publisher.h"
#include "relay_outputs.h"
#include "supervisor.h"

namespace plinth::firmware {

// [recorder]: the event recorder's folder (docs/monitor.md, "Event recorder").
struct RecorderFileSettings {
  RetentionLimits retention;  // recorder.max_captures, recorder.max_bytes (0: no limit)
  // recorder.bus_frames_hz: frames/s of the bus's other traffic (other boxes, other devices)
  // the capture buffers hold besides the configured sensors' (recorder_frame_rate_hz).
  double bus_frames_hz = 2000.0;
  // recorder.test_pause_mid_write_s, TEST ONLY (event_recorder.h); a box never sets it.
  double test_pause_mid_write_s = 0.0;
};

struct MonitorFile {
  MonitorConfig config;
  std::string second_scene_path;  // monitor.second_scene, resolved against the file's folder
  RelaySettings relays;           // [relays]
  WatchdogSettings watchdog;      // [watchdog]
  RecorderFileSettings recorder;  // [recorder]
  ModbusSettings modbus;          // [modbus]
  MqttSettings mqtt;              // [mqtt]
  // regional_alert.key_file, resolved (its key is in config.regional's authentication).
  std::string regional_key_file;
  // Each key the file set, and where: "box.toml:12" (the checks after the command line name
  // the line of a key that has no effect).
  std::map<std::string, std::string> key_where;
  CommissioningSettings commissioning;  // [commissioning] (docs/commissioning.md)
};

// Frames/s the event recorder's buffers are sized for (event_recorder.h): every configured
// sensor's frames at the sample rate (a ground or plate sensor one a sample, the statue sensor
// two: its acceleration and its rotation, with the single ground sensor three), with
// kRecorderClockMargin for sensor clocks that run fast, one heartbeat a second each, and the
// file's recorder.bus_frames_hz of other traffic.
inline constexpr double kRecorderClockMargin = 1.25;
[[nodiscard]] double recorder_frame_rate_hz(const MonitorFile& file);

// Reads `path` over `defaults`. Throws host::InputError naming the file, the line and the key
// for: a missing file, TOML syntax, unknown tables or keys, wrong types, and every value that
// validate(MonitorConfig) refuses (its field is the file's key).
[[nodiscard]] MonitorFile load_monitor_file(const std::string& path, const MonitorConfig& defaults);

// The same from text; `origin` names it in messages and resolves relative paths.
[[nodiscard]] MonitorFile load_monitor_text(const std::string& text, const std::string& origin,
                                            const MonitorConfig& defaults);

// What plinth-monitor's command line says about the configuration; unset: the file's value, or
// the default.
struct MonitorOverrides {
  std::string config_path;        // --config: the file, read over the defaults
  std::string scene_y_path;       // --scene-y: replaces the file's monitor.second_scene
  std::optional<int> steps;       // --steps: estimator.steps_per_sample
  std::optional<int> node;        // --node: the single ground sensor's (not with [[sensor]] tables)
  std::optional<double> rate_hz;  // --rate: estimator.sample_rate_hz
  std::optional<double> status_interval_s;  // --status-interval: monitor.status_interval_s
  std::optional<double> startup_window_s;   // --startup-window: every sensor's
  std::optional<int> stuck_samples;         // --stuck-samples: every sensor's
  bool no_forecast = false;                 // --no-forecast: forecast.enabled = false
  std::optional<std::string> relay_chip;    // --relay-chip: relays.chip
  bool no_relays = false;                   // --no-relays: the file's [relays] ignored
  std::string modbus_listen;                // --modbus HOST:PORT
  bool modbus_writes = false;               // --modbus-writes
  std::vector<std::string> modbus_write_from;  // --modbus-write-from: replaces modbus.write_from
  std::string mqtt_broker;                  // --mqtt HOST:PORT
  std::string mqtt_box_id;                  // --mqtt-box-id
  std::string mqtt_username;                // --mqtt-username
  std::string mqtt_password_file;           // --mqtt-password-file
  std::string mqtt_ca_file;                 // --mqtt-ca
  std::string mqtt_cert_file;               // --mqtt-cert
  std::string mqtt_key_file;                // --mqtt-key
};

// The command line over `file` (throws host::InputError for --node with [[sensor]] tables).
void apply_overrides(MonitorFile& file, const MonitorOverrides& overrides);

// plinth-monitor's configuration: the box's defaults (box_defaults(), record_replay.h), then
// the configuration file, then the command line.
[[nodiscard]] MonitorFile configure_monitor(const MonitorOverrides& overrides);

}  // namespace plinth::firmware

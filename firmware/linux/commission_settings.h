// The box file's [commissioning] table (docs/commissioning.md): whether plinth-monitor needs a
// passing commissioning report, where it is, an override with its reason, and the tolerances
// plinth-commission checks the sensors against. Host code: allocates.
#pragma once

#include <optional>
#include <string>

#include "plinth/firmware/config.h"

namespace plinth::firmware {

struct CommissioningSettings {
  // commissioning.required: without any report the box refuses to vouch (fault,
  // commissioning_failed); false: a box with no report monitors, saying so at each start.
  bool required = false;
  // commissioning.report: this report (resolved against the box file's folder), not the newest
  // commission-NNN.json of the recorder's folder.
  std::string report;
  // commissioning.override: a reason; the box monitors whatever the report says, logging the
  // reason and the report's verdict at each start.
  std::string override_reason;

  // What plinth-commission checks (each with its unit).
  double wedge_deg = 5.0;               // deg: the wedge's angle under a ground or plate sensor
  double wedge_tolerance_deg = 1.0;     // deg: the tilt read may differ from it by this
  double heading_tolerance_deg = 10.0;  // deg: a raise read this far from its axis at most
  double gravity_tolerance = 0.02;      // fraction of 1 g: |gravity read| - 1 g at rest
  double level_tolerance_deg = 2.0;     // deg: a sensor's gravity from the statue's vertical
  double statue_min_tilt_deg = 0.2;     // deg: the statue's raise must tilt its sensor this much
  double gyro_tolerance = 0.15;         // fraction: the gyroscope's turn against the tilt
  double seat_tolerance_deg = 0.1;      // deg: the statue back on its seat after a raise
  double rest_s = 10.0;                 // s: the rest windows (live)
  double hold_s = 5.0;                  // s: a raise held (live)
};

// A key at fault and what is wrong: "commissioning.wedge_deg: must lie in [1, 30]".
struct SettingError {
  std::string key;
  std::string message;
};

// The first setting outside its range, if any.
[[nodiscard]] std::optional<SettingError> validate(const CommissioningSettings& settings);

// What a commissioning vouches for, as text and its SHA-256 (64 hex digits): the sample rate
// and, for each sensor in configured order, its node, role, unit and sensor_to_statue, and the
// statue sensor's node, sensor_to_statue and place on the block. A report says what it checked
// by this digest; plinth-monitor compares it with its own box file's (any other key may change
// without a new commissioning).
[[nodiscard]] std::string mounting_text(const MonitorConfig& config);
[[nodiscard]] std::string mounting_sha256(const MonitorConfig& config);

}  // namespace plinth::firmware

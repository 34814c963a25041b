#include "commission_settings.h"

#include <array>
#include <cmath>
#include <cstdio>

#include "plinth/host/limits.h"
#include "run_identity.h"

namespace plinth::firmware {

std::optional<SettingError> validate(const CommissioningSettings& s) {
  struct Range {
    const char* key;
    double value;
    double low;
    double high;
  };
  // Physical ranges: a wedge steeper than 30 deg slides, one under 1 deg is lost in a floor's
  // unevenness; a tolerance as wide as the quantity would let anything pass.
  const std::array<Range, 10> ranges{{
      {"commissioning.wedge_deg", s.wedge_deg, 1.0, 30.0},
      {"commissioning.wedge_tolerance_deg", s.wedge_tolerance_deg, 0.05, 0.5 * s.wedge_deg},
      {"commissioning.heading_tolerance_deg", s.heading_tolerance_deg, 0.5, 30.0},
      {"commissioning.gravity_tolerance", s.gravity_tolerance, 0.001, 0.2},
      {"commissioning.level_tolerance_deg", s.level_tolerance_deg, 0.1, 10.0},
      {"commissioning.statue_min_tilt_deg", s.statue_min_tilt_deg, 0.05, 5.0},
      {"commissioning.gyro_tolerance", s.gyro_tolerance, 0.01, 0.5},
      {"commissioning.seat_tolerance_deg", s.seat_tolerance_deg, 0.01, 5.0},
      {"commissioning.rest_s", s.rest_s, 3.0, 600.0},
      {"commissioning.hold_s", s.hold_s, 2.0, 600.0},
  }};
  for (const Range& r : ranges) {
    if (!(r.value >= r.low && r.value <= r.high)) {
      return SettingError{r.key, std::string(r.key) + ": must lie in [" + host::number_text(r.low) +
                                     ", " + host::number_text(r.high) + "]"};
    }
  }
  return std::nullopt;
}

namespace {

std::string matrix_text(const Matrix3r& r) {
  std::string out = "[";
  char number[32];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      std::snprintf(number, sizeof number, "%s%.9g", i + j == 0 ? "" : " ",
                    static_cast<double>(r(i, j)));
      out += number;
    }
  }
  return out + "]";
}

}  // namespace

std::string mounting_text(const MonitorConfig& config) {
  std::array<SensorConfig, kMaxSensors> sensors{};
  const int count = resolved_sensors(config, sensors);
  char line[96];
  std::snprintf(line, sizeof line, "sample_rate_hz %.9g\n", config.estimator.sample_rate_hz);
  std::string out = line;
  for (int i = 0; i < count; ++i) {
    const SensorConfig& s = sensors[static_cast<std::size_t>(i)];
    std::snprintf(line, sizeof line, "sensor %d node %u role %s unit %s R ", i,
                  static_cast<unsigned>(s.node), sensor_role_name(s.role),
                  monitor::kAccelerationUnitNames.name(s.conditioning.unit));
    out += line + matrix_text(s.conditioning.sensor_to_statue) + "\n";
  }
  if (const auto* statue = monitor::built_part<StatueSensorSettings>(config.statue_sensor);
      statue != nullptr && statue->present) {
    std::snprintf(line, sizeof line, "statue node %u height %.9g offset %.9g %.9g R ",
                  static_cast<unsigned>(statue->node), static_cast<double>(statue->height_m),
                  static_cast<double>(statue->offset_x_m), static_cast<double>(statue->offset_y_m));
    out += line + matrix_text(statue->sensor_to_statue) + "\n";
  }
  return out;
}

std::string mounting_sha256(const MonitorConfig& config) {
  return hex(sha256(mounting_text(config)));
}

}  // namespace plinth::firmware

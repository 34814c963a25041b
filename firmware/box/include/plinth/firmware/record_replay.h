// The box fed by a ground motion record in place of its sensors (plinth-monitor --replay R.AT2,
// and the microcontroller image's compiled-in record): one ideal ground sensor whose samples are
// the ground's exact acceleration in the statue's frame, m/s2, after a quiet lead-in during which
// the health tracker recovers and the conditioner estimates the (zero) offset, so that the
// estimators start on the record's first sample. Every build replays a record the same way, so
// their decisions can be compared sample for sample.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "plinth/firmware/monitor.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// The box's start-up window, s: shorter than MonitorConfig's (a replay's quiet lead-in).
inline constexpr double kBoxStartupWindowS = 2.0;

// The box's settings before its configuration file (plinth-monitor's and the microcontroller
// image's): MonitorConfig's, with a kBoxStartupWindowS start-up window for the sensor's offset.
[[nodiscard]] MonitorConfig box_defaults();

// Turns `config` into the record replay's: the sample rate `sample_rate_hz`; a [[sensor]] list
// reduced to its first ground sensor (the single-sensor form); that sensor made ideal (m/s2, no
// mounting rotation, no offset tracking, no stuck-value check, no saturation).
void configure_record_replay(MonitorConfig& config, double sample_rate_hz);

// Samples of quiet input before the record's first (at rest, z reads g): the health tracker's
// recovery and the conditioner's start-up window. `config` as configure_record_replay left it.
[[nodiscard]] std::int64_t record_replay_lead_in(const MonitorConfig& config);

// Monitor time of the record's t = 0, s: the estimators' start.
[[nodiscard]] double record_replay_origin_s(const MonitorConfig& config);

// Input n of the replay: lead-in samples (0, 0, gravity), then the record's sample
// n - lead_in, `ground_m_s2` (z: gravity plus the vertical acceleration), received n sample
// periods after the first.
[[nodiscard]] monitor::SensorSample record_replay_sample(const MonitorConfig& config,
                                                         std::int64_t n,
                                                         const Eigen::Vector3d& ground_m_s2,
                                                         double gravity);

// A statue sensor on a replay (the microcontroller image's load case, plinth-eval run
// --statue-sensor): node 2, its offset estimated over the start-up window, no stuck-value check
// (a replay's rates may be exact: zero at rest).
void configure_replay_statue_sensor(MonitorConfig& config);

// The statue sensor's gyroscope sample n, received with the ground's: rotation rates about the
// sensor axes from each axis's theta' (statue_sensor.h: theta'_0 = -omega_y, theta'_1 =
// omega_x; the sensor mounted in the statue frame).
[[nodiscard]] StatueSample replay_statue_sample(const MonitorConfig& config, std::int64_t n,
                                                Real theta_dot_x, Real theta_dot_y);

}  // namespace plinth::firmware

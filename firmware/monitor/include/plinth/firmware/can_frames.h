// The one map between the monitor's domain types and the CAN protocol's messages
// (hal/can_codec/plinth.dbc): alarm levels and causes (lib/monitor), phases and corners
// (lib/core), sensor flags, and the messages built from them or read into them. The numbering
// of every enumeration is the DBC's, pinned by static_assert in can_frames.cpp, so the enums
// convert value for value. Freestanding.
#pragma once

#include <cstdint>

#include "plinth/core/state.h"
#include "plinth/firmware/box_status.h"
#include "plinth/firmware/statue_sensor.h"
#include "plinth/hal/can_codec.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/regional_alert.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// Domain -> wire.
[[nodiscard]] hal::can::Phase to_wire(Phase phase);
// kNone unless the mode rocks (a mode's corner means nothing outside the rocking phases).
[[nodiscard]] hal::can::Corner wire_corner(const Mode& mode);
[[nodiscard]] hal::can::AlarmLevel to_wire(monitor::AlarmLevel level);
[[nodiscard]] hal::can::AlarmCause to_wire(monitor::AlarmCause cause);

// Wire -> domain. The codec's decode() accepts only values in the DBC's VAL_ tables.
[[nodiscard]] monitor::AlarmLevel from_wire(hal::can::AlarmLevel level);

// The MonitorStatus of axis `axis` of `status`: phase, corner, alarm level, risk, and the age of
// the newest sample the estimate used (65535 ms, the most the frame says, before estimating).
[[nodiscard]] hal::can::MonitorStatus status_message(const BoxStatus& status, int axis,
                                                std::uint8_t sequence);
// The CollapseForecast of axis `axis` of `status`, whose forecast must be valid: probability,
// worst member (none: kNoWorstMember), members, the time from status.time_ns to the worst
// member's collapse (whole ms, 0 when that time has passed, capped at 65534 ms), the horizon
// `horizon_s` and the `sequence` of the MonitorStatus it goes out with.
[[nodiscard]] hal::can::CollapseForecast forecast_message(const BoxStatus& status, int axis,
                                                     double horizon_s, std::uint8_t sequence);
// The AlarmEvent of an alarm policy event: its time in whole ms since start, wrapping after
// 2^32 ms as the frame's counter does.
[[nodiscard]] hal::can::AlarmEvent alarm_event_message(const monitor::AlarmEventRecord& record);
// A SensorAcceleration of node `node` from a sample in g (its flags as they are: the protocol's
// status bits are sensor_flags).
[[nodiscard]] hal::can::SensorAcceleration sensor_message(std::uint8_t node,
                                                     const monitor::SensorSample& sample_g);

// A StatueRotation of node `node` from a gyroscope sample (the statue sensor's, rad/s).
[[nodiscard]] hal::can::StatueRotation rotation_message(std::uint8_t node,
                                                        const StatueSample& sample);

// An operator's Acknowledge as the alarm policy takes it (without its source id).
[[nodiscard]] monitor::Acknowledgement acknowledgement_of(const hal::can::Acknowledge& message);
// A regional alert's two frames as the regional room takes them: the origin frame (received
// `origin_before_s` before the alert frame) and the alert frame, its times relative to the
// alert frame's receipt.
[[nodiscard]] monitor::RegionalAlert regional_alert_of(const hal::can::RegionalAlertOrigin& origin,
                                                       const hal::can::RegionalAlert& alert,
                                                       double origin_before_s);
// A decoded SensorAcceleration as the sensor's health tracker takes it.
[[nodiscard]] monitor::SensorSample sample_of(const hal::can::SensorAcceleration& message,
                                              std::int64_t receive_time_ns);
// A StatueRotation frame as the statue sensor's gyroscope sample (statue_sensor.h).
[[nodiscard]] StatueSample sample_of(const hal::can::StatueRotation& message,
                                     std::int64_t receive_time_ns);

}  // namespace plinth::firmware

// The monitor's alarm vocabulary: levels, their causes and the sensors' status flags. Domain
// types of lib/monitor; the CAN protocol carries them with the same numbering (the mapping and
// its static_asserts: firmware/monitor/src/can_frames.cpp). Freestanding.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "plinth/core/name_table.h"

namespace plinth::monitor {

// Ordered: a higher value is a more severe risk level; fault is trouble with the input.
enum class AlarmLevel : std::uint8_t {
  kNormal = 0,
  kAdvisory = 1,
  kWarning = 2,
  kAlarm = 3,
  kFault = 4,
};

enum class AlarmCause : std::uint8_t {
  kNone = 0,                // level back to normal
  kRiskThreshold = 1,       // overturning risk crossed the level's threshold
  kPhaseChange = 2,         // the block left full contact (sliding or rocking began)
  kOverturnDetected = 3,    // overturned or fell
  kSensorTimeout = 4,       // a sensor's samples stopped arriving
  kSensorFault = 5,         // a sensor reported saturation, self-test failure, ...
  kSensorDisagreement = 6,  // redundant sensors disagree beyond tolerance
  kAcknowledged = 7,        // an operator acknowledged the alarm (latched alarm released)
  kBusError = 8,            // the bus reported errors or dropped frames
  kInternalFault = 9,       // the monitor's own self-check failed
  kCollapseForecast = 10,   // the forecast's probability of a collapse crossed the threshold
  kNotCalibrated = 11,      // no trusted sensor offset or initial state yet: nothing to vouch for
  kOutsideModel = 12,       // the estimate left the model (the block lifted off): nothing to vouch for
  kPWave = 13,              // the P-wave stage's probability of collapse crossed its threshold
  kStatueUnexplained = 14,  // no member of the ensemble explains the statue sensor's motion
  kRegionalAlert = 15,      // a regional alert's probability of collapse crossed its threshold
  // The statue sensor is unhealthy or not corroborated by the ground sensors: its reading may
  // not lower the level (docs/safety.md).
  kStatueSensorFault = 16,
  kRestored = 17,      // a latched level or a collapse restored from the box's saved state
  kStatueStands = 18,  // a person on site stated that the statue stands again
  // The box refuses to vouch: its newest commissioning report failed or is missing
  // (docs/commissioning.md).
  kCommissioningFailed = 19,
};

// The names in status and alarm lines (also the DBC's VAL_ names).
inline constexpr NameTable<AlarmLevel, 5> kAlarmLevelNames{{{
    {AlarmLevel::kNormal, "normal"},
    {AlarmLevel::kAdvisory, "advisory"},
    {AlarmLevel::kWarning, "warning"},
    {AlarmLevel::kAlarm, "alarm"},
    {AlarmLevel::kFault, "fault"},
}}};

inline constexpr NameTable<AlarmCause, 20> kAlarmCauseNames{{{
    {AlarmCause::kNone, "none"},
    {AlarmCause::kRiskThreshold, "risk_threshold"},
    {AlarmCause::kPhaseChange, "phase_change"},
    {AlarmCause::kOverturnDetected, "overturn_detected"},
    {AlarmCause::kSensorTimeout, "sensor_timeout"},
    {AlarmCause::kSensorFault, "sensor_fault"},
    {AlarmCause::kSensorDisagreement, "sensor_disagreement"},
    {AlarmCause::kAcknowledged, "acknowledged"},
    {AlarmCause::kBusError, "bus_error"},
    {AlarmCause::kInternalFault, "internal_fault"},
    {AlarmCause::kCollapseForecast, "collapse_forecast"},
    {AlarmCause::kNotCalibrated, "not_calibrated"},
    {AlarmCause::kOutsideModel, "outside_model"},
    {AlarmCause::kPWave, "p_wave"},
    {AlarmCause::kStatueUnexplained, "statue_unexplained"},
    {AlarmCause::kRegionalAlert, "regional_alert"},
    {AlarmCause::kStatueSensorFault, "statue_sensor_fault"},
    {AlarmCause::kRestored, "restored"},
    {AlarmCause::kStatueStands, "statue_stands"},
    {AlarmCause::kCommissioningFailed, "commissioning_failed"},
}}};

// The levels the risk raises, lowest first (neither normal nor fault): the ones plinth-eval
// scores (lib/host eval_metrics.h).
inline constexpr std::array<AlarmLevel, 3> kRiskLevels{AlarmLevel::kAdvisory, AlarmLevel::kWarning,
                                                       AlarmLevel::kAlarm};
// The position of a risk level in kRiskLevels.
[[nodiscard]] constexpr std::size_t risk_level_index(AlarmLevel level) {
  return static_cast<std::size_t>(level) - static_cast<std::size_t>(AlarmLevel::kAdvisory);
}

[[nodiscard]] constexpr const char* alarm_level_name(AlarmLevel level) {
  return kAlarmLevelNames.name(level);
}
[[nodiscard]] constexpr const char* alarm_cause_name(AlarmCause cause) {
  return kAlarmCauseNames.name(cause);
}

// A sensor's status flags, as it reports them with each sample. Bits 4-7 are undefined.
namespace sensor_flags {
inline constexpr std::uint8_t kSaturated = 1U << 0;           // a sample hit full scale
inline constexpr std::uint8_t kSelfTestFailed = 1U << 1;      // the accelerometer's self-test
inline constexpr std::uint8_t kOverTemperature = 1U << 2;     // outside the rated temperature
inline constexpr std::uint8_t kCalibrationInvalid = 1U << 3;  // no valid calibration stored
inline constexpr std::uint8_t kDefinedMask = 0x0F;
}  // namespace sensor_flags

}  // namespace plinth::monitor

#include "plinth/firmware/can_frames.h"

#include <cmath>

namespace plinth::firmware {

// The CAN protocol (hal/can_codec).
namespace can = hal::can;
namespace {

template <typename Domain, typename Wire>
constexpr bool same_number(Domain domain, Wire wire) {
  return static_cast<unsigned>(domain) == static_cast<unsigned>(wire);
}

// The DBC's VAL_ tables (hal/can_codec/plinth.dbc) against the domain enums, value for value:
// the conversions below are casts.
static_assert(same_number(Phase::kFullContact, can::Phase::kFullContact));
static_assert(same_number(Phase::kSliding, can::Phase::kSliding));
static_assert(same_number(Phase::kRocking, can::Phase::kRocking));
static_assert(same_number(Phase::kSlideRocking, can::Phase::kSlideRocking));
static_assert(same_number(Phase::kOverturned, can::Phase::kOverturned));
static_assert(same_number(Phase::kFell, can::Phase::kFell));
static_assert(same_number(Phase::kLiftedOff, can::Phase::kLiftedOff));
static_assert(same_number(Corner::kLeft, can::Corner::kLeft));
static_assert(same_number(Corner::kRight, can::Corner::kRight));

using monitor::AlarmCause;
using monitor::AlarmLevel;
static_assert(same_number(AlarmLevel::kNormal, can::AlarmLevel::kNormal));
static_assert(same_number(AlarmLevel::kAdvisory, can::AlarmLevel::kAdvisory));
static_assert(same_number(AlarmLevel::kWarning, can::AlarmLevel::kWarning));
static_assert(same_number(AlarmLevel::kAlarm, can::AlarmLevel::kAlarm));
static_assert(same_number(AlarmLevel::kFault, can::AlarmLevel::kFault));
static_assert(monitor::kAlarmLevelNames.size() == 5);  // no level the wire lacks
static_assert(same_number(AlarmCause::kNone, can::AlarmCause::kNone));
static_assert(same_number(AlarmCause::kRiskThreshold, can::AlarmCause::kRiskThreshold));
static_assert(same_number(AlarmCause::kPhaseChange, can::AlarmCause::kPhaseChange));
static_assert(same_number(AlarmCause::kOverturnDetected, can::AlarmCause::kOverturnDetected));
static_assert(same_number(AlarmCause::kSensorTimeout, can::AlarmCause::kSensorTimeout));
static_assert(same_number(AlarmCause::kSensorFault, can::AlarmCause::kSensorFault));
static_assert(same_number(AlarmCause::kSensorDisagreement, can::AlarmCause::kSensorDisagreement));
static_assert(same_number(AlarmCause::kAcknowledged, can::AlarmCause::kAcknowledged));
static_assert(same_number(AlarmCause::kBusError, can::AlarmCause::kBusError));
static_assert(same_number(AlarmCause::kInternalFault, can::AlarmCause::kInternalFault));
static_assert(same_number(AlarmCause::kCollapseForecast, can::AlarmCause::kCollapseForecast));
static_assert(same_number(AlarmCause::kNotCalibrated, can::AlarmCause::kNotCalibrated));
static_assert(same_number(AlarmCause::kOutsideModel, can::AlarmCause::kOutsideModel));
static_assert(same_number(AlarmCause::kPWave, can::AlarmCause::kPWave));
static_assert(same_number(AlarmCause::kStatueUnexplained, can::AlarmCause::kStatueUnexplained));
static_assert(same_number(AlarmCause::kRegionalAlert, can::AlarmCause::kRegionalAlert));
static_assert(same_number(AlarmCause::kStatueSensorFault, can::AlarmCause::kStatueSensorFault));
static_assert(same_number(AlarmCause::kRestored, can::AlarmCause::kRestored));
static_assert(same_number(AlarmCause::kStatueStands, can::AlarmCause::kStatueStands));
static_assert(same_number(AlarmCause::kCommissioningFailed,
                          can::AlarmCause::kCommissioningFailed));
static_assert(monitor::kAlarmCauseNames.size() == 20);

// The sensors' status bits (SensorAcceleration.Status): passed through as they are.
static_assert(monitor::sensor_flags::kSaturated == can::sensor_status::kSaturated);
static_assert(monitor::sensor_flags::kSelfTestFailed == can::sensor_status::kSelfTestFailed);
static_assert(monitor::sensor_flags::kOverTemperature == can::sensor_status::kOverTemperature);
static_assert(monitor::sensor_flags::kCalibrationInvalid ==
              can::sensor_status::kCalibrationInvalid);
static_assert(monitor::sensor_flags::kDefinedMask == can::sensor_status::kDefinedMask);

// The wire's member indices: the largest ensemble this build holds fits the frame's Members.
static_assert(kMaxEnsembleMembers <= can::kMaxForecastMembers);
static_assert(kMaxEnsembleMembers - 1 < can::kNoWorstMember);

constexpr std::int64_t kNanosecondsPerMillisecond = 1'000'000;
constexpr double kLargestCollapseInMs = can::kNoCollapseForecast - 1;  // CollapseIn, 16 bits
constexpr std::int64_t kLargestSampleAgeMs = 65535;  // the frame's SampleAge, 16 bits

}  // namespace

can::Phase to_wire(Phase phase) { return static_cast<can::Phase>(phase); }

can::Corner wire_corner(const Mode& mode) {
  return mode.rocking() ? static_cast<can::Corner>(mode.corner) : can::Corner::kNone;
}

can::AlarmLevel to_wire(monitor::AlarmLevel level) { return static_cast<can::AlarmLevel>(level); }

can::AlarmCause to_wire(monitor::AlarmCause cause) { return static_cast<can::AlarmCause>(cause); }

monitor::AlarmLevel from_wire(can::AlarmLevel level) {
  return static_cast<monitor::AlarmLevel>(level);
}

monitor::RegionalAlert regional_alert_of(const can::RegionalAlertOrigin& origin,
                                         const can::RegionalAlert& alert, double origin_before_s) {
  monitor::RegionalAlert a;
  a.event_id = alert.event_id;
  a.version = alert.version;
  a.cancelled = origin.cancelled;
  a.magnitude = static_cast<Real>(origin.magnitude);
  a.distance_km = static_cast<Real>(origin.distance_km);
  a.origin_age_s = static_cast<Real>(origin.origin_age_s + origin_before_s);
  a.pga_g = static_cast<Real>(alert.pga_g);
  a.sigma_ln = static_cast<Real>(alert.sigma_ln);
  a.s_arrival_in_s = static_cast<Real>(alert.s_arrival_in_s);
  return a;
}

can::MonitorStatus status_message(const BoxStatus& status, int axis, std::uint8_t sequence) {
  const AxisStatus& a = status.axes[static_cast<std::size_t>(axis)];
  can::MonitorStatus m;
  m.axis = static_cast<std::uint8_t>(axis);
  m.phase = to_wire(a.mode.phase);
  m.corner = wire_corner(a.mode);
  m.alarm_level = to_wire(status.alarm);
  m.trouble = status.trouble != monitor::AlarmCause::kNone;
  m.collapse_held = status.collapse.held;
  m.risk = a.risk.total;
  m.sequence = sequence;
  // Not estimating yet: no sample was used, the age is the largest the frame can say.
  const std::int64_t age_ms = status.estimating ? (status.time_ns - status.newest_sample_time_ns) /
                                                      kNanosecondsPerMillisecond
                                                : kLargestSampleAgeMs;
  m.sample_age_ms = static_cast<std::uint16_t>(
      age_ms < 0 ? 0 : (age_ms > kLargestSampleAgeMs ? kLargestSampleAgeMs : age_ms));
  return m;
}

can::CollapseForecast forecast_message(const BoxStatus& status, int axis, double horizon_s,
                                       std::uint8_t sequence) {
  const AxisStatus& a = status.axes[static_cast<std::size_t>(axis)];
  const ForecastOutcome& f = a.forecast;
  can::CollapseForecast m;
  m.axis = static_cast<std::uint8_t>(axis);
  m.probability = f.probability;
  m.members = static_cast<std::uint8_t>(f.members);
  m.horizon_s = horizon_s;
  m.sequence = sequence;
  // None collapses, or too few to show above the frame's resolution: the frame says 0 and
  // names no member (its signals must agree; the status names no collapse time either).
  if (f.worst_member < 0 || a.collapse_forecast_s < 0.0 || std::round(f.probability * 1e4) < 1) {
    m.probability = 0.0;
    return m;
  }
  m.worst_member = static_cast<std::uint8_t>(f.worst_member);
  // From the frame's time (the status's): a collapse forecast for a time now past is due now.
  const double in_ms =
      std::round((a.collapse_forecast_s - static_cast<double>(status.time_ns) * 1e-9) * 1e3);
  m.collapse_in_ms = static_cast<std::uint16_t>(
      in_ms < 0.0 ? 0.0 : (in_ms > kLargestCollapseInMs ? kLargestCollapseInMs : in_ms));
  return m;
}

can::AlarmEvent alarm_event_message(const monitor::AlarmEventRecord& record) {
  can::AlarmEvent event;
  event.level = to_wire(record.level);
  event.previous_level = to_wire(record.previous_level);
  event.cause = to_wire(record.cause);
  event.latched = record.latched;
  event.trouble = record.trouble != monitor::AlarmCause::kNone;
  // Modulo 2^32 ms, as the frame's counter wraps.
  const std::int64_t ms = record.time_ns / kNanosecondsPerMillisecond;
  event.time_since_start_ms = static_cast<std::uint32_t>(static_cast<std::uint64_t>(ms));
  event.sequence = record.sequence;
  return event;
}

can::SensorAcceleration sensor_message(std::uint8_t node, const monitor::SensorSample& sample_g) {
  can::SensorAcceleration m;
  m.node = node;
  m.ax_g = sample_g.acceleration_g.x();
  m.ay_g = sample_g.acceleration_g.y();
  m.az_g = sample_g.acceleration_g.z();
  m.sequence = sample_g.sequence;
  m.status = sample_g.status;
  return m;
}

can::StatueRotation rotation_message(std::uint8_t node, const StatueSample& sample) {
  can::StatueRotation m;
  m.node = node;
  m.wx_rad_s = static_cast<double>(sample.rotation_rate_rad_s.x());
  m.wy_rad_s = static_cast<double>(sample.rotation_rate_rad_s.y());
  m.wz_rad_s = static_cast<double>(sample.rotation_rate_rad_s.z());
  m.sequence = sample.sequence;
  m.status = sample.status;
  return m;
}

monitor::Acknowledgement acknowledgement_of(const can::Acknowledge& message) {
  return {from_wire(message.level), message.event_sequence};
}

monitor::SensorSample sample_of(const can::SensorAcceleration& message,
                                std::int64_t receive_time_ns) {
  monitor::SensorSample sample;
  sample.receive_time_ns = receive_time_ns;
  sample.sequence = message.sequence;
  sample.status = message.status;
  // The codec's physical values are double; the monitor's arithmetic is Real (plinth/core/real.h).
  sample.acceleration_g = Vector3r(static_cast<Real>(message.ax_g), static_cast<Real>(message.ay_g),
                                   static_cast<Real>(message.az_g));
  return sample;
}

StatueSample sample_of(const can::StatueRotation& message, std::int64_t receive_time_ns) {
  StatueSample sample;
  sample.receive_time_ns = receive_time_ns;
  sample.sequence = message.sequence;
  sample.status = message.status;
  sample.rotation_rate_rad_s =
      Vector3r(static_cast<Real>(message.wx_rad_s), static_cast<Real>(message.wy_rad_s),
               static_cast<Real>(message.wz_rad_s));
  return sample;
}

}  // namespace plinth::firmware

// The plinth CAN protocol: frames encoded and decoded without allocation or exceptions.
//
// hal/can_codec/plinth.dbc is the reference: every frame is classic CAN, 8 data bytes, an
// 11-bit standard identifier in 0x300-0x37F, every signal Intel (little-endian) byte order. The
// signal tables below (signal_layouts) carry the DBC's start bit, length, signedness, factor,
// offset and raw range; tests/unit/hal/test_can_codec.cpp checks them against the DBC file.
//
// Encoding refuses what it cannot represent (never clamps): a non-finite value, a value that
// rounds to a raw value outside the signal's DBC range, an enum value outside its VAL_ table,
// status flags the protocol does not define. Decoding refuses a frame whose length is not 8,
// whose identifier is not this message's (or no plinth message's), whose raw values lie outside
// the DBC range or VAL_ table, or whose reserved bits are not zero. A quantity's VAL_ table names
// a special value outside its range ("none"), valid as well. Both refuse a CollapseForecast whose
// signals contradict each other (a worst member beyond the members; "none" in one of
// Probability (0), WorstMember, CollapseIn but not in all). On refusal the output message is
// left untouched.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace plinth::hal::can {

// ---------------------------------------------------------------------------------------------
// Frames and identifiers

inline constexpr std::uint8_t kFrameLength = 8;  // bytes; every plinth frame is 8 bytes long

// One classic CAN data frame. `id` is the 11-bit standard identifier, without any flag bits
// (SocketCAN's CAN_EFF_FLAG / CAN_RTR_FLAG must be stripped or refused by the backend).
struct CanFrame {
  std::uint32_t id = 0;
  std::uint8_t length = 0;  // the data length, 0..8
  std::array<std::uint8_t, 8> data{};
};

// Identifier layout (11 bits): 0b011_KKKK_NNNN, K the message kind, N the sensor node or axis.
inline constexpr std::uint32_t kFirstPlinthId = 0x300;
inline constexpr std::uint32_t kLastPlinthId = 0x37F;
inline constexpr std::uint32_t kSensorAccelerationBaseId = 0x300;  // + node (1..15)
inline constexpr std::uint32_t kSensorHeartbeatBaseId = 0x310;     // + node (1..15)
inline constexpr std::uint32_t kMonitorStatusBaseId = 0x320;       // + axis (0..1)
inline constexpr std::uint32_t kAlarmEventId = 0x330;
inline constexpr std::uint32_t kAcknowledgeId = 0x340;
inline constexpr std::uint32_t kStatueStandsId = 0x341;
inline constexpr std::uint32_t kCollapseForecastBaseId = 0x350;  // + axis (0..1)
// A regional early-warning alert from the integrator's bridge: its origin part, then its
// intensity part (docs/regional.md).
inline constexpr std::uint32_t kRegionalAlertId = 0x360;
inline constexpr std::uint32_t kRegionalAlertOriginId = 0x361;
inline constexpr std::uint32_t kRegionalAlertTagId = 0x362;  // its authentication, when keyed
inline constexpr std::uint32_t kStatueRotationBaseId = 0x370;     // + node (1..15)

inline constexpr std::uint8_t kFirstSensorNode = 1;
inline constexpr std::uint8_t kLastSensorNode = 15;
inline constexpr std::uint8_t kMonitorAxisCount = 2;  // axis 0: first rocking plane, 1: second

enum class MessageKind : std::uint8_t {
  kUnknown,
  kSensorAcceleration,
  kSensorHeartbeat,
  kMonitorStatus,
  kAlarmEvent,
  kAcknowledge,
  kStatueStands,
  kCollapseForecast,
  kStatueRotation,
  kRegionalAlert,
  kRegionalAlertOrigin,
  kRegionalAlertTag,
};

// Which plinth message an identifier carries; kUnknown outside the table (node 0, axis 2, ...).
[[nodiscard]] MessageKind classify(std::uint32_t id);
// The DBC message name without node or axis suffix, e.g. "SensorAcceleration"; "unknown".
[[nodiscard]] const char* message_kind_name(MessageKind kind);

// ---------------------------------------------------------------------------------------------
// Enumerations (the DBC's VAL_ tables)
//
// The wire's numbering only: the names are the domain types' (plinth::Phase and Corner in
// lib/core, monitor::AlarmLevel and AlarmCause in lib/monitor), which firmware/monitor maps to
// and from these (src/can_frames.cpp, numbering pinned by static_assert).

// The block's phase of motion.
enum class Phase : std::uint8_t {
  kFullContact = 0,
  kSliding = 1,
  kRocking = 2,
  kSlideRocking = 3,
  kOverturned = 4,
  kFell = 5,
  kLiftedOff = 6,
};
// The corner the block rocks about; kNone when it does not rock.
enum class Corner : std::uint8_t { kNone = 0, kLeft = 1, kRight = 2 };
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
  kSensorTimeout = 4,       // a sensor node's frames stopped arriving
  kSensorFault = 5,         // a sensor reported saturation, self-test failure, ...
  kSensorDisagreement = 6,  // redundant sensors disagree beyond tolerance
  kAcknowledged = 7,        // an operator acknowledged the alarm (latched alarm released)
  kBusError = 8,            // CAN bus-off or error-passive
  kInternalFault = 9,       // the monitor's own self-check failed
  kCollapseForecast = 10,   // the forecast's probability of a collapse crossed the threshold
  kNotCalibrated = 11,      // no trusted sensor offset or initial state yet
  kOutsideModel = 12,       // the estimate left the model's validity (lift-off)
  kPWave = 13,              // the P-wave stage's probability of collapse crossed its threshold
  kStatueUnexplained = 14,  // no member of the ensemble explains the statue sensor's motion
  kRegionalAlert = 15,      // a regional alert's probability of collapse crossed its threshold
  kStatueSensorFault = 16,  // the statue sensor unhealthy or not corroborated: it may not lower
  kRestored = 17,           // a latched level or a collapse restored after a restart
  kStatueStands = 18,       // a person on site stated that the statue stands again
  kCommissioningFailed = 19,  // the box's commissioning report failed or is missing
};

// Sensor status flags (SensorAcceleration.Status, SensorHeartbeat.Status). Bits 4-7 reserved.
namespace sensor_status {
inline constexpr std::uint8_t kSaturated = 1U << 0;           // a sample hit full scale
inline constexpr std::uint8_t kSelfTestFailed = 1U << 1;      // the accelerometer's self-test
inline constexpr std::uint8_t kOverTemperature = 1U << 2;     // outside the rated temperature
inline constexpr std::uint8_t kCalibrationInvalid = 1U << 3;  // no valid calibration stored
inline constexpr std::uint8_t kDefinedMask = 0x0F;
}  // namespace sensor_status

// ---------------------------------------------------------------------------------------------
// Messages

// 0x300 + node. Acceleration of the sensor in g (9.80665 m/s2), +-8.192 g at 0.25 mg.
struct SensorAcceleration {
  std::uint8_t node = kFirstSensorNode;  // 1..15
  double ax_g = 0.0;
  double ay_g = 0.0;
  double az_g = 0.0;
  std::uint8_t sequence = 0;  // increments by one per frame, wraps 255 -> 0
  std::uint8_t status = 0;    // sensor_status flags
};

// 0x370 + node. The rotation rate of an IMU's gyroscope (the statue sensor) in rad/s,
// right-handed about the sensor axes, +-16.384 rad/s at 0.5 mrad/s. Its accelerometer sends
// SensorAcceleration on the same node, the same sample under the same sequence.
struct StatueRotation {
  std::uint8_t node = kFirstSensorNode;  // 1..15
  double wx_rad_s = 0.0;
  double wy_rad_s = 0.0;
  double wz_rad_s = 0.0;
  std::uint8_t sequence = 0;  // increments by one per frame, wraps 255 -> 0
  std::uint8_t status = 0;    // sensor_status flags
};

// 0x310 + node, about once a second.
struct SensorHeartbeat {
  std::uint8_t node = kFirstSensorNode;  // 1..15
  std::uint32_t uptime_s = 0;
  std::uint8_t firmware_major = 0;  // 0..15
  std::uint8_t firmware_minor = 0;  // 0..15
  std::uint8_t status = 0;          // sensor_status flags
  std::uint8_t can_tx_errors = 0;   // the node's CAN controller transmit error counter
  std::uint8_t can_rx_errors = 0;   // ... receive error counter
};

// 0x320 + axis: the monitor's estimate for one rocking plane.
struct MonitorStatus {
  std::uint8_t axis = 0;  // 0..1
  Phase phase = Phase::kFullContact;
  Corner corner = Corner::kNone;
  AlarmLevel alarm_level = AlarmLevel::kNormal;
  bool trouble = false;        // trouble shown beside the level (a fault, a refused input)
  bool collapse_held = false;  // a collapse is held until a StatueStands
  double risk = 0.0;  // overturning risk, 0..1 (dimensionless), resolution 1e-4
  std::uint8_t sequence = 0;
  std::uint16_t sample_age_ms = 0;  // age of the newest sensor sample the estimate used
};

// 0x330: sent when the alarm level changes.
struct AlarmEvent {
  AlarmLevel level = AlarmLevel::kNormal;
  AlarmLevel previous_level = AlarmLevel::kNormal;
  AlarmCause cause = AlarmCause::kNone;
  bool latched = false;                  // the level holds until acknowledged
  bool trouble = false;                  // trouble shown beside the level after the event
  std::uint32_t time_since_start_ms = 0;  // monitor time, wraps after 2^32 ms (49.7 days)
  std::uint8_t sequence = 0;              // increments by one per event
};

// 0x340: an operator (or supervisory system) acknowledges an alarm.
struct Acknowledge {
  AlarmLevel level = AlarmLevel::kNormal;  // the level acknowledged
  std::uint8_t source_id = 0;              // operator panel / supervisory system id
  std::uint8_t event_sequence = 0;         // AlarmEvent.sequence of the event acknowledged
};

// 0x341: a person on site states that the statue stands again (a held collapse clears).
struct StatueStands {
  std::uint8_t source_id = 0;       // operator panel id
  std::uint8_t event_sequence = 0;  // AlarmEvent.sequence of the latest event seen
};

// 0x350 + axis: the forecast of one rocking plane, sent with its MonitorStatus while the
// monitor forecasts (docs/monitor.md).
inline constexpr std::uint8_t kMaxForecastMembers = 17;       // the ensemble's largest size
inline constexpr std::uint8_t kNoWorstMember = 255;           // WorstMember: no member collapses
inline constexpr std::uint16_t kNoCollapseForecast = 0xFFFF;  // CollapseIn: none forecast
struct CollapseForecast {
  std::uint8_t axis = 0;     // 0..1
  double probability = 0.0;  // of a collapse within the horizon, 0..1, resolution 1e-4
  // The member forecast to collapse first, 0..members-1 (0: the nominal statue), or
  // kNoWorstMember exactly when the probability is 0.
  std::uint8_t worst_member = kNoWorstMember;
  std::uint8_t members = 1;  // the ensemble's size, 1..kMaxForecastMembers
  // ms from the frame's time to that member's forecast collapse (0: due now or overdue),
  // 0..65534; kNoCollapseForecast exactly when worst_member is kNoWorstMember.
  std::uint16_t collapse_in_ms = kNoCollapseForecast;
  double horizon_s = 0.0;     // how far ahead the forecast looks, 0..25.5 s at 0.1 s
  std::uint8_t sequence = 0;  // the MonitorStatus.Sequence it goes out with
};

// 0x361: the origin part of a regional alert (the bridge sends it just before the alert's 0x360
// frame, with the same event and version). Times relative to the frame's sending.
struct RegionalAlertOrigin {
  std::uint16_t event_id = 0;  // the bridge's number for the operator's event
  std::uint8_t version = 0;    // a higher version replaces the event's earlier ones
  double magnitude = 0.0;      // 0..10 at 0.05
  double origin_age_s = 0.0;   // s since the origin time, -655.36..655.34 at 0.02 s
  std::uint16_t distance_km = 0;  // epicentral distance, km, 0..4095
  bool cancelled = false;      // the operator withdrew the event
};

// 0x360: the intensity part of a regional alert; the box takes the alert with it.
struct RegionalAlert {
  std::uint16_t event_id = 0;
  std::uint8_t version = 0;
  double pga_g = 0.0;         // expected PGA at the site (median), g, 0..6.5535 at 1e-4 g
  double sigma_ln = 0.0;      // its lognormal sigma, 0..2.55 at 0.01
  double s_arrival_in_s = 0.0;  // s to the expected S arrival, -327.68..327.67 at 0.01 s
};

// 0x362: a regional alert's authentication, right after its 0x360 frame (docs/regional.md, "Who
// may send an alert"): the bridge's counter and the first 4 bytes of the HMAC-SHA256 of both
// frames' data and the counter.
struct RegionalAlertTag {
  std::uint32_t counter = 0;  // one more for each alert the bridge signs
  std::uint32_t tag = 0;      // the HMAC's bytes 0-3, byte 0 in the low byte (Intel)
};

// ---------------------------------------------------------------------------------------------
// Results

enum class CodecError : std::uint8_t {
  kOk = 0,
  kWrongLength,        // frame length is not 8
  kUnknownIdentifier,  // the identifier is no plinth message
  kWrongMessage,       // a plinth identifier, but of another message than the one asked for
  kNotFinite,          // NaN or infinity to encode
  kOutOfRange,         // outside the signal's DBC range (or node/axis outside its range)
  kInvalidEnum,        // a value missing from the signal's VAL_ table
  kReservedBitsSet,    // reserved frame bits or undefined status flags not zero
};

[[nodiscard]] const char* codec_error_text(CodecError error);

// `signal` is the DBC signal name at fault ("Ax", "Risk", ...), "" when none is.
struct CodecResult {
  CodecError error = CodecError::kOk;
  const char* signal = "";

  [[nodiscard]] constexpr bool ok() const { return error == CodecError::kOk; }
};
using EncodeResult = CodecResult;
using DecodeResult = CodecResult;

// On success `frame` holds id, length 8 and the data; on failure it is left untouched.
[[nodiscard]] EncodeResult encode(const SensorAcceleration& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const SensorHeartbeat& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const MonitorStatus& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const AlarmEvent& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const Acknowledge& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const StatueStands& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const CollapseForecast& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const StatueRotation& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const RegionalAlertOrigin& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const RegionalAlert& message, CanFrame& frame);
[[nodiscard]] EncodeResult encode(const RegionalAlertTag& message, CanFrame& frame);

// On success `message` holds the decoded values (node / axis from the identifier); on failure
// it is left untouched.
[[nodiscard]] DecodeResult decode(const CanFrame& frame, SensorAcceleration& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, SensorHeartbeat& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, MonitorStatus& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, AlarmEvent& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, Acknowledge& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, StatueStands& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, CollapseForecast& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, StatueRotation& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, RegionalAlertOrigin& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, RegionalAlert& message);
[[nodiscard]] DecodeResult decode(const CanFrame& frame, RegionalAlertTag& message);

// ---------------------------------------------------------------------------------------------
// Signal layouts (as in the DBC) and Intel bit packing

// physical = raw * factor + offset; the DBC's [minimum|maximum] is raw_min/raw_max scaled.
struct SignalLayout {
  const char* name;  // the DBC signal name
  std::uint8_t start_bit;
  std::uint8_t length;  // bits
  bool is_signed;
  double factor;
  double offset;
  std::int64_t raw_min;
  std::int64_t raw_max;
  const char* unit;       // the DBC unit string ("" for none)
  bool has_value_table;  // an enumeration: the DBC has a VAL_ table for it
  // A raw value outside raw_min..raw_max that is valid too: the DBC's VAL_ table names it
  // "none" (a quantity's "not available"); kNoSpecialRaw when there is none.
  std::int64_t special_raw;
};
inline constexpr std::int64_t kNoSpecialRaw = INT64_MIN;

// The signals of one message kind in frame order; empty for kUnknown.
[[nodiscard]] std::span<const SignalLayout> signal_layouts(MessageKind kind);

// The frame's 8 data bytes as one little-endian word (byte 0 in bits 0-7), and back.
[[nodiscard]] std::uint64_t load_le64(const std::array<std::uint8_t, 8>& bytes);
void store_le64(std::uint64_t word, std::array<std::uint8_t, 8>& bytes);
// The mask of an Intel signal of `length` bits at `start_bit` within the 64-bit word.
[[nodiscard]] std::uint64_t bit_mask(unsigned start_bit, unsigned length);
// The raw bits of an Intel signal (unsigned), and `raw` placed into `word` at the signal.
[[nodiscard]] std::uint64_t extract_bits(std::uint64_t word, unsigned start_bit, unsigned length);
[[nodiscard]] std::uint64_t insert_bits(std::uint64_t word, unsigned start_bit, unsigned length,
                                        std::uint64_t raw);
// Two's complement sign extension of a `length`-bit raw value.
[[nodiscard]] std::int64_t sign_extend(std::uint64_t raw, unsigned length);

}  // namespace plinth::hal::can

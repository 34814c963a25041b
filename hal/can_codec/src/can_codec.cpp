// The plinth CAN codec: table-driven Intel bit packing of the frames in plinth.dbc.
#include "plinth/hal/can_codec.h"

#include <cmath>

#include "plinth/core/name_table.h"

namespace plinth::hal::can {

namespace {

// ---------------------------------------------------------------------------------------------
// Signal tables: one row per DBC SG_ line (tests/unit/hal/test_can_codec.cpp compares them).

constexpr std::int64_t kU8Max = 255;
constexpr std::int64_t kU16Max = 65535;
constexpr std::int64_t kU32Max = 4294967295;

// SensorAcceleration (0x300 + node)
enum AccelerationSignal : std::size_t { kAx, kAy, kAz, kAccSequence, kAccStatus };
constexpr std::array<SignalLayout, 5> kAccelerationSignals{{
    {"Ax", 0, 16, true, 0.00025, 0.0, -32768, 32767, "g", false, kNoSpecialRaw},
    {"Ay", 16, 16, true, 0.00025, 0.0, -32768, 32767, "g", false, kNoSpecialRaw},
    {"Az", 32, 16, true, 0.00025, 0.0, -32768, 32767, "g", false, kNoSpecialRaw},
    {"Sequence", 48, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"Status", 56, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
}};

// StatueRotation (0x370 + node): SensorAcceleration's layout, rates for accelerations.
enum RotationSignal : std::size_t { kWx, kWy, kWz, kRotSequence, kRotStatus };
constexpr std::array<SignalLayout, 5> kRotationSignals{{
    {"Wx", 0, 16, true, 0.0005, 0.0, -32768, 32767, "rad/s", false, kNoSpecialRaw},
    {"Wy", 16, 16, true, 0.0005, 0.0, -32768, 32767, "rad/s", false, kNoSpecialRaw},
    {"Wz", 32, 16, true, 0.0005, 0.0, -32768, 32767, "rad/s", false, kNoSpecialRaw},
    {"Sequence", 48, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"Status", 56, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
}};

// SensorHeartbeat (0x310 + node)
enum HeartbeatSignal : std::size_t {
  kUptime,
  kFirmwareMajor,
  kFirmwareMinor,
  kHbStatus,
  kCanTxErrors,
  kCanRxErrors
};
constexpr std::array<SignalLayout, 6> kHeartbeatSignals{{
    {"Uptime", 0, 32, false, 1.0, 0.0, 0, kU32Max, "s", false, kNoSpecialRaw},
    {"FirmwareMajor", 32, 4, false, 1.0, 0.0, 0, 15, "", false, kNoSpecialRaw},
    {"FirmwareMinor", 36, 4, false, 1.0, 0.0, 0, 15, "", false, kNoSpecialRaw},
    {"Status", 40, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"CanTxErrors", 48, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"CanRxErrors", 56, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
}};

// MonitorStatus (0x320 + axis)
enum StatusSignal : std::size_t {
  kPhase,
  kCorner,
  kAlarmLevel,
  kStTrouble,
  kCollapseHeld,
  kRisk,
  kStSequence,
  kSampleAge
};
constexpr std::array<SignalLayout, 8> kStatusSignals{{
    {"Phase", 0, 4, false, 1.0, 0.0, 0, 6, "", true, kNoSpecialRaw},
    {"Corner", 4, 4, false, 1.0, 0.0, 0, 2, "", true, kNoSpecialRaw},
    {"AlarmLevel", 8, 4, false, 1.0, 0.0, 0, 4, "", true, kNoSpecialRaw},
    {"Trouble", 12, 1, false, 1.0, 0.0, 0, 1, "", false, kNoSpecialRaw},
    {"CollapseHeld", 13, 1, false, 1.0, 0.0, 0, 1, "", false, kNoSpecialRaw},
    {"Risk", 16, 16, false, 0.0001, 0.0, 0, 10000, "", false, kNoSpecialRaw},
    {"Sequence", 32, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"SampleAge", 40, 16, false, 1.0, 0.0, 0, kU16Max, "ms", false, kNoSpecialRaw},
}};

// AlarmEvent (0x330)
enum EventSignal : std::size_t {
  kLevel,
  kPreviousLevel,
  kCause,
  kLatched,
  kEvTrouble,
  kTime,
  kEvSequence
};
constexpr std::array<SignalLayout, 7> kEventSignals{{
    {"Level", 0, 4, false, 1.0, 0.0, 0, 4, "", true, kNoSpecialRaw},
    {"PreviousLevel", 4, 4, false, 1.0, 0.0, 0, 4, "", true, kNoSpecialRaw},
    {"Cause", 8, 8, false, 1.0, 0.0, 0, 19, "", true, kNoSpecialRaw},
    {"Latched", 16, 1, false, 1.0, 0.0, 0, 1, "", true, kNoSpecialRaw},
    {"Trouble", 17, 1, false, 1.0, 0.0, 0, 1, "", false, kNoSpecialRaw},
    {"TimeSinceStart", 24, 32, false, 1.0, 0.0, 0, kU32Max, "ms", false, kNoSpecialRaw},
    {"Sequence", 56, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
}};

// Acknowledge (0x340)
enum AcknowledgeSignal : std::size_t { kAckLevel, kSourceId, kEventSequence };
constexpr std::array<SignalLayout, 3> kAcknowledgeSignals{{
    {"Level", 0, 4, false, 1.0, 0.0, 0, 4, "", true, kNoSpecialRaw},
    {"SourceId", 8, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"EventSequence", 16, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
}};

// StatueStands (0x341)
enum StandsSignal : std::size_t { kStandsSourceId, kStandsEventSequence };
constexpr std::array<SignalLayout, 2> kStandsSignals{{
    {"SourceId", 0, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"EventSequence", 8, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
}};

// CollapseForecast (0x350 + axis)
enum ForecastSignal : std::size_t {
  kProbability,
  kWorstMember,
  kMembers,
  kCollapseIn,
  kHorizon,
  kFcSequence
};
constexpr std::array<SignalLayout, 6> kForecastSignals{{
    {"Probability", 0, 16, false, 0.0001, 0.0, 0, 10000, "", false, kNoSpecialRaw},
    {"WorstMember", 16, 8, false, 1.0, 0.0, 0, kMaxForecastMembers - 1, "", false, kNoWorstMember},
    {"Members", 24, 8, false, 1.0, 0.0, 1, kMaxForecastMembers, "", false, kNoSpecialRaw},
    {"CollapseIn", 32, 16, false, 1.0, 0.0, 0, kU16Max - 1, "ms", false, kNoCollapseForecast},
    {"Horizon", 48, 8, false, 0.1, 0.0, 0, kU8Max, "s", false, kNoSpecialRaw},
    {"Sequence", 56, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
}};

// RegionalAlertOrigin (0x361)
enum OriginSignal : std::size_t {
  kOrEventId,
  kOrVersion,
  kMagnitude,
  kOriginAge,
  kDistance,
  kCancelled
};
constexpr std::array<SignalLayout, 6> kOriginSignals{{
    {"EventId", 0, 16, false, 1.0, 0.0, 0, kU16Max, "", false, kNoSpecialRaw},
    {"Version", 16, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"Magnitude", 24, 8, false, 0.05, 0.0, 0, 200, "", false, kNoSpecialRaw},
    {"OriginAge", 32, 16, true, 0.02, 0.0, -32768, 32767, "s", false, kNoSpecialRaw},
    {"Distance", 48, 12, false, 1.0, 0.0, 0, 4095, "km", false, kNoSpecialRaw},
    {"Cancelled", 60, 1, false, 1.0, 0.0, 0, 1, "", true, kNoSpecialRaw},
}};

// RegionalAlert (0x360)
enum RegionalSignal : std::size_t { kRaEventId, kRaVersion, kPga, kSigmaLn, kSArrivalIn };
constexpr std::array<SignalLayout, 5> kRegionalSignals{{
    {"EventId", 0, 16, false, 1.0, 0.0, 0, kU16Max, "", false, kNoSpecialRaw},
    {"Version", 16, 8, false, 1.0, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"Pga", 24, 16, false, 0.0001, 0.0, 0, kU16Max, "g", false, kNoSpecialRaw},
    {"SigmaLn", 40, 8, false, 0.01, 0.0, 0, kU8Max, "", false, kNoSpecialRaw},
    {"SArrivalIn", 48, 16, true, 0.01, 0.0, -32768, 32767, "s", false, kNoSpecialRaw},
}};

// RegionalAlertTag (0x362)
enum TagSignal : std::size_t { kCounter, kTag };
constexpr std::array<SignalLayout, 2> kTagSignals{{
    {"Counter", 0, 32, false, 1.0, 0.0, 0, kU32Max, "", false, kNoSpecialRaw},
    {"Tag", 32, 32, false, 1.0, 0.0, 0, kU32Max, "", false, kNoSpecialRaw},
}};

// ---------------------------------------------------------------------------------------------
// Packing with the first error kept.

// Inside the signal's DBC range, or its special value.
constexpr bool valid_raw(std::int64_t raw, const SignalLayout& signal) {
  return (raw >= signal.raw_min && raw <= signal.raw_max) ||
         (signal.special_raw != kNoSpecialRaw && raw == signal.special_raw);
}

// |raw| below this converts to int64 exactly and safely (2^53).
constexpr double kMaxConvertible = 9007199254740992.0;

class Packer {
 public:
  void physical(double value, const SignalLayout& signal) {
    if (!result_.ok()) return;
    if (!std::isfinite(value)) {
      fail(CodecError::kNotFinite, signal);
      return;
    }
    const double scaled = (value - signal.offset) / signal.factor;
    if (!(std::fabs(scaled) < kMaxConvertible)) {
      fail(CodecError::kOutOfRange, signal);
      return;
    }
    // Round half away from zero, independent of the floating-point environment.
    const auto raw = static_cast<std::int64_t>(std::llround(scaled));
    put(raw, signal, CodecError::kOutOfRange);
  }

  void integer(std::uint64_t value, const SignalLayout& signal) {
    if (!result_.ok()) return;
    if (value > static_cast<std::uint64_t>(signal.raw_max) &&
        !(signal.special_raw != kNoSpecialRaw &&
          value == static_cast<std::uint64_t>(signal.special_raw))) {
      fail(CodecError::kOutOfRange, signal);
      return;
    }
    put(static_cast<std::int64_t>(value), signal, CodecError::kOutOfRange);
  }

  template <typename Enum>
  void enumeration(Enum value, const SignalLayout& signal) {
    if (!result_.ok()) return;
    put(static_cast<std::int64_t>(value), signal, CodecError::kInvalidEnum);
  }

  void fail(CodecError error, const char* signal) {
    if (result_.ok()) result_ = CodecResult{error, signal};
  }

  EncodeResult finish(std::uint32_t id, CanFrame& frame) const {
    if (!result_.ok()) return result_;
    frame.id = id;
    frame.length = kFrameLength;
    store_le64(word_, frame.data);
    return result_;
  }

 private:
  void fail(CodecError error, const SignalLayout& signal) { fail(error, signal.name); }

  void put(std::int64_t raw, const SignalLayout& signal, CodecError out_of_range) {
    if (!valid_raw(raw, signal)) {
      fail(out_of_range, signal);
      return;
    }
    word_ = insert_bits(word_, signal.start_bit, signal.length, static_cast<std::uint64_t>(raw));
  }

  std::uint64_t word_ = 0;
  CodecResult result_{};
};

class Unpacker {
 public:
  Unpacker(const CanFrame& frame, MessageKind expected, std::span<const SignalLayout> signals)
      : word_(load_le64(frame.data)) {
    const MessageKind kind = classify(frame.id);
    if (kind == MessageKind::kUnknown) {
      result_ = CodecResult{CodecError::kUnknownIdentifier, ""};
    } else if (kind != expected) {
      result_ = CodecResult{CodecError::kWrongMessage, ""};
    } else if (frame.length != kFrameLength) {
      result_ = CodecResult{CodecError::kWrongLength, ""};
    } else {
      std::uint64_t used = 0;
      for (const SignalLayout& s : signals) used |= bit_mask(s.start_bit, s.length);
      if ((word_ & ~used) != 0) result_ = CodecResult{CodecError::kReservedBitsSet, ""};
    }
  }

  double physical(const SignalLayout& signal) {
    return static_cast<double>(raw(signal, CodecError::kOutOfRange)) * signal.factor +
           signal.offset;
  }

  template <typename Integer>
  Integer integer(const SignalLayout& signal) {
    return static_cast<Integer>(raw(signal, CodecError::kOutOfRange));
  }

  template <typename Enum>
  Enum enumeration(const SignalLayout& signal) {
    return static_cast<Enum>(raw(signal, CodecError::kInvalidEnum));
  }

  void fail(CodecError error, const char* signal) {
    if (result_.ok()) result_ = CodecResult{error, signal};
  }

  [[nodiscard]] const CodecResult& result() const { return result_; }

 private:
  // The raw value, 0 (and the error recorded) when it lies outside the DBC range.
  std::int64_t raw(const SignalLayout& signal, CodecError out_of_range) {
    if (!result_.ok()) return 0;
    const std::uint64_t bits = extract_bits(word_, signal.start_bit, signal.length);
    const std::int64_t value =
        signal.is_signed ? sign_extend(bits, signal.length) : static_cast<std::int64_t>(bits);
    if (!valid_raw(value, signal)) {
      fail(out_of_range, signal.name);
      return 0;
    }
    return value;
  }

  std::uint64_t word_;
  CodecResult result_{};
};

constexpr bool undefined_status_flags(std::uint8_t status) {
  return (status & static_cast<std::uint8_t>(~sensor_status::kDefinedMask)) != 0;
}

// The DBC message names, without node or axis suffix.
constexpr NameTable<MessageKind, 11> kMessageKindNames{{{
    {MessageKind::kSensorAcceleration, "SensorAcceleration"},
    {MessageKind::kSensorHeartbeat, "SensorHeartbeat"},
    {MessageKind::kMonitorStatus, "MonitorStatus"},
    {MessageKind::kAlarmEvent, "AlarmEvent"},
    {MessageKind::kAcknowledge, "Acknowledge"},
    {MessageKind::kStatueStands, "StatueStands"},
    {MessageKind::kCollapseForecast, "CollapseForecast"},
    {MessageKind::kStatueRotation, "StatueRotation"},
    {MessageKind::kRegionalAlert, "RegionalAlert"},
    {MessageKind::kRegionalAlertOrigin, "RegionalAlertOrigin"},
    {MessageKind::kRegionalAlertTag, "RegionalAlertTag"},
}}};

constexpr NameTable<CodecError, 8> kCodecErrorTexts{{{
    {CodecError::kOk, "ok"},
    {CodecError::kWrongLength, "frame length is not 8 bytes"},
    {CodecError::kUnknownIdentifier, "identifier is not a plinth message"},
    {CodecError::kWrongMessage, "identifier belongs to another message"},
    {CodecError::kNotFinite, "value is NaN or infinite"},
    {CodecError::kOutOfRange, "value outside the signal's range"},
    {CodecError::kInvalidEnum, "value not in the signal's value table"},
    {CodecError::kReservedBitsSet, "reserved bits or undefined flags set"},
}}};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Identifiers and names

MessageKind classify(std::uint32_t id) {
  if (id < kFirstPlinthId || id > kLastPlinthId) return MessageKind::kUnknown;
  const std::uint32_t group = id & 0x7F0U;
  const std::uint32_t index = id & 0x00FU;
  switch (group) {
    case kSensorAccelerationBaseId:
      return index >= kFirstSensorNode ? MessageKind::kSensorAcceleration : MessageKind::kUnknown;
    case kSensorHeartbeatBaseId:
      return index >= kFirstSensorNode ? MessageKind::kSensorHeartbeat : MessageKind::kUnknown;
    case kMonitorStatusBaseId:
      return index < kMonitorAxisCount ? MessageKind::kMonitorStatus : MessageKind::kUnknown;
    case kAlarmEventId:
      return index == 0 ? MessageKind::kAlarmEvent : MessageKind::kUnknown;
    case kAcknowledgeId:
      return index == 0   ? MessageKind::kAcknowledge
             : index == 1 ? MessageKind::kStatueStands
                          : MessageKind::kUnknown;
    case kCollapseForecastBaseId:
      return index < kMonitorAxisCount ? MessageKind::kCollapseForecast : MessageKind::kUnknown;
    case kStatueRotationBaseId:
      return index >= kFirstSensorNode ? MessageKind::kStatueRotation : MessageKind::kUnknown;
    case kRegionalAlertId:
      return index == 0   ? MessageKind::kRegionalAlert
             : index == 1 ? MessageKind::kRegionalAlertOrigin
             : index == 2 ? MessageKind::kRegionalAlertTag
                          : MessageKind::kUnknown;
    default:
      return MessageKind::kUnknown;
  }
}

const char* message_kind_name(MessageKind kind) { return kMessageKindNames.name(kind, "unknown"); }

const char* codec_error_text(CodecError error) {
  return kCodecErrorTexts.name(error, "unknown error");
}

std::span<const SignalLayout> signal_layouts(MessageKind kind) {
  switch (kind) {
    case MessageKind::kSensorAcceleration: return kAccelerationSignals;
    case MessageKind::kSensorHeartbeat: return kHeartbeatSignals;
    case MessageKind::kMonitorStatus: return kStatusSignals;
    case MessageKind::kAlarmEvent: return kEventSignals;
    case MessageKind::kAcknowledge: return kAcknowledgeSignals;
    case MessageKind::kStatueStands: return kStandsSignals;
    case MessageKind::kCollapseForecast: return kForecastSignals;
    case MessageKind::kStatueRotation: return kRotationSignals;
    case MessageKind::kRegionalAlert: return kRegionalSignals;
    case MessageKind::kRegionalAlertOrigin: return kOriginSignals;
    case MessageKind::kRegionalAlertTag: return kTagSignals;
    case MessageKind::kUnknown: break;
  }
  return {};
}

// ---------------------------------------------------------------------------------------------
// Intel bit packing

std::uint64_t load_le64(const std::array<std::uint8_t, 8>& bytes) {
  std::uint64_t word = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    word |= static_cast<std::uint64_t>(bytes[i]) << (8U * i);
  }
  return word;
}

void store_le64(std::uint64_t word, std::array<std::uint8_t, 8>& bytes) {
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    bytes[i] = static_cast<std::uint8_t>(word >> (8U * i));
  }
}

std::uint64_t bit_mask(unsigned start_bit, unsigned length) {
  if (length == 0 || start_bit >= 64) return 0;
  const std::uint64_t low = length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1U;
  return low << start_bit;
}

std::uint64_t extract_bits(std::uint64_t word, unsigned start_bit, unsigned length) {
  if (start_bit >= 64) return 0;
  return (word & bit_mask(start_bit, length)) >> start_bit;
}

std::uint64_t insert_bits(std::uint64_t word, unsigned start_bit, unsigned length,
                          std::uint64_t raw) {
  if (start_bit >= 64) return word;
  const std::uint64_t mask = bit_mask(start_bit, length);
  return (word & ~mask) | ((raw << start_bit) & mask);
}

std::int64_t sign_extend(std::uint64_t raw, unsigned length) {
  if (length == 0 || length >= 64) return static_cast<std::int64_t>(raw);
  const std::uint64_t sign = std::uint64_t{1} << (length - 1U);
  const std::uint64_t value = raw & ((std::uint64_t{1} << length) - 1U);
  // (value ^ sign) - sign: two's complement of `length` bits, without signed overflow.
  return static_cast<std::int64_t>((value ^ sign) - sign);
}

// ---------------------------------------------------------------------------------------------
// Messages

namespace {

// A node's sample (SensorAcceleration, StatueRotation): three signed values, the sequence and
// the status flags, in the signals' order.
struct NodeSample {
  std::uint8_t node = kFirstSensorNode;
  std::array<double, 3> values{};
  std::uint8_t sequence = 0;
  std::uint8_t status = 0;
};

EncodeResult encode_node_sample(const NodeSample& m, std::span<const SignalLayout> s,
                                std::uint32_t base_id, CanFrame& frame) {
  Packer packer;
  if (m.node < kFirstSensorNode || m.node > kLastSensorNode) {
    packer.fail(CodecError::kOutOfRange, "node");
  }
  for (std::size_t i = 0; i < 3; ++i) packer.physical(m.values[i], s[i]);
  packer.integer(m.sequence, s[3]);
  if (undefined_status_flags(m.status)) packer.fail(CodecError::kReservedBitsSet, "Status");
  packer.integer(m.status, s[4]);
  return packer.finish(base_id + m.node, frame);
}

DecodeResult decode_node_sample(const CanFrame& frame, MessageKind kind,
                                std::span<const SignalLayout> s, std::uint32_t base_id,
                                NodeSample& m) {
  Unpacker unpacker(frame, kind, s);
  m.node = static_cast<std::uint8_t>(frame.id - base_id);
  for (std::size_t i = 0; i < 3; ++i) m.values[i] = unpacker.physical(s[i]);
  m.sequence = unpacker.integer<std::uint8_t>(s[3]);
  m.status = unpacker.integer<std::uint8_t>(s[4]);
  if (undefined_status_flags(m.status)) unpacker.fail(CodecError::kReservedBitsSet, "Status");
  return unpacker.result();
}

static_assert(kAx == 0 && kAy == 1 && kAz == 2 && kAccSequence == 3 && kAccStatus == 4);
static_assert(kWx == 0 && kWy == 1 && kWz == 2 && kRotSequence == 3 && kRotStatus == 4);

}  // namespace

EncodeResult encode(const SensorAcceleration& message, CanFrame& frame) {
  return encode_node_sample(
      {message.node, {message.ax_g, message.ay_g, message.az_g}, message.sequence, message.status},
      kAccelerationSignals, kSensorAccelerationBaseId, frame);
}

DecodeResult decode(const CanFrame& frame, SensorAcceleration& message) {
  NodeSample m;
  const DecodeResult r = decode_node_sample(frame, MessageKind::kSensorAcceleration,
                                            kAccelerationSignals, kSensorAccelerationBaseId, m);
  if (r.ok()) message = {m.node, m.values[0], m.values[1], m.values[2], m.sequence, m.status};
  return r;
}

EncodeResult encode(const StatueRotation& message, CanFrame& frame) {
  return encode_node_sample({message.node,
                             {message.wx_rad_s, message.wy_rad_s, message.wz_rad_s},
                             message.sequence,
                             message.status},
                            kRotationSignals, kStatueRotationBaseId, frame);
}

DecodeResult decode(const CanFrame& frame, StatueRotation& message) {
  NodeSample m;
  const DecodeResult r = decode_node_sample(frame, MessageKind::kStatueRotation, kRotationSignals,
                                            kStatueRotationBaseId, m);
  if (r.ok()) message = {m.node, m.values[0], m.values[1], m.values[2], m.sequence, m.status};
  return r;
}

EncodeResult encode(const SensorHeartbeat& message, CanFrame& frame) {
  const auto& s = kHeartbeatSignals;
  Packer packer;
  if (message.node < kFirstSensorNode || message.node > kLastSensorNode) {
    packer.fail(CodecError::kOutOfRange, "node");
  }
  packer.integer(message.uptime_s, s[kUptime]);
  packer.integer(message.firmware_major, s[kFirmwareMajor]);
  packer.integer(message.firmware_minor, s[kFirmwareMinor]);
  if (undefined_status_flags(message.status)) packer.fail(CodecError::kReservedBitsSet, "Status");
  packer.integer(message.status, s[kHbStatus]);
  packer.integer(message.can_tx_errors, s[kCanTxErrors]);
  packer.integer(message.can_rx_errors, s[kCanRxErrors]);
  return packer.finish(kSensorHeartbeatBaseId + message.node, frame);
}

DecodeResult decode(const CanFrame& frame, SensorHeartbeat& message) {
  const auto& s = kHeartbeatSignals;
  Unpacker unpacker(frame, MessageKind::kSensorHeartbeat, s);
  SensorHeartbeat m;
  m.node = static_cast<std::uint8_t>(frame.id - kSensorHeartbeatBaseId);
  m.uptime_s = unpacker.integer<std::uint32_t>(s[kUptime]);
  m.firmware_major = unpacker.integer<std::uint8_t>(s[kFirmwareMajor]);
  m.firmware_minor = unpacker.integer<std::uint8_t>(s[kFirmwareMinor]);
  m.status = unpacker.integer<std::uint8_t>(s[kHbStatus]);
  if (undefined_status_flags(m.status)) unpacker.fail(CodecError::kReservedBitsSet, "Status");
  m.can_tx_errors = unpacker.integer<std::uint8_t>(s[kCanTxErrors]);
  m.can_rx_errors = unpacker.integer<std::uint8_t>(s[kCanRxErrors]);
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

EncodeResult encode(const MonitorStatus& message, CanFrame& frame) {
  const auto& s = kStatusSignals;
  Packer packer;
  if (message.axis >= kMonitorAxisCount) packer.fail(CodecError::kOutOfRange, "axis");
  packer.enumeration(message.phase, s[kPhase]);
  packer.enumeration(message.corner, s[kCorner]);
  packer.enumeration(message.alarm_level, s[kAlarmLevel]);
  packer.integer(message.trouble ? 1U : 0U, s[kStTrouble]);
  packer.integer(message.collapse_held ? 1U : 0U, s[kCollapseHeld]);
  packer.physical(message.risk, s[kRisk]);
  packer.integer(message.sequence, s[kStSequence]);
  packer.integer(message.sample_age_ms, s[kSampleAge]);
  return packer.finish(kMonitorStatusBaseId + message.axis, frame);
}

DecodeResult decode(const CanFrame& frame, MonitorStatus& message) {
  const auto& s = kStatusSignals;
  Unpacker unpacker(frame, MessageKind::kMonitorStatus, s);
  MonitorStatus m;
  m.axis = static_cast<std::uint8_t>(frame.id - kMonitorStatusBaseId);
  m.phase = unpacker.enumeration<Phase>(s[kPhase]);
  m.corner = unpacker.enumeration<Corner>(s[kCorner]);
  m.alarm_level = unpacker.enumeration<AlarmLevel>(s[kAlarmLevel]);
  m.trouble = unpacker.integer<std::uint8_t>(s[kStTrouble]) != 0;
  m.collapse_held = unpacker.integer<std::uint8_t>(s[kCollapseHeld]) != 0;
  m.risk = unpacker.physical(s[kRisk]);
  m.sequence = unpacker.integer<std::uint8_t>(s[kStSequence]);
  m.sample_age_ms = unpacker.integer<std::uint16_t>(s[kSampleAge]);
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

EncodeResult encode(const AlarmEvent& message, CanFrame& frame) {
  const auto& s = kEventSignals;
  Packer packer;
  packer.enumeration(message.level, s[kLevel]);
  packer.enumeration(message.previous_level, s[kPreviousLevel]);
  packer.enumeration(message.cause, s[kCause]);
  packer.integer(message.latched ? 1U : 0U, s[kLatched]);
  packer.integer(message.trouble ? 1U : 0U, s[kEvTrouble]);
  packer.integer(message.time_since_start_ms, s[kTime]);
  packer.integer(message.sequence, s[kEvSequence]);
  return packer.finish(kAlarmEventId, frame);
}

DecodeResult decode(const CanFrame& frame, AlarmEvent& message) {
  const auto& s = kEventSignals;
  Unpacker unpacker(frame, MessageKind::kAlarmEvent, s);
  AlarmEvent m;
  m.level = unpacker.enumeration<AlarmLevel>(s[kLevel]);
  m.previous_level = unpacker.enumeration<AlarmLevel>(s[kPreviousLevel]);
  m.cause = unpacker.enumeration<AlarmCause>(s[kCause]);
  m.latched = unpacker.integer<std::uint8_t>(s[kLatched]) != 0;
  m.trouble = unpacker.integer<std::uint8_t>(s[kEvTrouble]) != 0;
  m.time_since_start_ms = unpacker.integer<std::uint32_t>(s[kTime]);
  m.sequence = unpacker.integer<std::uint8_t>(s[kEvSequence]);
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

EncodeResult encode(const Acknowledge& message, CanFrame& frame) {
  const auto& s = kAcknowledgeSignals;
  Packer packer;
  packer.enumeration(message.level, s[kAckLevel]);
  packer.integer(message.source_id, s[kSourceId]);
  packer.integer(message.event_sequence, s[kEventSequence]);
  return packer.finish(kAcknowledgeId, frame);
}

DecodeResult decode(const CanFrame& frame, Acknowledge& message) {
  const auto& s = kAcknowledgeSignals;
  Unpacker unpacker(frame, MessageKind::kAcknowledge, s);
  Acknowledge m;
  m.level = unpacker.enumeration<AlarmLevel>(s[kAckLevel]);
  m.source_id = unpacker.integer<std::uint8_t>(s[kSourceId]);
  m.event_sequence = unpacker.integer<std::uint8_t>(s[kEventSequence]);
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

EncodeResult encode(const StatueStands& message, CanFrame& frame) {
  const auto& s = kStandsSignals;
  Packer packer;
  packer.integer(message.source_id, s[kStandsSourceId]);
  packer.integer(message.event_sequence, s[kStandsEventSequence]);
  return packer.finish(kStatueStandsId, frame);
}

DecodeResult decode(const CanFrame& frame, StatueStands& message) {
  const auto& s = kStandsSignals;
  Unpacker unpacker(frame, MessageKind::kStatueStands, s);
  StatueStands m;
  m.source_id = unpacker.integer<std::uint8_t>(s[kStandsSourceId]);
  m.event_sequence = unpacker.integer<std::uint8_t>(s[kStandsEventSequence]);
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

namespace {

// The signals of a CollapseForecast that must agree: the worst member is one of the members, and
// "none collapses" is said by all of Probability (raw 0), WorstMember and CollapseIn or by none.
CodecResult contradiction(const CollapseForecast& m, bool probability_zero) {
  const bool none = m.worst_member == kNoWorstMember;
  if (!none && m.worst_member >= m.members) return {CodecError::kOutOfRange, "WorstMember"};
  if (none != (m.collapse_in_ms == kNoCollapseForecast)) {
    return {CodecError::kOutOfRange, "CollapseIn"};
  }
  if (none != probability_zero) return {CodecError::kOutOfRange, "Probability"};
  return {};
}

// Whether `value` encodes to raw 0 (a value that does not encode at all is refused elsewhere).
bool encodes_to_zero(double value, const SignalLayout& signal) {
  const double scaled = (value - signal.offset) / signal.factor;
  return std::isfinite(scaled) && std::fabs(scaled) < 1.0 && std::llround(scaled) == 0;
}

}  // namespace

EncodeResult encode(const CollapseForecast& message, CanFrame& frame) {
  const auto& s = kForecastSignals;
  Packer packer;
  if (message.axis >= kMonitorAxisCount) packer.fail(CodecError::kOutOfRange, "axis");
  packer.physical(message.probability, s[kProbability]);
  packer.integer(message.worst_member, s[kWorstMember]);
  packer.integer(message.members, s[kMembers]);
  packer.integer(message.collapse_in_ms, s[kCollapseIn]);
  packer.physical(message.horizon_s, s[kHorizon]);
  packer.integer(message.sequence, s[kFcSequence]);
  const CodecResult agree =
      contradiction(message, encodes_to_zero(message.probability, s[kProbability]));
  if (!agree.ok()) packer.fail(agree.error, agree.signal);
  return packer.finish(kCollapseForecastBaseId + message.axis, frame);
}

DecodeResult decode(const CanFrame& frame, CollapseForecast& message) {
  const auto& s = kForecastSignals;
  Unpacker unpacker(frame, MessageKind::kCollapseForecast, s);
  CollapseForecast m;
  m.axis = static_cast<std::uint8_t>(frame.id - kCollapseForecastBaseId);
  m.probability = unpacker.physical(s[kProbability]);
  m.worst_member = unpacker.integer<std::uint8_t>(s[kWorstMember]);
  m.members = unpacker.integer<std::uint8_t>(s[kMembers]);
  m.collapse_in_ms = unpacker.integer<std::uint16_t>(s[kCollapseIn]);
  m.horizon_s = unpacker.physical(s[kHorizon]);
  m.sequence = unpacker.integer<std::uint8_t>(s[kFcSequence]);
  if (unpacker.result().ok()) {
    const CodecResult agree = contradiction(m, m.probability == 0.0);
    if (!agree.ok()) unpacker.fail(agree.error, agree.signal);
  }
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

EncodeResult encode(const RegionalAlertOrigin& message, CanFrame& frame) {
  const auto& s = kOriginSignals;
  Packer packer;
  packer.integer(message.event_id, s[kOrEventId]);
  packer.integer(message.version, s[kOrVersion]);
  packer.physical(message.magnitude, s[kMagnitude]);
  packer.physical(message.origin_age_s, s[kOriginAge]);
  packer.integer(message.distance_km, s[kDistance]);
  packer.integer(message.cancelled ? 1U : 0U, s[kCancelled]);
  return packer.finish(kRegionalAlertOriginId, frame);
}

DecodeResult decode(const CanFrame& frame, RegionalAlertOrigin& message) {
  const auto& s = kOriginSignals;
  Unpacker unpacker(frame, MessageKind::kRegionalAlertOrigin, s);
  RegionalAlertOrigin m;
  m.event_id = unpacker.integer<std::uint16_t>(s[kOrEventId]);
  m.version = unpacker.integer<std::uint8_t>(s[kOrVersion]);
  m.magnitude = unpacker.physical(s[kMagnitude]);
  m.origin_age_s = unpacker.physical(s[kOriginAge]);
  m.distance_km = unpacker.integer<std::uint16_t>(s[kDistance]);
  m.cancelled = unpacker.integer<std::uint8_t>(s[kCancelled]) != 0;
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

EncodeResult encode(const RegionalAlert& message, CanFrame& frame) {
  const auto& s = kRegionalSignals;
  Packer packer;
  packer.integer(message.event_id, s[kRaEventId]);
  packer.integer(message.version, s[kRaVersion]);
  packer.physical(message.pga_g, s[kPga]);
  packer.physical(message.sigma_ln, s[kSigmaLn]);
  packer.physical(message.s_arrival_in_s, s[kSArrivalIn]);
  return packer.finish(kRegionalAlertId, frame);
}

DecodeResult decode(const CanFrame& frame, RegionalAlert& message) {
  const auto& s = kRegionalSignals;
  Unpacker unpacker(frame, MessageKind::kRegionalAlert, s);
  RegionalAlert m;
  m.event_id = unpacker.integer<std::uint16_t>(s[kRaEventId]);
  m.version = unpacker.integer<std::uint8_t>(s[kRaVersion]);
  m.pga_g = unpacker.physical(s[kPga]);
  m.sigma_ln = unpacker.physical(s[kSigmaLn]);
  m.s_arrival_in_s = unpacker.physical(s[kSArrivalIn]);
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

EncodeResult encode(const RegionalAlertTag& message, CanFrame& frame) {
  const auto& s = kTagSignals;
  Packer packer;
  packer.integer(message.counter, s[kCounter]);
  packer.integer(message.tag, s[kTag]);
  return packer.finish(kRegionalAlertTagId, frame);
}

DecodeResult decode(const CanFrame& frame, RegionalAlertTag& message) {
  const auto& s = kTagSignals;
  Unpacker unpacker(frame, MessageKind::kRegionalAlertTag, s);
  RegionalAlertTag m;
  m.counter = unpacker.integer<std::uint32_t>(s[kCounter]);
  m.tag = unpacker.integer<std::uint32_t>(s[kTag]);
  if (unpacker.result().ok()) message = m;
  return unpacker.result();
}

}  // namespace plinth::hal::can

// The plinth CAN codec against hand-written golden frames, over the whole range of every signal,
// on every rejection, and against hal/can_codec/plinth.dbc itself.
#include "plinth/hal/can_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string_view>
#include <string>
#include <vector>

#include "dbc_file.h"

namespace plinth::hal::can {
namespace {

using testing::Dbc;
using testing::DbcSignal;
using testing::plinth_dbc;

using Bytes = std::array<std::uint8_t, 8>;

CanFrame make_frame(std::uint32_t id, const Bytes& data, std::uint8_t length = 8) {
  CanFrame f;
  f.id = id;
  f.length = length;
  f.data = data;
  return f;
}

void expect_frame(const CanFrame& f, std::uint32_t id, const Bytes& data) {
  EXPECT_EQ(f.id, id);
  EXPECT_EQ(f.length, 8);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], data[i]) << "byte " << i;
}

// A golden frame: `m` encodes to `golden` under identifier `id`, and `golden` decodes into
// `decoded`, for the caller to check field by field.
template <typename Message>
void expect_golden(const Message& m, std::uint32_t id, const Bytes& golden, Message& decoded) {
  CanFrame f;
  ASSERT_TRUE(encode(m, f).ok());
  expect_frame(f, id, golden);
  ASSERT_TRUE(decode(make_frame(id, golden), decoded).ok());
}

std::uint64_t raw_at(const CanFrame& f, unsigned start, unsigned length) {
  return extract_bits(load_le64(f.data), start, length);
}

constexpr double kG = 0.00025;  // SensorAcceleration factor, g/bit
constexpr double kRadS = 0.0005;  // StatueRotation factor, rad/s/bit
constexpr double kRiskStep = 0.0001;

// ---------------------------------------------------------------------------------------------
// Bit packing helpers

TEST(CanBitPacking, LittleEndianWordAndSignals) {
  const Bytes bytes{0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF};
  EXPECT_EQ(load_le64(bytes), 0xEFCDAB8967452301ULL);
  Bytes back{};
  store_le64(0xEFCDAB8967452301ULL, back);
  EXPECT_EQ(back, bytes);
  EXPECT_EQ(bit_mask(4, 4), 0xF0ULL);
  EXPECT_EQ(bit_mask(0, 64), ~0ULL);
  EXPECT_EQ(bit_mask(0, 0), 0ULL);
  EXPECT_EQ(extract_bits(0xEFCDAB8967452301ULL, 12, 8), 0x52ULL);
  EXPECT_EQ(insert_bits(0, 12, 8, 0x1FF), 0xFF000ULL);  // excess raw bits dropped
  EXPECT_EQ(insert_bits(~0ULL, 8, 8, 0), 0xFFFFFFFFFFFF00FFULL);
  EXPECT_EQ(sign_extend(0x8000, 16), -32768);
  EXPECT_EQ(sign_extend(0x7FFF, 16), 32767);
  EXPECT_EQ(sign_extend(0xFFFF, 16), -1);
  EXPECT_EQ(sign_extend(0x1, 1), -1);
  EXPECT_EQ(sign_extend(0xF0, 4), 0);  // bits above the length ignored
}

// ---------------------------------------------------------------------------------------------
// Golden frames, derived by hand from plinth.dbc (Intel: the 8 bytes are one little-endian
// 64-bit word; a signal at start bit S of length L is bits S..S+L-1; raw = phys / factor).

TEST(CanGolden, SensorAcceleration) {
  // Node 3: identifier 0x300 + 3 = 0x303.
  // Ax  0|16@1- (0.00025,0):  1.0 g   -> raw  4000 = 0x0FA0 -> bytes 0-1: A0 0F
  // Ay 16|16@1- (0.00025,0): -0.5 g   -> raw -2000 = 0xF830 -> bytes 2-3: 30 F8
  // Az 32|16@1- (0.00025,0): -8.192 g -> raw -32768 = 0x8000 -> bytes 4-5: 00 80
  // Sequence 48|8: 0x5A -> byte 6; Status 56|8: saturated|over_temperature = 0x05 -> byte 7
  const Bytes golden{0xA0, 0x0F, 0x30, 0xF8, 0x00, 0x80, 0x5A, 0x05};
  SensorAcceleration m;
  m.node = 3;
  m.ax_g = 1.0;
  m.ay_g = -0.5;
  m.az_g = -8.192;
  m.sequence = 0x5A;
  m.status = sensor_status::kSaturated | sensor_status::kOverTemperature;
  SensorAcceleration d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x303, golden, d));
  EXPECT_EQ(d.node, 3);
  EXPECT_DOUBLE_EQ(d.ax_g, 1.0);
  EXPECT_DOUBLE_EQ(d.ay_g, -0.5);
  EXPECT_DOUBLE_EQ(d.az_g, -8.192);
  EXPECT_EQ(d.sequence, 0x5A);
  EXPECT_EQ(d.status, 0x05);
}

TEST(CanGolden, SensorHeartbeat) {
  // Node 15: identifier 0x310 + 15 = 0x31F.
  // Uptime 0|32 (1,0): 0x12345678 s -> bytes 0-3: 78 56 34 12
  // FirmwareMajor 32|4 = 2 (low nibble of byte 4), FirmwareMinor 36|4 = 7 (high) -> byte 4: 72
  // Status 40|8: self_test_failed = 0x02 -> byte 5
  // CanTxErrors 48|8 = 128 -> byte 6: 80; CanRxErrors 56|8 = 127 -> byte 7: 7F
  const Bytes golden{0x78, 0x56, 0x34, 0x12, 0x72, 0x02, 0x80, 0x7F};
  SensorHeartbeat m;
  m.node = 15;
  m.uptime_s = 0x12345678;
  m.firmware_major = 2;
  m.firmware_minor = 7;
  m.status = sensor_status::kSelfTestFailed;
  m.can_tx_errors = 128;
  m.can_rx_errors = 127;
  SensorHeartbeat d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x31F, golden, d));
  EXPECT_EQ(d.node, 15);
  EXPECT_EQ(d.uptime_s, 0x12345678U);
  EXPECT_EQ(d.firmware_major, 2);
  EXPECT_EQ(d.firmware_minor, 7);
  EXPECT_EQ(d.status, sensor_status::kSelfTestFailed);
  EXPECT_EQ(d.can_tx_errors, 128);
  EXPECT_EQ(d.can_rx_errors, 127);
}

TEST(CanGolden, MonitorStatus) {
  // Axis 1: identifier 0x320 + 1 = 0x321.
  // Phase 0|4 = slide_rocking (3), Corner 4|4 = right (2) -> byte 0: 23
  // AlarmLevel 8|4 = warning (2), bits 12-15 reserved 0 -> byte 1: 02
  // Risk 16|16 (0.0001,0): 0.75 -> raw 7500 = 0x1D4C -> bytes 2-3: 4C 1D
  // Sequence 32|8 = 200 -> byte 4: C8
  // SampleAge 40|16 (1,0) ms: 1234 = 0x04D2 -> bytes 5-6: D2 04; byte 7 reserved: 00
  const Bytes golden{0x23, 0x02, 0x4C, 0x1D, 0xC8, 0xD2, 0x04, 0x00};
  MonitorStatus m;
  m.axis = 1;
  m.phase = Phase::kSlideRocking;
  m.corner = Corner::kRight;
  m.alarm_level = AlarmLevel::kWarning;
  m.risk = 0.75;
  m.sequence = 200;
  m.sample_age_ms = 1234;
  MonitorStatus d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x321, golden, d));
  EXPECT_EQ(d.axis, 1);
  EXPECT_EQ(d.phase, Phase::kSlideRocking);
  EXPECT_EQ(d.corner, Corner::kRight);
  EXPECT_EQ(d.alarm_level, AlarmLevel::kWarning);
  EXPECT_DOUBLE_EQ(d.risk, 0.75);
  EXPECT_EQ(d.sequence, 200);
  EXPECT_EQ(d.sample_age_ms, 1234);
}

TEST(CanGolden, MonitorStatusTroubleAndCollapseHeld) {
  // Axis 0: 0x320. Phase 0|4 = overturned (4), Corner 4|4 = none -> byte 0: 04
  // AlarmLevel 8|4 = alarm (3), Trouble 12|1 = 1, CollapseHeld 13|1 = 1 -> byte 1: 0x33
  // Risk 1.0 -> raw 10000 = 0x2710 -> bytes 2-3: 10 27; the rest 0.
  const Bytes golden{0x04, 0x33, 0x10, 0x27, 0x00, 0x00, 0x00, 0x00};
  MonitorStatus m;
  m.phase = Phase::kOverturned;
  m.alarm_level = AlarmLevel::kAlarm;
  m.trouble = true;
  m.collapse_held = true;
  m.risk = 1.0;
  MonitorStatus d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x320, golden, d));
  EXPECT_TRUE(d.trouble);
  EXPECT_TRUE(d.collapse_held);
  EXPECT_EQ(d.alarm_level, AlarmLevel::kAlarm);
}

TEST(CanGolden, AlarmEvent) {
  // Identifier 0x330.
  // Level 0|4 = alarm (3), PreviousLevel 4|4 = advisory (1) -> byte 0: 13
  // Cause 8|8 = overturn_detected (3) -> byte 1: 03
  // Latched 16|1 = 1, bits 17-23 reserved 0 -> byte 2: 01
  // TimeSinceStart 24|32 (1,0) ms: 0xDEADBEEF -> bytes 3-6: EF BE AD DE
  // Sequence 56|8 = 0x42 -> byte 7
  const Bytes golden{0x13, 0x03, 0x01, 0xEF, 0xBE, 0xAD, 0xDE, 0x42};
  AlarmEvent m;
  m.level = AlarmLevel::kAlarm;
  m.previous_level = AlarmLevel::kAdvisory;
  m.cause = AlarmCause::kOverturnDetected;
  m.latched = true;
  m.time_since_start_ms = 0xDEADBEEF;
  m.sequence = 0x42;
  AlarmEvent d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x330, golden, d));
  EXPECT_EQ(d.level, AlarmLevel::kAlarm);
  EXPECT_EQ(d.previous_level, AlarmLevel::kAdvisory);
  EXPECT_EQ(d.cause, AlarmCause::kOverturnDetected);
  EXPECT_TRUE(d.latched);
  EXPECT_EQ(d.time_since_start_ms, 0xDEADBEEFU);
  EXPECT_EQ(d.sequence, 0x42);
}

TEST(CanGolden, AlarmEventWithTrouble) {
  // Level alarm (3), PreviousLevel alarm (3) -> byte 0: 33; Cause statue_sensor_fault (16) -> 10
  // Latched 16|1 = 1, Trouble 17|1 = 1 -> byte 2: 03; the rest 0.
  const Bytes golden{0x33, 0x10, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00};
  AlarmEvent m;
  m.level = AlarmLevel::kAlarm;
  m.previous_level = AlarmLevel::kAlarm;
  m.cause = AlarmCause::kStatueSensorFault;
  m.latched = true;
  m.trouble = true;
  AlarmEvent d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x330, golden, d));
  EXPECT_EQ(d.cause, AlarmCause::kStatueSensorFault);
  EXPECT_TRUE(d.trouble);
  EXPECT_TRUE(d.latched);
}

TEST(CanGolden, RegionalAlert) {
  // Identifier 0x360. EventId 0|16 = 0x1234 -> 34 12; Version 16|8 = 5 -> 05;
  // Pga 24|16 (0.0001 g): 0.4 g = 4000 = 0x0FA0 -> A0 0F; SigmaLn 40|8 (0.01): 0.6 = 60 -> 3C;
  // SArrivalIn 48|16 signed (0.01 s): -1.5 s = -150 = 0xFF6A -> 6A FF.
  const Bytes golden{0x34, 0x12, 0x05, 0xA0, 0x0F, 0x3C, 0x6A, 0xFF};
  RegionalAlert m;
  m.event_id = 0x1234;
  m.version = 5;
  m.pga_g = 0.4;
  m.sigma_ln = 0.6;
  m.s_arrival_in_s = -1.5;
  RegionalAlert d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x360, golden, d));
  EXPECT_EQ(d.event_id, 0x1234);
  EXPECT_EQ(d.version, 5);
  EXPECT_NEAR(d.pga_g, 0.4, 1e-12);
  EXPECT_NEAR(d.sigma_ln, 0.6, 1e-12);
  EXPECT_NEAR(d.s_arrival_in_s, -1.5, 1e-12);
  // Beyond the ranges: refused, never clamped.
  CanFrame f;
  m.s_arrival_in_s = 400.0;
  EXPECT_STREQ(encode(m, f).signal, "SArrivalIn");
  m.s_arrival_in_s = 0.0;
  m.pga_g = -0.1;
  EXPECT_STREQ(encode(m, f).signal, "Pga");
  m.pga_g = 0.1;
  m.sigma_ln = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(encode(m, f).error, CodecError::kNotFinite);
}

TEST(CanGolden, RegionalAlertTag) {
  // Identifier 0x362. Counter 0|32 = 0x01020304 -> 04 03 02 01; Tag 32|32 = 0xA1B2C3D4 ->
  // D4 C3 B2 A1.
  const Bytes golden{0x04, 0x03, 0x02, 0x01, 0xD4, 0xC3, 0xB2, 0xA1};
  RegionalAlertTag m;
  m.counter = 0x01020304;
  m.tag = 0xA1B2C3D4;
  RegionalAlertTag d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x362, golden, d));
  EXPECT_EQ(d.counter, 0x01020304U);
  EXPECT_EQ(d.tag, 0xA1B2C3D4U);
}

TEST(CanGolden, RegionalAlertOrigin) {
  // Identifier 0x361. EventId 0|16 = 0x1234 -> 34 12; Version 16|8 = 5 -> 05;
  // Magnitude 24|8 (0.05): 7.1 = 142 -> 8E; OriginAge 32|16 signed (0.02 s): 12.34 s = 617 =
  // 0x0269 -> 69 02; Distance 48|12 = 60 km = 0x03C, Cancelled 60|1 = 1 -> bits 48-63 0x103C ->
  // 3C 10.
  const Bytes golden{0x34, 0x12, 0x05, 0x8E, 0x69, 0x02, 0x3C, 0x10};
  RegionalAlertOrigin m;
  m.event_id = 0x1234;
  m.version = 5;
  m.magnitude = 7.1;
  m.origin_age_s = 12.34;
  m.distance_km = 60;
  m.cancelled = true;
  RegionalAlertOrigin d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x361, golden, d));
  EXPECT_EQ(d.event_id, 0x1234);
  EXPECT_EQ(d.version, 5);
  EXPECT_NEAR(d.magnitude, 7.1, 1e-12);
  EXPECT_NEAR(d.origin_age_s, 12.34, 1e-12);
  EXPECT_EQ(d.distance_km, 60);
  EXPECT_TRUE(d.cancelled);
  CanFrame f;
  m.magnitude = 10.5;
  EXPECT_STREQ(encode(m, f).signal, "Magnitude");
  m.magnitude = 7.0;
  m.distance_km = 4096;
  EXPECT_STREQ(encode(m, f).signal, "Distance");
  // Magnitude raw values above 200 (10) are refused on decode.
  EXPECT_STREQ(decode(make_frame(0x361, Bytes{0, 0, 0, 201, 0, 0, 0, 0}), d).signal,
               "Magnitude");
}

TEST(CanGolden, Acknowledge) {
  // Identifier 0x340.
  // Level 0|4 = alarm (3), bits 4-7 reserved -> byte 0: 03
  // SourceId 8|8 = 0x21 -> byte 1; EventSequence 16|8 = 0x42 -> byte 2; bytes 3-7 reserved: 00
  const Bytes golden{0x03, 0x21, 0x42, 0x00, 0x00, 0x00, 0x00, 0x00};
  Acknowledge m;
  m.level = AlarmLevel::kAlarm;
  m.source_id = 0x21;
  m.event_sequence = 0x42;
  Acknowledge d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x340, golden, d));
  EXPECT_EQ(d.level, AlarmLevel::kAlarm);
  EXPECT_EQ(d.source_id, 0x21);
  EXPECT_EQ(d.event_sequence, 0x42);
}

TEST(CanGolden, StatueStands) {
  // Identifier 0x341. SourceId 0|8 = 0x21 -> byte 0; EventSequence 8|8 = 0x42 -> byte 1;
  // bytes 2-7 reserved: 00
  const Bytes golden{0x21, 0x42, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  StatueStands m;
  m.source_id = 0x21;
  m.event_sequence = 0x42;
  StatueStands d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x341, golden, d));
  EXPECT_EQ(d.source_id, 0x21);
  EXPECT_EQ(d.event_sequence, 0x42);
}

TEST(CanGolden, CollapseForecast) {
  // Axis 1: identifier 0x350 + 1 = 0x351.
  // Probability 0|16 (0.0001,0): 0.3529 (6 of 17) -> raw 3529 = 0x0DC9 -> bytes 0-1: C9 0D
  // WorstMember 16|8 = 12 -> byte 2: 0C; Members 24|8 = 17 -> byte 3: 11
  // CollapseIn 32|16 (1,0) ms: 2345 = 0x0929 -> bytes 4-5: 29 09
  // Horizon 48|8 (0.1,0) s: 4.0 -> raw 40 = 0x28 -> byte 6; Sequence 56|8 = 0xFE -> byte 7
  const Bytes golden{0xC9, 0x0D, 0x0C, 0x11, 0x29, 0x09, 0x28, 0xFE};
  CollapseForecast m;
  m.axis = 1;
  m.probability = 0.3529;
  m.worst_member = 12;
  m.members = 17;
  m.collapse_in_ms = 2345;
  m.horizon_s = 4.0;
  m.sequence = 0xFE;
  CollapseForecast d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x351, golden, d));
  EXPECT_EQ(d.axis, 1);
  EXPECT_DOUBLE_EQ(d.probability, 0.3529);
  EXPECT_EQ(d.worst_member, 12);
  EXPECT_EQ(d.members, 17);
  EXPECT_EQ(d.collapse_in_ms, 2345);
  EXPECT_DOUBLE_EQ(d.horizon_s, 4.0);
  EXPECT_EQ(d.sequence, 0xFE);

  // None collapses (axis 0, 0x350): Probability 0, WorstMember 255, Members 9, CollapseIn 65535,
  // Horizon 10 s (raw 100 = 0x64), Sequence 0.
  const Bytes none{0x00, 0x00, 0xFF, 0x09, 0xFF, 0xFF, 0x64, 0x00};
  CollapseForecast n;
  n.members = 9;
  n.horizon_s = 10.0;
  ASSERT_NO_FATAL_FAILURE(expect_golden(n, 0x350, none, d));
  EXPECT_EQ(d.axis, 0);
  EXPECT_EQ(d.probability, 0.0);
  EXPECT_EQ(d.worst_member, kNoWorstMember);
  EXPECT_EQ(d.members, 9);
  EXPECT_EQ(d.collapse_in_ms, kNoCollapseForecast);
  EXPECT_DOUBLE_EQ(d.horizon_s, 10.0);
}

// StatueRotation of node 2 (0x372): Wx = +1 rad/s (raw 2000 = 0x07D0), Wy = -0.5 rad/s (raw
// -1000 = 0xFC18), Wz = the most negative raw (0x8000, -16.384 rad/s), Sequence 0x81, Status
// saturated + over-temperature (0x05).
TEST(CanGolden, StatueRotation) {
  const Bytes golden{0xD0, 0x07, 0x18, 0xFC, 0x00, 0x80, 0x81, 0x05};
  StatueRotation m;
  m.node = 2;
  m.wx_rad_s = 1.0;
  m.wy_rad_s = -0.5;
  m.wz_rad_s = -16.384;
  m.sequence = 0x81;
  m.status = sensor_status::kSaturated | sensor_status::kOverTemperature;
  StatueRotation d;
  ASSERT_NO_FATAL_FAILURE(expect_golden(m, 0x372, golden, d));
  EXPECT_EQ(d.node, 2);
  EXPECT_DOUBLE_EQ(d.wx_rad_s, 1.0);
  EXPECT_DOUBLE_EQ(d.wy_rad_s, -0.5);
  EXPECT_DOUBLE_EQ(d.wz_rad_s, -16.384);
  EXPECT_EQ(d.sequence, 0x81);
  EXPECT_EQ(d.status, m.status);
  EXPECT_STREQ(message_kind_name(classify(0x372)), "StatueRotation");
}

// ---------------------------------------------------------------------------------------------
// Round trips over every signal's range

TEST(CanRoundTrip, StatueRotationEveryRawValueOfEveryAxisAndNode) {
  for (std::uint8_t node = kFirstSensorNode; node <= kLastSensorNode; ++node) {
    StatueRotation m;
    m.node = node;
    m.sequence = static_cast<std::uint8_t>(node * 17);
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok());
    EXPECT_EQ(f.id, 0x370U + node);
    EXPECT_EQ(classify(f.id), MessageKind::kStatueRotation);
    StatueRotation d;
    ASSERT_TRUE(decode(f, d).ok());
    EXPECT_EQ(d.node, node);
    EXPECT_EQ(d.sequence, m.sequence);
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (std::int32_t raw = -32768; raw <= 32767; ++raw) {
      StatueRotation m;
      const double w = raw * kRadS;
      (axis == 0 ? m.wx_rad_s : axis == 1 ? m.wy_rad_s : m.wz_rad_s) = w;
      CanFrame f;
      ASSERT_TRUE(encode(m, f).ok()) << w;
      ASSERT_EQ(sign_extend(raw_at(f, 16U * static_cast<unsigned>(axis), 16), 16), raw);
      StatueRotation d;
      ASSERT_TRUE(decode(f, d).ok());
      ASSERT_EQ(axis == 0 ? d.wx_rad_s : axis == 1 ? d.wy_rad_s : d.wz_rad_s, w);
    }
  }
  // Beyond the range (half a step past either end), not finite, an undefined flag, node 0/16.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const double w : {16.38375 + 1e-9, -16.38425, 100.0, nan}) {
    StatueRotation m;
    m.wy_rad_s = w;
    CanFrame f;
    const EncodeResult r = encode(m, f);
    EXPECT_EQ(r.error, std::isnan(w) ? CodecError::kNotFinite : CodecError::kOutOfRange) << w;
    EXPECT_STREQ(r.signal, "Wy");
  }
  for (const int node : {0, 16}) {
    StatueRotation m;
    m.node = static_cast<std::uint8_t>(node);
    CanFrame f;
    EXPECT_STREQ(encode(m, f).signal, "node");
  }
}

TEST(CanRoundTrip, SensorAccelerationEveryRawValueOfEveryAxis) {
  for (std::uint8_t node = kFirstSensorNode; node <= kLastSensorNode; ++node) {
    SensorAcceleration m;
    m.node = node;
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok());
    EXPECT_EQ(f.id, 0x300U + node);
    EXPECT_EQ(classify(f.id), MessageKind::kSensorAcceleration);
    SensorAcceleration d;
    ASSERT_TRUE(decode(f, d).ok());
    EXPECT_EQ(d.node, node);
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (std::int32_t raw = -32768; raw <= 32767; ++raw) {
      SensorAcceleration m;
      const double g = raw * kG;
      (axis == 0 ? m.ax_g : axis == 1 ? m.ay_g : m.az_g) = g;
      CanFrame f;
      ASSERT_TRUE(encode(m, f).ok()) << raw;
      const auto start = static_cast<unsigned>(16 * axis);
      ASSERT_EQ(sign_extend(raw_at(f, start, 16), 16), raw);
      SensorAcceleration d;
      ASSERT_TRUE(decode(f, d).ok()) << raw;
      ASSERT_EQ(axis == 0 ? d.ax_g : axis == 1 ? d.ay_g : d.az_g, g) << raw;
    }
  }
}

TEST(CanRoundTrip, SensorAccelerationEverySequenceAndStatus) {
  for (unsigned v = 0; v <= 255; ++v) {
    SensorAcceleration m;
    m.sequence = static_cast<std::uint8_t>(v);
    m.status = static_cast<std::uint8_t>(v & sensor_status::kDefinedMask);
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok());
    EXPECT_EQ(f.data[6], v);
    SensorAcceleration d;
    ASSERT_TRUE(decode(f, d).ok());
    EXPECT_EQ(d.sequence, m.sequence);
    EXPECT_EQ(d.status, m.status);
  }
}

TEST(CanRoundTrip, SensorAccelerationRandomValuesWithinHalfAStep) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> g(-8.192, 8.19175);
  for (int i = 0; i < 100000; ++i) {
    SensorAcceleration m;
    m.ax_g = g(rng);
    m.ay_g = g(rng);
    m.az_g = g(rng);
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok()) << m.ax_g << " " << m.ay_g << " " << m.az_g;
    SensorAcceleration d;
    ASSERT_TRUE(decode(f, d).ok());
    EXPECT_LE(std::fabs(d.ax_g - m.ax_g), 0.5 * kG + 1e-12);
    EXPECT_LE(std::fabs(d.ay_g - m.ay_g), 0.5 * kG + 1e-12);
    EXPECT_LE(std::fabs(d.az_g - m.az_g), 0.5 * kG + 1e-12);
  }
}

TEST(CanRoundTrip, SensorHeartbeatEverySmallFieldAndUptimeSweep) {
  for (std::uint8_t node = kFirstSensorNode; node <= kLastSensorNode; ++node) {
    SensorHeartbeat m;
    m.node = node;
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok());
    EXPECT_EQ(f.id, 0x310U + node);
    SensorHeartbeat d;
    ASSERT_TRUE(decode(f, d).ok());
    EXPECT_EQ(d.node, node);
  }
  for (unsigned v = 0; v <= 255; ++v) {
    SensorHeartbeat m;
    m.firmware_major = static_cast<std::uint8_t>(v & 0x0F);
    m.firmware_minor = static_cast<std::uint8_t>(v >> 4);
    m.status = static_cast<std::uint8_t>(v & sensor_status::kDefinedMask);
    m.can_tx_errors = static_cast<std::uint8_t>(v);
    m.can_rx_errors = static_cast<std::uint8_t>(255 - v);
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok());
    EXPECT_EQ(f.data[4], v);  // major in the low nibble, minor in the high one
    SensorHeartbeat d;
    ASSERT_TRUE(decode(f, d).ok());
    EXPECT_EQ(d.firmware_major, m.firmware_major);
    EXPECT_EQ(d.firmware_minor, m.firmware_minor);
    EXPECT_EQ(d.status, m.status);
    EXPECT_EQ(d.can_tx_errors, m.can_tx_errors);
    EXPECT_EQ(d.can_rx_errors, m.can_rx_errors);
  }
  // Uptime: 2^20 values spread over the 32-bit range, plus both ends.
  std::vector<std::uint32_t> uptimes{0, 1, 0xFFFFFFFEU, 0xFFFFFFFFU};
  for (std::uint32_t k = 0; k < (1U << 20); ++k) uptimes.push_back(k * 4093U + (k >> 7));
  for (const std::uint32_t u : uptimes) {
    SensorHeartbeat m;
    m.uptime_s = u;
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok());
    ASSERT_EQ(raw_at(f, 0, 32), u);
    SensorHeartbeat d;
    ASSERT_TRUE(decode(f, d).ok());
    ASSERT_EQ(d.uptime_s, u);
  }
}

TEST(CanRoundTrip, MonitorStatusEveryEnumCombinationAndAxis) {
  for (std::uint8_t axis = 0; axis < kMonitorAxisCount; ++axis) {
    for (unsigned p = 0; p <= 6; ++p) {
      for (unsigned c = 0; c <= 2; ++c) {
        for (unsigned a = 0; a <= 4; ++a) {
          MonitorStatus m;
          m.axis = axis;
          m.phase = static_cast<Phase>(p);
          m.corner = static_cast<Corner>(c);
          m.alarm_level = static_cast<AlarmLevel>(a);
          CanFrame f;
          ASSERT_TRUE(encode(m, f).ok());
          EXPECT_EQ(f.id, 0x320U + axis);
          MonitorStatus d;
          ASSERT_TRUE(decode(f, d).ok());
          EXPECT_EQ(d.axis, axis);
          EXPECT_EQ(d.phase, m.phase);
          EXPECT_EQ(d.corner, m.corner);
          EXPECT_EQ(d.alarm_level, m.alarm_level);
        }
      }
    }
  }
}

TEST(CanRoundTrip, MonitorStatusEveryRiskSequenceAndAge) {
  for (std::uint32_t raw = 0; raw <= 10000; ++raw) {
    MonitorStatus m;
    m.risk = raw * kRiskStep;
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok()) << raw;
    ASSERT_EQ(raw_at(f, 16, 16), raw);
    MonitorStatus d;
    ASSERT_TRUE(decode(f, d).ok());
    ASSERT_EQ(d.risk, m.risk);
    ASSERT_LE(d.risk, 1.0);
  }
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> risk(0.0, 1.0);
  for (int i = 0; i < 100000; ++i) {
    MonitorStatus m;
    m.risk = risk(rng);
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok()) << m.risk;
    MonitorStatus d;
    ASSERT_TRUE(decode(f, d).ok());
    ASSERT_LE(std::fabs(d.risk - m.risk), 0.5 * kRiskStep + 1e-12);
  }
  for (std::uint32_t age = 0; age <= 65535; ++age) {
    MonitorStatus m;
    m.sample_age_ms = static_cast<std::uint16_t>(age);
    m.sequence = static_cast<std::uint8_t>(age & 0xFF);
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok());
    MonitorStatus d;
    ASSERT_TRUE(decode(f, d).ok());
    ASSERT_EQ(d.sample_age_ms, age);
    ASSERT_EQ(d.sequence, age & 0xFF);
  }
}

TEST(CanRoundTrip, AlarmEventEveryEnumCombinationAndTimeSweep) {
  for (unsigned l = 0; l <= 4; ++l) {
    for (unsigned p = 0; p <= 4; ++p) {
      for (unsigned c = 0; c <= 18; ++c) {
        for (const unsigned flags : {0U, 1U, 2U, 3U}) {
          AlarmEvent m;
          m.level = static_cast<AlarmLevel>(l);
          m.previous_level = static_cast<AlarmLevel>(p);
          m.cause = static_cast<AlarmCause>(c);
          m.latched = (flags & 1U) != 0;
          m.trouble = (flags & 2U) != 0;
          CanFrame f;
          ASSERT_TRUE(encode(m, f).ok());
          AlarmEvent d;
          ASSERT_TRUE(decode(f, d).ok());
          EXPECT_EQ(d.level, m.level);
          EXPECT_EQ(d.previous_level, m.previous_level);
          EXPECT_EQ(d.cause, m.cause);
          EXPECT_EQ(d.latched, m.latched);
          EXPECT_EQ(d.trouble, m.trouble);
        }
      }
    }
  }
  std::vector<std::uint32_t> times{0, 1, 0xFFFFFFFEU, 0xFFFFFFFFU};
  for (std::uint32_t k = 0; k < (1U << 20); ++k) times.push_back(k * 4099U + (k >> 5));
  std::uint32_t n = 0;
  for (const std::uint32_t t : times) {
    AlarmEvent m;
    m.time_since_start_ms = t;
    m.sequence = static_cast<std::uint8_t>(n++);
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok());
    ASSERT_EQ(raw_at(f, 24, 32), t);
    AlarmEvent d;
    ASSERT_TRUE(decode(f, d).ok());
    ASSERT_EQ(d.time_since_start_ms, t);
    ASSERT_EQ(d.sequence, m.sequence);
  }
}

TEST(CanRoundTrip, AcknowledgeEveryValue) {
  for (unsigned l = 0; l <= 4; ++l) {
    for (unsigned v = 0; v <= 255; ++v) {
      Acknowledge m;
      m.level = static_cast<AlarmLevel>(l);
      m.source_id = static_cast<std::uint8_t>(v);
      m.event_sequence = static_cast<std::uint8_t>(255 - v);
      CanFrame f;
      ASSERT_TRUE(encode(m, f).ok());
      Acknowledge d;
      ASSERT_TRUE(decode(f, d).ok());
      EXPECT_EQ(d.level, m.level);
      EXPECT_EQ(d.source_id, m.source_id);
      EXPECT_EQ(d.event_sequence, m.event_sequence);
    }
  }
}

// A collapse forecast of `members` members, member `worst` collapsing first in `in_ms`.
CollapseForecast forecast_of(std::uint8_t members, std::uint8_t worst, std::uint16_t in_ms) {
  CollapseForecast m;
  m.members = members;
  m.worst_member = worst;
  m.collapse_in_ms = in_ms;
  m.probability = 1.0 / members;
  m.horizon_s = 4.0;
  return m;
}

TEST(CanRoundTrip, CollapseForecastEveryMembersWorstMemberAndAxis) {
  for (std::uint8_t axis = 0; axis < kMonitorAxisCount; ++axis) {
    for (unsigned members = 1; members <= kMaxForecastMembers; ++members) {
      for (unsigned worst = 0; worst <= members; ++worst) {  // worst == members: none collapses
        const bool none = worst == members;
        CollapseForecast m = forecast_of(static_cast<std::uint8_t>(members),
                                         none ? kNoWorstMember : static_cast<std::uint8_t>(worst),
                                         none ? kNoCollapseForecast : 100);
        m.axis = axis;
        if (none) m.probability = 0.0;
        CanFrame f;
        ASSERT_TRUE(encode(m, f).ok()) << members << " " << worst;
        EXPECT_EQ(f.id, 0x350U + axis);
        EXPECT_EQ(classify(f.id), MessageKind::kCollapseForecast);
        EXPECT_EQ(raw_at(f, 16, 8), none ? 255U : worst);
        EXPECT_EQ(raw_at(f, 24, 8), members);
        CollapseForecast d;
        ASSERT_TRUE(decode(f, d).ok());
        EXPECT_EQ(d.axis, axis);
        EXPECT_EQ(d.members, m.members);
        EXPECT_EQ(d.worst_member, m.worst_member);
        EXPECT_EQ(d.collapse_in_ms, m.collapse_in_ms);
        EXPECT_LE(std::fabs(d.probability - m.probability), 0.5 * kRiskStep + 1e-12);
      }
    }
  }
}

TEST(CanRoundTrip, CollapseForecastEveryProbabilityCollapseInHorizonAndSequence) {
  for (std::uint32_t raw = 1; raw <= 10000; ++raw) {
    CollapseForecast m = forecast_of(17, 3, 500);
    m.probability = raw * kRiskStep;
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok()) << raw;
    ASSERT_EQ(raw_at(f, 0, 16), raw);
    CollapseForecast d;
    ASSERT_TRUE(decode(f, d).ok());
    ASSERT_EQ(d.probability, m.probability);
  }
  for (std::uint32_t ms = 0; ms <= 65534; ++ms) {
    CollapseForecast m = forecast_of(5, 4, static_cast<std::uint16_t>(ms));
    m.sequence = static_cast<std::uint8_t>(ms & 0xFF);
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok()) << ms;
    ASSERT_EQ(raw_at(f, 32, 16), ms);
    CollapseForecast d;
    ASSERT_TRUE(decode(f, d).ok());
    ASSERT_EQ(d.collapse_in_ms, ms);
    ASSERT_EQ(d.sequence, ms & 0xFF);
  }
  for (std::uint32_t raw = 0; raw <= 255; ++raw) {
    CollapseForecast m = forecast_of(2, 0, 0);
    m.horizon_s = raw * 0.1;
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok()) << raw;
    ASSERT_EQ(raw_at(f, 48, 8), raw);
    CollapseForecast d;
    ASSERT_TRUE(decode(f, d).ok());
    ASSERT_NEAR(d.horizon_s, m.horizon_s, 1e-12);
  }
  // Horizons between the steps round to the nearest one.
  for (const double h : {0.04, 1e-3, 4.04, 4.06, 25.54}) {
    CollapseForecast m = forecast_of(2, 1, 7);
    m.horizon_s = h;
    CanFrame f;
    ASSERT_TRUE(encode(m, f).ok()) << h;
    CollapseForecast d;
    ASSERT_TRUE(decode(f, d).ok());
    EXPECT_LE(std::fabs(d.horizon_s - h), 0.05 + 1e-12) << h;
  }
}

// ---------------------------------------------------------------------------------------------
// Rejections

// A valid frame of every message kind.
std::vector<CanFrame> valid_frames() {
  std::vector<CanFrame> frames(11);
  SensorAcceleration a;
  a.ax_g = 0.1;
  EXPECT_TRUE(encode(a, frames[0]).ok());
  SensorHeartbeat h;
  h.uptime_s = 5;
  EXPECT_TRUE(encode(h, frames[1]).ok());
  MonitorStatus s;
  s.risk = 0.5;
  EXPECT_TRUE(encode(s, frames[2]).ok());
  AlarmEvent e;
  e.level = AlarmLevel::kAlarm;
  EXPECT_TRUE(encode(e, frames[3]).ok());
  Acknowledge k;
  k.level = AlarmLevel::kAlarm;
  EXPECT_TRUE(encode(k, frames[4]).ok());
  EXPECT_TRUE(encode(forecast_of(9, 2, 1500), frames[5]).ok());
  StatueRotation r;
  r.node = 3;
  r.wy_rad_s = -0.25;
  EXPECT_TRUE(encode(r, frames[6]).ok());
  RegionalAlert g;
  g.pga_g = 0.3;
  EXPECT_TRUE(encode(g, frames[7]).ok());
  RegionalAlertOrigin o;
  o.magnitude = 6.5;
  EXPECT_TRUE(encode(o, frames[8]).ok());
  StatueStands t;
  t.source_id = 4;
  t.event_sequence = 9;
  RegionalAlertTag g2;
  g2.counter = 7;
  g2.tag = 0xDEADBEEF;
  EXPECT_TRUE(encode(g2, frames[10]).ok());
  EXPECT_TRUE(encode(t, frames[9]).ok());
  return frames;
}

// Decodes `f` as every message type; the result of the one `f.id` classifies as, or of all.
struct AllDecodes {
  DecodeResult acceleration, heartbeat, status, event, acknowledge, forecast, rotation, regional,
      origin, stands, tag;
};
AllDecodes decode_all(const CanFrame& f) {
  SensorAcceleration a;
  SensorHeartbeat h;
  MonitorStatus s;
  AlarmEvent e;
  Acknowledge k;
  CollapseForecast c;
  StatueRotation r;
  RegionalAlert g;
  RegionalAlertOrigin o;
  StatueStands t;
  RegionalAlertTag g2;
  return {decode(f, a), decode(f, h), decode(f, s), decode(f, e), decode(f, k),
          decode(f, c), decode(f, r), decode(f, g), decode(f, o), decode(f, t),
          decode(f, g2)};
}
DecodeResult decode_as_own_kind(const CanFrame& f) {
  const AllDecodes all = decode_all(f);
  switch (classify(f.id)) {
    case MessageKind::kSensorAcceleration: return all.acceleration;
    case MessageKind::kSensorHeartbeat: return all.heartbeat;
    case MessageKind::kMonitorStatus: return all.status;
    case MessageKind::kAlarmEvent: return all.event;
    case MessageKind::kAcknowledge: return all.acknowledge;
    case MessageKind::kStatueStands: return all.stands;
    case MessageKind::kCollapseForecast: return all.forecast;
    case MessageKind::kStatueRotation: return all.rotation;
    case MessageKind::kRegionalAlert: return all.regional;
    case MessageKind::kRegionalAlertOrigin: return all.origin;
    case MessageKind::kRegionalAlertTag: return all.tag;
    case MessageKind::kUnknown: break;
  }
  ADD_FAILURE() << "unknown identifier " << f.id;
  return {};
}

TEST(CanReject, EveryLengthButEight) {
  for (CanFrame f : valid_frames()) {
    for (unsigned length = 0; length <= 255; ++length) {
      f.length = static_cast<std::uint8_t>(length);
      const DecodeResult r = decode_as_own_kind(f);
      if (length == 8) {
        EXPECT_TRUE(r.ok());
      } else {
        EXPECT_EQ(r.error, CodecError::kWrongLength) << "id " << f.id << " length " << length;
      }
    }
  }
}

TEST(CanReject, UnknownIdentifiers) {
  std::set<std::uint32_t> known;
  for (std::uint32_t n = 1; n <= 15; ++n) known.insert({0x300 + n, 0x310 + n, 0x370 + n});
  known.insert({0x320, 0x321, 0x330, 0x340, 0x341, 0x350, 0x351, 0x360, 0x361, 0x362});
  std::vector<std::uint32_t> ids;
  for (std::uint32_t id = 0; id <= 0x7FF; ++id) ids.push_back(id);
  // Identifiers with flag bits (SocketCAN's extended / RTR flags) or beyond 11 bits.
  ids.insert(ids.end(), {0x800, 0x1303, 0x80000303U, 0x40000330U, 0xFFFFFFFFU});
  const Bytes zero{};
  for (const std::uint32_t id : ids) {
    if (known.count(id) != 0) {
      EXPECT_NE(classify(id), MessageKind::kUnknown) << id;
      continue;
    }
    EXPECT_EQ(classify(id), MessageKind::kUnknown) << id;
    const AllDecodes all = decode_all(make_frame(id, zero));
    EXPECT_EQ(all.acceleration.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.heartbeat.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.status.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.event.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.acknowledge.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.forecast.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.rotation.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.regional.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.origin.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.stands.error, CodecError::kUnknownIdentifier) << id;
    EXPECT_EQ(all.tag.error, CodecError::kUnknownIdentifier) << id;
  }
  EXPECT_EQ(known.size(), 55U);
}

TEST(CanReject, AnotherMessagesIdentifier) {
  for (const CanFrame& f : valid_frames()) {
    const AllDecodes all = decode_all(f);
    const MessageKind kind = classify(f.id);
    EXPECT_EQ(all.acceleration.error == CodecError::kWrongMessage,
              kind != MessageKind::kSensorAcceleration);
    EXPECT_EQ(all.heartbeat.error == CodecError::kWrongMessage,
              kind != MessageKind::kSensorHeartbeat);
    EXPECT_EQ(all.status.error == CodecError::kWrongMessage, kind != MessageKind::kMonitorStatus);
    EXPECT_EQ(all.event.error == CodecError::kWrongMessage, kind != MessageKind::kAlarmEvent);
    EXPECT_EQ(all.acknowledge.error == CodecError::kWrongMessage,
              kind != MessageKind::kAcknowledge);
    EXPECT_EQ(all.forecast.error == CodecError::kWrongMessage,
              kind != MessageKind::kCollapseForecast);
    EXPECT_EQ(all.rotation.error == CodecError::kWrongMessage,
              kind != MessageKind::kStatueRotation);
    EXPECT_EQ(all.regional.error == CodecError::kWrongMessage,
              kind != MessageKind::kRegionalAlert);
    EXPECT_EQ(all.origin.error == CodecError::kWrongMessage,
              kind != MessageKind::kRegionalAlertOrigin);
    EXPECT_EQ(all.stands.error == CodecError::kWrongMessage, kind != MessageKind::kStatueStands);
    EXPECT_EQ(all.tag.error == CodecError::kWrongMessage, kind != MessageKind::kRegionalAlertTag);
  }
}

TEST(CanReject, EveryReservedBit) {
  for (const CanFrame& valid : valid_frames()) {
    std::uint64_t used = 0;
    for (const SignalLayout& s : signal_layouts(classify(valid.id))) {
      used |= bit_mask(s.start_bit, s.length);
    }
    for (unsigned bit = 0; bit < 64; ++bit) {
      if ((used >> bit) & 1U) continue;
      CanFrame f = valid;
      store_le64(load_le64(f.data) | (std::uint64_t{1} << bit), f.data);
      const DecodeResult r = decode_as_own_kind(f);
      EXPECT_EQ(r.error, CodecError::kReservedBitsSet) << "id " << f.id << " bit " << bit;
    }
  }
}

TEST(CanReject, UndefinedSensorStatusFlags) {
  for (unsigned flag = 4; flag < 8; ++flag) {
    const auto status = static_cast<std::uint8_t>(1U << flag);
    SensorAcceleration a;
    a.status = status;
    SensorHeartbeat h;
    h.status = status;
    CanFrame f;
    const EncodeResult ea = encode(a, f);
    EXPECT_EQ(ea.error, CodecError::kReservedBitsSet);
    EXPECT_STREQ(ea.signal, "Status");
    EXPECT_EQ(encode(h, f).error, CodecError::kReservedBitsSet);

    SensorAcceleration da;
    Bytes bytes{};
    bytes[7] = status;  // Status 56|8
    const DecodeResult ra = decode(make_frame(0x301, bytes), da);
    EXPECT_EQ(ra.error, CodecError::kReservedBitsSet);
    EXPECT_STREQ(ra.signal, "Status");
    SensorHeartbeat dh;
    bytes = Bytes{};
    bytes[5] = status;  // Status 40|8
    EXPECT_EQ(decode(make_frame(0x311, bytes), dh).error, CodecError::kReservedBitsSet);
    StatueRotation r;
    r.status = status;
    EXPECT_STREQ(encode(r, f).signal, "Status");
    StatueRotation dr;
    bytes = Bytes{};
    bytes[7] = status;  // Status 56|8
    const DecodeResult rr = decode(make_frame(0x37F, bytes), dr);
    EXPECT_EQ(rr.error, CodecError::kReservedBitsSet);
    EXPECT_STREQ(rr.signal, "Status");
  }
}

TEST(CanReject, EnumValuesMissingFromTheValueTables) {
  // Decode: every raw value above the VAL_ table.
  for (unsigned v = 7; v <= 15; ++v) {
    MonitorStatus d;
    const DecodeResult r = decode(make_frame(0x320, Bytes{static_cast<std::uint8_t>(v)}), d);
    EXPECT_EQ(r.error, CodecError::kInvalidEnum);
    EXPECT_STREQ(r.signal, "Phase");
  }
  for (unsigned v = 3; v <= 15; ++v) {
    MonitorStatus d;
    const DecodeResult r = decode(make_frame(0x320, Bytes{static_cast<std::uint8_t>(v << 4)}), d);
    EXPECT_EQ(r.error, CodecError::kInvalidEnum);
    EXPECT_STREQ(r.signal, "Corner");
  }
  for (unsigned v = 5; v <= 15; ++v) {
    const auto raw = static_cast<std::uint8_t>(v);
    MonitorStatus ds;
    const DecodeResult rs = decode(make_frame(0x321, Bytes{0, raw}), ds);
    EXPECT_EQ(rs.error, CodecError::kInvalidEnum);
    EXPECT_STREQ(rs.signal, "AlarmLevel");
    AlarmEvent de;
    EXPECT_STREQ(decode(make_frame(0x330, Bytes{raw}), de).signal, "Level");
    EXPECT_STREQ(decode(make_frame(0x330, Bytes{static_cast<std::uint8_t>(raw << 4)}), de).signal,
                 "PreviousLevel");
    Acknowledge dk;
    const DecodeResult rk = decode(make_frame(0x340, Bytes{raw}), dk);
    EXPECT_EQ(rk.error, CodecError::kInvalidEnum);
    EXPECT_STREQ(rk.signal, "Level");
  }
  for (unsigned v = 20; v <= 255; ++v) {
    AlarmEvent d;
    const DecodeResult r = decode(make_frame(0x330, Bytes{0, static_cast<std::uint8_t>(v)}), d);
    EXPECT_EQ(r.error, CodecError::kInvalidEnum);
    EXPECT_STREQ(r.signal, "Cause");
  }
  // Encode: values no enumerator names.
  CanFrame f;
  MonitorStatus s;
  s.phase = static_cast<Phase>(7);
  EXPECT_EQ(encode(s, f).error, CodecError::kInvalidEnum);
  s = MonitorStatus{};
  s.corner = static_cast<Corner>(3);
  EXPECT_STREQ(encode(s, f).signal, "Corner");
  s = MonitorStatus{};
  s.alarm_level = static_cast<AlarmLevel>(5);
  EXPECT_STREQ(encode(s, f).signal, "AlarmLevel");
  AlarmEvent e;
  e.cause = static_cast<AlarmCause>(20);
  EXPECT_EQ(encode(e, f).error, CodecError::kInvalidEnum);
  for (const AlarmCause cause :
       {AlarmCause::kPWave, AlarmCause::kStatueUnexplained, AlarmCause::kRegionalAlert,
        AlarmCause::kStatueSensorFault, AlarmCause::kRestored, AlarmCause::kStatueStands,
        AlarmCause::kCommissioningFailed}) {
    e.cause = cause;
    EXPECT_TRUE(encode(e, f).ok()) << static_cast<unsigned>(cause);
  }
  e = AlarmEvent{};
  e.previous_level = static_cast<AlarmLevel>(255);
  EXPECT_STREQ(encode(e, f).signal, "PreviousLevel");
  Acknowledge k;
  k.level = static_cast<AlarmLevel>(7);
  EXPECT_EQ(encode(k, f).error, CodecError::kInvalidEnum);
}

TEST(CanReject, RiskAboveOne) {
  for (std::uint32_t raw = 10001; raw <= 65535; ++raw) {
    Bytes bytes{};
    bytes[2] = static_cast<std::uint8_t>(raw & 0xFF);
    bytes[3] = static_cast<std::uint8_t>(raw >> 8);
    MonitorStatus d;
    const DecodeResult r = decode(make_frame(0x320, bytes), d);
    ASSERT_EQ(r.error, CodecError::kOutOfRange) << raw;
    ASSERT_STREQ(r.signal, "Risk");
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double risk : {1.0001, 1.5, 2.0, -0.0001, -1.0, 1e300, -1e300}) {
    MonitorStatus m;
    m.risk = risk;
    CanFrame f;
    const EncodeResult r = encode(m, f);
    EXPECT_EQ(r.error, CodecError::kOutOfRange) << risk;
    EXPECT_STREQ(r.signal, "Risk");
  }
  for (const double risk : {nan, inf, -inf}) {
    MonitorStatus m;
    m.risk = risk;
    CanFrame f;
    EXPECT_EQ(encode(m, f).error, CodecError::kNotFinite);
  }
  // Values that round into the range are represented, not refused.
  for (const double risk : {1.0, 1.00004, 0.0, -0.00004, -0.0}) {
    MonitorStatus m;
    m.risk = risk;
    CanFrame f;
    EXPECT_TRUE(encode(m, f).ok()) << risk;
  }
}

// Every raw value of a CollapseForecast signal outside its range and special value, each refused
// naming the signal; encoding refuses the same values.
TEST(CanReject, CollapseForecastEveryInvalidRawValue) {
  CanFrame valid;
  ASSERT_TRUE(encode(forecast_of(17, 16, 1000), valid).ok());
  const auto with = [&valid](unsigned start, unsigned length, std::uint64_t raw) {
    CanFrame f = valid;
    store_le64(insert_bits(load_le64(f.data), start, length, raw), f.data);
    return f;
  };
  const auto expect_refused = [](const CanFrame& f, const char* signal, std::uint64_t raw) {
    CollapseForecast d;
    d.sequence = 77;
    const DecodeResult r = decode(f, d);
    ASSERT_EQ(r.error, CodecError::kOutOfRange) << signal << " " << raw;
    ASSERT_STREQ(r.signal, signal) << raw;
    ASSERT_EQ(d.sequence, 77);  // untouched
  };
  for (std::uint64_t raw = 10001; raw <= 65535; ++raw) {
    ASSERT_NO_FATAL_FAILURE(expect_refused(with(0, 16, raw), "Probability", raw));
  }
  for (std::uint64_t raw = 17; raw <= 254; ++raw) {
    ASSERT_NO_FATAL_FAILURE(expect_refused(with(16, 8, raw), "WorstMember", raw));
  }
  for (std::uint64_t raw = 0; raw <= 255; ++raw) {
    if (raw >= 1 && raw <= 17) continue;
    ASSERT_NO_FATAL_FAILURE(expect_refused(with(24, 8, raw), "Members", raw));
  }
  // Encode: the same values.
  CanFrame f;
  for (const double p : {1.00005, 1.5, -0.00005, -1.0, 1e300}) {
    CollapseForecast m = forecast_of(17, 16, 1000);
    m.probability = p;
    const EncodeResult r = encode(m, f);
    EXPECT_EQ(r.error, CodecError::kOutOfRange) << p;
    EXPECT_STREQ(r.signal, "Probability");
  }
  for (const double p :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    CollapseForecast m = forecast_of(17, 16, 1000);
    m.probability = p;
    EXPECT_EQ(encode(m, f).error, CodecError::kNotFinite);
    m = forecast_of(17, 16, 1000);
    m.horizon_s = p;
    EXPECT_STREQ(encode(m, f).signal, "Horizon");
  }
  for (unsigned worst = 17; worst <= 254; ++worst) {
    const EncodeResult r = encode(forecast_of(17, static_cast<std::uint8_t>(worst), 1), f);
    EXPECT_EQ(r.error, CodecError::kOutOfRange) << worst;
    EXPECT_STREQ(r.signal, "WorstMember");
  }
  for (const unsigned members : {0U, 18U, 200U, 255U}) {
    CollapseForecast m = forecast_of(1, 0, 1);
    m.members = static_cast<std::uint8_t>(members);
    EXPECT_STREQ(encode(m, f).signal, "Members") << members;
  }
  for (const double h : {25.55, 26.0, -0.05, -1.0}) {
    CollapseForecast m = forecast_of(2, 0, 1);
    m.horizon_s = h;
    const EncodeResult r = encode(m, f);
    EXPECT_EQ(r.error, CodecError::kOutOfRange) << h;
    EXPECT_STREQ(r.signal, "Horizon");
  }
  CollapseForecast m = forecast_of(2, 0, 1);
  m.axis = 2;
  EXPECT_STREQ(encode(m, f).signal, "axis");
}

// Signals that contradict each other: each valid alone, refused together naming the signal.
TEST(CanReject, CollapseForecastContradictions) {
  struct Case {
    std::uint64_t probability, worst, members, collapse_in;
    const char* signal;
  };
  const Case cases[] = {
      {1000, 5, 5, 100, "WorstMember"},  // the worst member is not one of the members
      {1000, 16, 1, 100, "WorstMember"},
      {1000, 3, 5, 65535, "CollapseIn"},     // a worst member without a collapse time
      {0, 255, 5, 100, "CollapseIn"},        // a collapse time without a worst member
      {0, 3, 5, 100, "Probability"},         // a member collapses, probability 0
      {1000, 255, 5, 65535, "Probability"},  // none collapses, probability not 0
  };
  for (const Case& c : cases) {
    std::uint64_t word = 0;
    word = insert_bits(word, 0, 16, c.probability);
    word = insert_bits(word, 16, 8, c.worst);
    word = insert_bits(word, 24, 8, c.members);
    word = insert_bits(word, 32, 16, c.collapse_in);
    CanFrame f = make_frame(0x350, Bytes{});
    store_le64(word, f.data);
    CollapseForecast d;
    const DecodeResult r = decode(f, d);
    EXPECT_EQ(r.error, CodecError::kOutOfRange) << c.signal;
    EXPECT_STREQ(r.signal, c.signal);

    CollapseForecast m;
    m.probability = static_cast<double>(c.probability) * kRiskStep;
    m.worst_member = static_cast<std::uint8_t>(c.worst);
    m.members = static_cast<std::uint8_t>(c.members);
    m.collapse_in_ms = static_cast<std::uint16_t>(c.collapse_in);
    const EncodeResult e = encode(m, f);
    EXPECT_EQ(e.error, CodecError::kOutOfRange) << c.signal;
    EXPECT_STREQ(e.signal, c.signal);
  }
  // A probability that rounds to 0 says none collapses; one that rounds to 1e-4 does not.
  CanFrame f;
  CollapseForecast m;
  m.probability = 0.00004;
  EXPECT_TRUE(encode(m, f).ok());
  m.probability = 0.00006;
  EXPECT_STREQ(encode(m, f).signal, "Probability");
}

TEST(CanReject, AccelerationNotFiniteOrOutOfRange) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const char* names[3] = {"Ax", "Ay", "Az"};
  for (int axis = 0; axis < 3; ++axis) {
    auto with = [axis](double g) {
      SensorAcceleration m;
      (axis == 0 ? m.ax_g : axis == 1 ? m.ay_g : m.az_g) = g;
      return m;
    };
    CanFrame f;
    for (const double g : {nan, -nan, inf, -inf}) {
      const EncodeResult r = encode(with(g), f);
      EXPECT_EQ(r.error, CodecError::kNotFinite);
      EXPECT_STREQ(r.signal, names[axis]);
    }
    // 8.1919 g is raw 32767.6, rounding to 32768; -8.1922 g is raw -32768.8, rounding to -32769.
    for (const double g : {8.1919, 8.2, 9.0, -8.1922, -8.2, 1e300, -1e300, 1e20}) {
      const EncodeResult r = encode(with(g), f);
      EXPECT_EQ(r.error, CodecError::kOutOfRange) << g;
      EXPECT_STREQ(r.signal, names[axis]);
    }
    for (const double g : {8.19175, 8.19187, -8.192, -8.19212}) {
      EXPECT_TRUE(encode(with(g), f).ok()) << g;
    }
  }
}

TEST(CanReject, NodeAxisAndNibbleOutOfRange) {
  CanFrame f;
  for (const unsigned node : {0U, 16U, 255U}) {
    SensorAcceleration a;
    a.node = static_cast<std::uint8_t>(node);
    const EncodeResult r = encode(a, f);
    EXPECT_EQ(r.error, CodecError::kOutOfRange);
    EXPECT_STREQ(r.signal, "node");
    SensorHeartbeat h;
    h.node = static_cast<std::uint8_t>(node);
    EXPECT_EQ(encode(h, f).error, CodecError::kOutOfRange);
  }
  MonitorStatus s;
  s.axis = 2;
  EXPECT_STREQ(encode(s, f).signal, "axis");
  SensorHeartbeat h;
  h.firmware_major = 16;
  EXPECT_STREQ(encode(h, f).signal, "FirmwareMajor");
  h = SensorHeartbeat{};
  h.firmware_minor = 200;
  EXPECT_STREQ(encode(h, f).signal, "FirmwareMinor");
}

TEST(CanReject, OutputsUntouchedOnFailure) {
  CanFrame f = make_frame(0x123, Bytes{1, 2, 3, 4, 5, 6, 7, 8}, 3);
  const CanFrame before = f;
  SensorAcceleration a;
  a.ax_g = std::numeric_limits<double>::quiet_NaN();
  ASSERT_FALSE(encode(a, f).ok());
  EXPECT_EQ(f.id, before.id);
  EXPECT_EQ(f.length, before.length);
  EXPECT_EQ(f.data, before.data);

  MonitorStatus m;
  m.risk = 0.25;
  m.sequence = 9;
  Bytes bad{0x07};  // Phase 7: not in the table
  ASSERT_FALSE(decode(make_frame(0x320, bad), m).ok());
  EXPECT_EQ(m.risk, 0.25);
  EXPECT_EQ(m.sequence, 9);
}

TEST(CanReject, ErrorTexts) {
  for (unsigned e = 0; e <= static_cast<unsigned>(CodecError::kReservedBitsSet); ++e) {
    const char* text = codec_error_text(static_cast<CodecError>(e));
    ASSERT_NE(text, nullptr);
    EXPECT_GT(std::string(text).size(), 1U);
    EXPECT_NE(std::string(text), "unknown error");
  }
}

// ---------------------------------------------------------------------------------------------
// The codec against plinth.dbc

TEST(CanDbc, EveryIdentifierTheCodecKnowsIsAMessageAndNoOther) {
  const Dbc& dbc = plinth_dbc();
  ASSERT_EQ(dbc.messages.size(), 55U);
  for (std::uint32_t id = 0; id <= 0x7FF; ++id) {
    const MessageKind kind = classify(id);
    const auto it = dbc.messages.find(id);
    if (kind == MessageKind::kUnknown) {
      EXPECT_EQ(it, dbc.messages.end()) << "DBC message " << id << " unknown to the codec";
      continue;
    }
    ASSERT_NE(it, dbc.messages.end()) << "identifier " << id << " missing from the DBC";
    EXPECT_GE(id, kFirstPlinthId);
    EXPECT_LE(id, kLastPlinthId);
    EXPECT_EQ(it->second.dlc, kFrameLength) << it->second.name;
    EXPECT_EQ(it->second.name.rfind(message_kind_name(kind), 0), 0U)
        << it->second.name << " is not a " << message_kind_name(kind);
  }
}

TEST(CanDbc, EverySignalMatchesTheCodecsLayout) {
  const Dbc& dbc = plinth_dbc();
  for (const auto& [id, message] : dbc.messages) {
    const std::span<const SignalLayout> layouts = signal_layouts(classify(id));
    ASSERT_EQ(message.signals.size(), layouts.size()) << message.name;
    for (std::size_t i = 0; i < layouts.size(); ++i) {
      const SignalLayout& c = layouts[i];
      const DbcSignal& d = message.signals[i];
      SCOPED_TRACE(message.name + "." + d.name);
      EXPECT_EQ(d.name, c.name);
      EXPECT_EQ(d.start, c.start_bit);
      EXPECT_EQ(d.length, c.length);
      EXPECT_EQ(d.byte_order, '1');  // Intel
      EXPECT_EQ(d.sign, c.is_signed ? '-' : '+');
      EXPECT_EQ(d.factor, c.factor);
      EXPECT_EQ(d.offset, c.offset);
      EXPECT_NEAR(d.minimum, static_cast<double>(c.raw_min) * c.factor + c.offset,
                  1e-9 * std::fabs(d.minimum) + 1e-12);
      EXPECT_NEAR(d.maximum, static_cast<double>(c.raw_max) * c.factor + c.offset,
                  1e-9 * std::fabs(d.maximum) + 1e-12);
      EXPECT_EQ(d.unit, c.unit);
      // The raw range fits the bits.
      if (c.is_signed) {
        EXPECT_GE(c.raw_min, -(std::int64_t{1} << (c.length - 1)));
        EXPECT_LE(c.raw_max, (std::int64_t{1} << (c.length - 1)) - 1);
      } else {
        EXPECT_GE(c.raw_min, 0);
        EXPECT_LE(c.raw_max, (std::int64_t{1} << c.length) - 1);
      }
      EXPECT_LE(c.start_bit + c.length, 64U);
      // A special value fits the bits and lies outside the range.
      if (c.special_raw != kNoSpecialRaw) {
        EXPECT_FALSE(c.is_signed);
        EXPECT_LE(c.special_raw, (std::int64_t{1} << c.length) - 1);
        EXPECT_TRUE(c.special_raw < c.raw_min || c.special_raw > c.raw_max);
      }
    }
    // Signals do not overlap.
    std::uint64_t used = 0;
    for (const SignalLayout& c : layouts) {
      EXPECT_EQ(used & bit_mask(c.start_bit, c.length), 0U) << message.name << "." << c.name;
      used |= bit_mask(c.start_bit, c.length);
    }
  }
}

// The names of the values are the domain types' (firmware's test_can_frames.cpp checks them
// against these tables); the codec's part is the range.
TEST(CanDbc, ValueTablesMatchTheCodecsEnumerations) {
  const Dbc& dbc = plinth_dbc();
  for (const auto& [id, message] : dbc.messages) {
    for (const SignalLayout& c : signal_layouts(classify(id))) {
      SCOPED_TRACE(message.name + "." + c.name);
      const auto it = dbc.values.find({id, c.name});
      ASSERT_EQ(it != dbc.values.end(), c.has_value_table || c.special_raw != kNoSpecialRaw);
      if (c.special_raw != kNoSpecialRaw) {
        // A quantity's table names its special value only.
        ASSERT_FALSE(c.has_value_table);
        ASSERT_EQ(it->second.size(), 1U);
        EXPECT_EQ(static_cast<std::int64_t>(it->second.begin()->first), c.special_raw);
        EXPECT_EQ(it->second.begin()->second, "none");
        continue;
      }
      if (!c.has_value_table) continue;
      const auto& table = it->second;
      // The table is exactly raw_min..raw_max: what decode accepts is what the DBC names.
      ASSERT_EQ(table.size(), static_cast<std::size_t>(c.raw_max - c.raw_min + 1));
      for (const auto& [value, name] : table) {
        EXPECT_GE(static_cast<std::int64_t>(value), c.raw_min);
        EXPECT_LE(static_cast<std::int64_t>(value), c.raw_max);
        EXPECT_FALSE(name.empty()) << value;
      }
    }
  }
}

TEST(CanDbc, EveryMessageAndSignalIsDocumented) {
  const Dbc& dbc = plinth_dbc();
  EXPECT_TRUE(dbc.network_comment);
  for (const auto& [id, message] : dbc.messages) {
    EXPECT_EQ(dbc.message_comments.count(id), 1U) << message.name;
    for (const DbcSignal& s : message.signals) {
      EXPECT_EQ(dbc.signal_comments.count({id, s.name}), 1U) << message.name << "." << s.name;
    }
  }
}

}  // namespace
}  // namespace plinth::hal::can

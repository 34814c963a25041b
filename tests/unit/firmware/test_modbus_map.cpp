// plinth-monitor's Modbus map (firmware/linux/modbus_map.h): the shipped modbus-map.csv is the
// code's map, the registers and discrete inputs of a snapshot, the run's identity (version and
// file digests), the pinned codes.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include "modbus_map.h"
#include "plinth/version/version.h"

namespace plinth::firmware::modbus {
namespace {

TEST(ModbusMap, TheShippedCsvIsTheCodesMap) {
  const std::string path = std::string(PLINTH_SOURCE_DIR) + "/firmware/linux/modbus-map.csv";
  std::ifstream file(path, std::ios::binary);
  ASSERT_TRUE(file) << path;
  std::ostringstream text;
  text << file.rdbuf();
  EXPECT_EQ(text.str(), map_csv())
      << path << " differs from the code's map: write it again with\n"
      << "  plinth-monitor --modbus-map > firmware/linux/modbus-map.csv";
}

TEST(ModbusMap, EveryCauseHasItsCodeInTheCsv) {
  const std::string csv = map_csv();
  EXPECT_NE(csv.find("10=collapse_forecast;11=not_calibrated;12=outside_model;13=p_wave;"
                     "14=statue_unexplained;15=regional_alert;16=statue_sensor_fault;"
                     "17=restored;18=statue_stands;19=commissioning_failed\""),
            std::string::npos);
  EXPECT_NE(csv.find("4=overturned;5=fell;6=lifted_off\""), std::string::npos);
  EXPECT_NE(csv.find("\"0=normal;1=advisory;2=warning;3=alarm;4=fault\""), std::string::npos);
}

// The pinned codes are the ones documented (docs/integration.md), whatever the domain's and
// the CAN wire's numbering.
TEST(ModbusMap, CodesArePinned) {
  EXPECT_EQ(kAlarmCauseCodes.code(monitor::AlarmCause::kCollapseForecast), 10);
  EXPECT_EQ(kAlarmCauseCodes.code(monitor::AlarmCause::kNotCalibrated), 11);
  EXPECT_EQ(kAlarmCauseCodes.code(monitor::AlarmCause::kOutsideModel), 12);
  EXPECT_EQ(kAlarmCauseCodes.code(monitor::AlarmCause::kPWave), 13);
  EXPECT_EQ(kAlarmCauseCodes.code(monitor::AlarmCause::kStatueUnexplained), 14);
  EXPECT_EQ(kAlarmCauseCodes.code(monitor::AlarmCause::kRegionalAlert), 15);
  EXPECT_EQ(kAlarmCauseCodes.code(monitor::AlarmCause::kCommissioningFailed), 19);
  EXPECT_EQ(kAlarmLevelCodes.code(monitor::AlarmLevel::kFault), 4);
  EXPECT_EQ(kPhaseCodes.code(Phase::kFell), 5);
  EXPECT_EQ(kPhaseCodes.code(Phase::kLiftedOff), 6);
  EXPECT_EQ(kHealthStateCodes.code(monitor::HealthState::kDegraded), 1);
  EXPECT_EQ(kAckOutcomeCodes.code(monitor::AckOutcome::kNothingLatched), 5);
}

std::uint32_t read32(const Image& image, int address) {
  return (std::uint32_t{image.registers[static_cast<std::size_t>(address)]} << 16) |
         image.registers[static_cast<std::size_t>(address + 1)];
}

TEST(ModbusMap, ASnapshotsRegisters) {
  StatusSnapshot s;
  s.level = monitor::AlarmLevel::kWarning;
  s.latched = monitor::AlarmLevel::kWarning;
  s.cause = monitor::AlarmCause::kNotCalibrated;
  s.any_event = true;
  s.event_sequence = 7;
  s.risk = 0.43214;
  s.probability = 0.5;
  s.forecast_axis = 1;
  s.forecast_worst_member = 3;
  s.t = 10.0;
  s.collapse_forecast = true;
  s.collapse_forecast_t = 12.3456;
  s.axis_count = 2;
  s.phase = {Phase::kRocking, Phase::kFell};
  s.sensor = monitor::HealthState::kDegraded;
  s.sensor_counters.fed = 0x12345678;
  s.sensor_counters.out_of_range = 2;
  s.sensor_counters.non_finite = 1;
  s.estimator_restarts = 5'000'000'000ULL;  // saturates
  s.uptime_ns = 3'500'000'000;
  s.statuses = 65537;
  Image image;
  fill(s, 4, image);
  const auto at = [&](int address) { return image.registers[static_cast<std::size_t>(address)]; };
  EXPECT_EQ(at(reg::kAlarmLevel), 2);
  EXPECT_EQ(at(reg::kHeartbeat), 1) << "modulo 65536";
  EXPECT_EQ(at(reg::kRisk), 4321);
  EXPECT_EQ(at(reg::kCause), 11);
  EXPECT_EQ(at(reg::kEventSequence), 7);
  EXPECT_EQ(at(reg::kPhaseX), 2);
  EXPECT_EQ(at(reg::kPhaseY), 5);
  EXPECT_EQ(at(reg::kSensorHealth), 1);
  EXPECT_EQ(read32(image, reg::kUptime), 3U);
  EXPECT_EQ(read32(image, reg::kSamplesFed), 0x12345678U);
  EXPECT_EQ(read32(image, reg::kSamplesRejected), 3U);
  EXPECT_EQ(read32(image, reg::kEstimatorRestarts), 0xFFFFFFFFU);
  EXPECT_EQ(at(reg::kAlarmEvents), 4);
  EXPECT_EQ(at(reg::kMapVersion), 8);
  EXPECT_EQ(at(reg::kProbability), 5000);
  EXPECT_EQ(at(reg::kForecastAxis), 1);
  EXPECT_EQ(at(reg::kCollapseIn), 2346) << "ms, rounded up";
  EXPECT_EQ(at(reg::kForecastWorstMember), 3);
  for (int level = 0; level < discrete::kCount; ++level) {
    EXPECT_EQ(image.discrete_inputs[static_cast<std::size_t>(level)], level == 2 ? 1 : 0) << level;
  }
}

// The statue sensor's registers: kNone without one; with one, its streams' health, its offset,
// and per axis the weights' code (pinned: 0 not measured .. 3 unexplained) and effective members.
TEST(ModbusMap, TheStatueSensorsRegisters) {
  StatusSnapshot s;
  Image image;
  fill(s, 0, image);
  const auto at = [&](int address) { return image.registers[static_cast<std::size_t>(address)]; };
  for (int r = reg::kStatueRateHealth; r <= reg::kStatueEffectiveMembersY; ++r) {
    EXPECT_EQ(at(r), kNone) << r;
  }
  EXPECT_EQ(reg::kStatueRateHealth, 102) << "after 86-101, the regional alerts'";
  s.has_statue_sensor = true;
  s.axis_count = 1;
  s.statue_rate = monitor::HealthState::kOk;
  s.statue_acceleration = monitor::HealthState::kDegraded;
  s.statue_ready = true;
  s.statue_axes[0] = {true, true, false, true, Real(2.345), Real(1.1), 4};
  fill(s, 0, image);
  EXPECT_EQ(at(reg::kStatueRateHealth), 0);
  EXPECT_EQ(at(reg::kStatueAccelerationHealth), 1);
  EXPECT_EQ(at(reg::kStatueReady), 1);
  EXPECT_EQ(at(reg::kStatueWeightsX), 2) << "weighted";
  EXPECT_EQ(at(reg::kStatueEffectiveMembersX), 235);
  EXPECT_EQ(at(reg::kStatueWeightsY), kNone) << "one axis";
  EXPECT_EQ(at(reg::kStatueEffectiveMembersY), kNone);
  s.axis_count = 2;
  s.statue_axes[0].unexplained = true;
  s.statue_axes[0].weighted = false;
  s.statue_axes[1] = {true, false, false, false, Real(17), Real(0), 0};
  fill(s, 0, image);
  EXPECT_EQ(at(reg::kStatueWeightsX), 3) << "unexplained";
  EXPECT_EQ(at(reg::kStatueWeightsY), 1) << "uninformative";
  EXPECT_EQ(at(reg::kStatueEffectiveMembersY), 1700);
  s.statue_axes[1].measured = false;
  fill(s, 0, image);
  EXPECT_EQ(at(reg::kStatueWeightsY), 0) << "not measured";
  // Map 6: the regional alerts' registers (86-101) end where the statue sensor's begin, and
  // every register up to reg::kCount is one point's (5 had 86-101 reserved on main).
  EXPECT_EQ(reg::kRegionalHeld, 86);
  EXPECT_EQ(reg::kRegionalLastRefusal + 1, reg::kStatueRateHealth);
  std::array<int, reg::kCount> owners{};
  for (const Point& p : points()) {
    if (p.table != Table::kRegister) continue;
    for (int r = p.address; r < p.address + p.words; ++r) ++owners[static_cast<std::size_t>(r)];
  }
  for (int r = 0; r < reg::kCount; ++r) EXPECT_EQ(owners[static_cast<std::size_t>(r)], 1) << r;
}

// The safety rule's registers (117-118, map 8): the trouble beside the level, coded as the
// cause register, and the held collapse.
TEST(ModbusMap, TheTroubleAndTheHeldCollapse) {
  StatusSnapshot s;
  Image image;
  fill(s, 0, image);
  const auto at = [&](int address) { return image.registers[static_cast<std::size_t>(address)]; };
  EXPECT_EQ(reg::kCollapseHeld + 1, reg::kCount);
  EXPECT_EQ(at(reg::kTrouble), 0);
  EXPECT_EQ(at(reg::kCollapseHeld), 0);
  s.trouble = monitor::AlarmCause::kStatueSensorFault;
  s.collapse_held = true;
  fill(s, 0, image);
  EXPECT_EQ(at(reg::kTrouble), 16);
  EXPECT_EQ(at(reg::kCollapseHeld), 1);
}

// The event recorder's registers (109-116, map 7): kNone in health and problem without one
// (--record-dir), else their pinned codes and the counts.
TEST(ModbusMap, TheRecordersRegisters) {
  StatusSnapshot s;
  Image image;
  fill(s, 0, image);
  const auto at = [&](int address) { return image.registers[static_cast<std::size_t>(address)]; };
  EXPECT_EQ(reg::kRecorderHealth, reg::kStatueEffectiveMembersY + 1);
  EXPECT_EQ(reg::kTrouble, reg::kCapturesTruncated + 2);
  EXPECT_EQ(at(reg::kRecorderHealth), kNone);
  EXPECT_EQ(at(reg::kRecorderProblem), kNone);
  EXPECT_EQ(read32(image, reg::kCapturesWritten), 0U);
  s.recorder.present = true;
  fill(s, 0, image);
  EXPECT_EQ(at(reg::kRecorderHealth), 0) << "ok";
  EXPECT_EQ(at(reg::kRecorderProblem), 0) << "none";
  s.recorder.health = RecorderHealth::kFailed;
  s.recorder.problem = RecorderProblem::kDiskFull;
  s.recorder.captures_written = 3;
  s.recorder.captures_lost = 0x10002;
  s.recorder.captures_truncated = 1;
  fill(s, 0, image);
  EXPECT_EQ(at(reg::kRecorderHealth), 2);
  EXPECT_EQ(at(reg::kRecorderProblem), 5);
  EXPECT_EQ(read32(image, reg::kCapturesWritten), 3U);
  EXPECT_EQ(read32(image, reg::kCapturesLost), 0x10002U);
  EXPECT_EQ(read32(image, reg::kCapturesTruncated), 1U);
  EXPECT_EQ(kRecorderHealthCodes.code(RecorderHealth::kDegraded), 1);
  EXPECT_EQ(kRecorderProblemCodes.code(RecorderProblem::kFolderInUse), 3);
  EXPECT_EQ(kRecorderProblemCodes.code(RecorderProblem::kTruncated), 9);
}

std::uint64_t read64(const Image& image, int address) {
  return (std::uint64_t{read32(image, address)} << 32) | read32(image, address + 2);
}

TEST(ModbusMap, TheRunsIdentity) {
  RunIdentity identity;
  identity.scene = sha256("abc");  // ba7816bf 8f01cfea ...
  identity.config = sha256("");    // e3b0c442 98fc1c14 ...
  Image image;
  fill_identity(identity, image);
  const auto at = [&](int address) { return image.registers[static_cast<std::size_t>(address)]; };
  EXPECT_EQ(at(reg::kSceneGiven), 1);
  EXPECT_EQ(at(reg::kSceneSha256), 0xba78) << "the high word first";
  EXPECT_EQ(at(reg::kSceneSha256 + 3), 0xcfea);
  EXPECT_EQ(read64(image, reg::kSceneSha256), 0xba7816bf8f01cfeaULL);
  EXPECT_EQ(at(reg::kConfigGiven), 1);
  EXPECT_EQ(read64(image, reg::kConfigSha256), 0xe3b0c44298fc1c14ULL);
  // No second scene: its flag 0, kNone in each register of its digest.
  EXPECT_EQ(at(reg::kSceneYGiven), 0);
  for (int i = 0; i < reg::kDigestWords; ++i) EXPECT_EQ(at(reg::kSceneYSha256 + i), kNone) << i;
  // A snapshot leaves them as they are.
  StatusSnapshot s;
  fill(s, 0, image);
  EXPECT_EQ(read64(image, reg::kSceneSha256), 0xba7816bf8f01cfeaULL);
  EXPECT_EQ(at(reg::kSceneYGiven), 0);
  // The version: the numbers of kProjectVersion, the description two characters a register.
  const std::string numbers = std::to_string(at(reg::kVersionMajor)) + "." +
                              std::to_string(at(reg::kVersionMinor)) + "." +
                              std::to_string(at(reg::kVersionPatch));
  EXPECT_EQ(numbers, version::kProjectVersion);
  std::string description;
  for (int i = 0; i < reg::kGitDescriptionWords; ++i) {
    for (const int shift : {8, 0}) {
      const char c = static_cast<char>((at(reg::kGitDescription + i) >> shift) & 0xFF);
      if (c != '\0') description += c;
    }
  }
  EXPECT_EQ(description, std::string(version::kGitDescription).substr(0, 64));
}

TEST(ModbusMap, NoValueReads65535) {
  StatusSnapshot s;  // before the first event and forecast, one axis
  s.t = 3.0;
  s.collapse_forecast_t = 1.0;
  Image image;
  fill(s, 0, image);
  const auto at = [&](int address) { return image.registers[static_cast<std::size_t>(address)]; };
  EXPECT_EQ(at(reg::kEventSequence), kNone);
  EXPECT_EQ(at(reg::kPhaseY), kNone);
  EXPECT_EQ(at(reg::kForecastAxis), kNone);
  EXPECT_EQ(at(reg::kCollapseIn), kNone);
  EXPECT_EQ(at(reg::kForecastWorstMember), kNone);
  s.collapse_forecast = true;  // forecast for a time already past: due
  fill(s, 0, image);
  EXPECT_EQ(at(reg::kCollapseIn), 0);
  EXPECT_EQ(image.discrete_inputs[0], 1) << "normal";
}

}  // namespace
}  // namespace plinth::firmware::modbus

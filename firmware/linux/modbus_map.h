// plinth-monitor's Modbus map: every register, discrete input and coil with its address, type,
// scale and codes (docs/integration.md; shipped as modbus-map.csv, which map_csv() writes and a
// test compares). The codes are Modbus's own, pinned here by name of the domain value: the CAN
// wire's numbering (hal/can_codec/plinth.dbc) or a domain enum renumbered leaves them as they
// are, and a value a domain enum gains does not compile until it has a code here.
// Host code: allocates.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "plinth/core/name_table.h"
#include "plinth/core/state.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/regional_alert.h"
#include "plinth/monitor/sensor_health.h"
#include "recorder_status.h"
#include "run_identity.h"
#include "status_outputs.h"

namespace plinth::firmware::modbus {

inline constexpr std::uint16_t kNone = 0xFFFF;  // a register with no value (yet)
inline constexpr std::uint16_t kMapVersion = 8;  // register 31; 2: holding registers, discrete
                                                 // inputs, causes 10-11, forecast, version;
                                                 // 3: the files' digests; 4 (issue 26's branch):
                                                 // regional alerts (86-101), cause 15; 5: two
                                                 // maps, cause 13 on issue 26's branch, the
                                                 // statue sensor (102-108, cause 14; 86-101
                                                 // reserved) on main; 6: both, no gap; 7: the
                                                 // event recorder's health (109-116); 8: the
                                                 // trouble and the held collapse (117-118),
                                                 // coil 2 statue_stands

template <class Enum>
struct Code {
  Enum value;
  std::uint16_t code;
};

template <class Enum, std::size_t N>
struct CodeTable {
  std::array<Code<Enum>, N> codes;
  [[nodiscard]] constexpr std::uint16_t code(Enum value) const {
    for (const Code<Enum>& c : codes) {
      if (c.value == value) return c.code;
    }
    return kNone;
  }
};

// The pinned codes. Never change a code: a BMS point list refers to it; a new value takes the
// next free code.
inline constexpr CodeTable<monitor::AlarmLevel, 5> kAlarmLevelCodes{{{
    {monitor::AlarmLevel::kNormal, 0},
    {monitor::AlarmLevel::kAdvisory, 1},
    {monitor::AlarmLevel::kWarning, 2},
    {monitor::AlarmLevel::kAlarm, 3},
    {monitor::AlarmLevel::kFault, 4},
}}};
inline constexpr CodeTable<monitor::AlarmCause, 20> kAlarmCauseCodes{{{
    {monitor::AlarmCause::kNone, 0},
    {monitor::AlarmCause::kRiskThreshold, 1},
    {monitor::AlarmCause::kPhaseChange, 2},
    {monitor::AlarmCause::kOverturnDetected, 3},
    {monitor::AlarmCause::kSensorTimeout, 4},
    {monitor::AlarmCause::kSensorFault, 5},
    {monitor::AlarmCause::kSensorDisagreement, 6},
    {monitor::AlarmCause::kAcknowledged, 7},
    {monitor::AlarmCause::kBusError, 8},
    {monitor::AlarmCause::kInternalFault, 9},
    {monitor::AlarmCause::kCollapseForecast, 10},
    {monitor::AlarmCause::kNotCalibrated, 11},
    {monitor::AlarmCause::kOutsideModel, 12},
    {monitor::AlarmCause::kPWave, 13},
    {monitor::AlarmCause::kStatueUnexplained, 14},
    {monitor::AlarmCause::kRegionalAlert, 15},
    {monitor::AlarmCause::kStatueSensorFault, 16},
    {monitor::AlarmCause::kRestored, 17},
    {monitor::AlarmCause::kStatueStands, 18},
    {monitor::AlarmCause::kCommissioningFailed, 19},
}}};
inline constexpr CodeTable<Phase, 7> kPhaseCodes{{{
    {Phase::kFullContact, 0},
    {Phase::kSliding, 1},
    {Phase::kRocking, 2},
    {Phase::kSlideRocking, 3},
    {Phase::kOverturned, 4},
    {Phase::kFell, 5},
    {Phase::kLiftedOff, 6},
}}};
inline constexpr CodeTable<monitor::HealthState, 3> kHealthStateCodes{{{
    {monitor::HealthState::kOk, 0},
    {monitor::HealthState::kDegraded, 1},
    {monitor::HealthState::kFault, 2},
}}};
inline constexpr CodeTable<monitor::AckOutcome, 6> kAckOutcomeCodes{{{
    {monitor::AckOutcome::kNone, 0},
    {monitor::AckOutcome::kReleased, 1},
    {monitor::AckOutcome::kReleasedConditionHolds, 2},
    {monitor::AckOutcome::kStale, 3},
    {monitor::AckOutcome::kWrongLevel, 4},
    {monitor::AckOutcome::kNothingLatched, 5},
}}};

inline constexpr CodeTable<monitor::RegionalRefusal, monitor::kRegionalRefusalCount>
    kRegionalRefusalCodes{{{
        {monitor::RegionalRefusal::kNone, 0},
        {monitor::RegionalRefusal::kMalformed, 1},
        {monitor::RegionalRefusal::kNotFinite, 2},
        {monitor::RegionalRefusal::kOutOfRange, 3},
        {monitor::RegionalRefusal::kInconsistent, 4},
        {monitor::RegionalRefusal::kFutureDated, 5},
        {monitor::RegionalRefusal::kStale, 6},
        {monitor::RegionalRefusal::kDuplicate, 7},
        {monitor::RegionalRefusal::kOutOfOrder, 8},
        {monitor::RegionalRefusal::kNoRoom, 9},
        {monitor::RegionalRefusal::kUnauthenticated, 10},
    }}};

inline constexpr CodeTable<RecorderHealth, 3> kRecorderHealthCodes{{{
    {RecorderHealth::kOk, 0},
    {RecorderHealth::kDegraded, 1},
    {RecorderHealth::kFailed, 2},
}}};
inline constexpr CodeTable<RecorderProblem, 10> kRecorderProblemCodes{{{
    {RecorderProblem::kNone, 0},
    {RecorderProblem::kFolderMissing, 1},
    {RecorderProblem::kNotWritable, 2},
    {RecorderProblem::kFolderInUse, 3},
    {RecorderProblem::kLockFile, 4},
    {RecorderProblem::kDiskFull, 5},
    {RecorderProblem::kWriteError, 6},
    {RecorderProblem::kNumberingExhausted, 7},
    {RecorderProblem::kWriterBehind, 8},
    {RecorderProblem::kTruncated, 9},
}}};

// Every value the domain names has exactly one code, and no two values share one.
template <class Enum, std::size_t N, std::size_t M>
[[nodiscard]] constexpr bool pins_every_value(const CodeTable<Enum, N>& table,
                                              const NameTable<Enum, M>& names) {
  if (N != M) return false;
  for (const NamedValue<Enum>& named : names) {
    int found = 0;
    for (const Code<Enum>& c : table.codes) found += c.value == named.value ? 1 : 0;
    if (found != 1) return false;
  }
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = i + 1; j < N; ++j) {
      if (table.codes[i].code == table.codes[j].code) return false;
    }
  }
  return true;
}
static_assert(pins_every_value(kAlarmLevelCodes, monitor::kAlarmLevelNames));
static_assert(pins_every_value(kAlarmCauseCodes, monitor::kAlarmCauseNames));
static_assert(pins_every_value(kPhaseCodes, kPhaseNames));
static_assert(pins_every_value(kHealthStateCodes, monitor::kHealthStateNames));
static_assert(pins_every_value(kAckOutcomeCodes, monitor::kAckOutcomeNames));
static_assert(pins_every_value(kRegionalRefusalCodes, monitor::kRegionalRefusalNames));
static_assert(pins_every_value(kRecorderHealthCodes, kRecorderHealthNames));
static_assert(pins_every_value(kRecorderProblemCodes, kRecorderProblemNames));

// Registers (functions 03 and 04 read the same values), 0-based addresses. 32-bit values: two
// registers, the high word first; 64-bit values: four, the highest word first; text: two ASCII
// characters a register, the first in the high byte, NUL-padded.
namespace reg {
inline constexpr int kAlarmLevel = 0;     // kAlarmLevelCodes
inline constexpr int kHeartbeat = 1;      // status reports, modulo 65536
inline constexpr int kRisk = 2;           // risk x 10000 (0 .. 10000)
inline constexpr int kLatchedLevel = 3;   // kAlarmLevelCodes; 0: none latched
inline constexpr int kCause = 4;          // kAlarmCauseCodes, of the latest alarm event
inline constexpr int kEventSequence = 5;  // the latest alarm event's sequence; kNone: none yet
inline constexpr int kAxisCount = 6;      // 1 or 2
inline constexpr int kPhaseX = 7;         // kPhaseCodes
inline constexpr int kPhaseY = 8;         // kNone when the box models one axis
inline constexpr int kEstimating = 9;     // 1: the estimators run
inline constexpr int kSensorHealth = 10;  // the primary sensor's, kHealthStateCodes
inline constexpr int kSensorsState = 11;  // all sensors', kHealthStateCodes
inline constexpr int kUptime = 12;        // s since plinth-monitor started (32 bits)
inline constexpr int kSamplesFed = 14;    // the primary's counters (32 bits each) ...
inline constexpr int kSamplesBridged = 16;
inline constexpr int kSamplesMissing = 18;
inline constexpr int kSensorTimeouts = 20;
inline constexpr int kSensorFaults = 22;
inline constexpr int kSamplesRejected = 24;
inline constexpr int kEstimatorRestarts = 26;    // (32 bits)
inline constexpr int kLastAcknowledgement = 28;  // kAckOutcomeCodes, of the latest acknowledge
inline constexpr int kCommands = 29;             // operator commands carried out, modulo 65536
inline constexpr int kAlarmEvents = 30;          // alarm events so far, modulo 65536
inline constexpr int kMapVersion = 31;           // kMapVersion
inline constexpr int kProbability = 32;          // the forecast's probability x 10000
inline constexpr int kForecastAxis = 33;         // 0 x, 1 y; kNone: no forecast yet
inline constexpr int kCollapseIn = 34;  // ms to the forecast collapse, 0 once due; kNone: none
inline constexpr int kForecastWorstMember = 35;  // the member that collapses first; kNone: none
inline constexpr int kVersionMajor = 36;         // kProjectVersion, MAJOR.MINOR.PATCH
inline constexpr int kVersionMinor = 37;
inline constexpr int kVersionPatch = 38;
inline constexpr int kGitDescription = 39;  // kGitDescription, kGitDescriptionWords registers
inline constexpr int kGitDescriptionWords = 32;  // 64 characters
// Each file the box runs (run_identity.h): 1 while it was given, then its SHA-256's leading 64
// bits (kDigestWords registers); a file not given reads 0, then kNone in each register.
inline constexpr int kSceneGiven = 71;
inline constexpr int kSceneSha256 = 72;
inline constexpr int kSceneYGiven = 76;
inline constexpr int kSceneYSha256 = 77;
inline constexpr int kConfigGiven = 81;
inline constexpr int kConfigSha256 = 82;
inline constexpr int kDigestWords = 4;
// Regional alerts (docs/regional.md): the worst held alert and the counters.
inline constexpr int kRegionalHeld = 86;         // alerts held
inline constexpr int kRegionalProbability = 87;  // of collapse under the worst, x 10000
inline constexpr int kRegionalSArrivalIn = 88;   // 0.1 s to its S arrival, 0 once due; kNone
inline constexpr int kRegionalPga = 89;          // its expected PGA, 0.001 g; kNone
inline constexpr int kRegionalMagnitude = 90;    // its magnitude x 100; kNone
inline constexpr int kRegionalDistance = 91;     // its epicentral distance, km; kNone
inline constexpr int kRegionalEventId = 92;      // its event id (32 bits; 0 when none held)
inline constexpr int kRegionalVersion = 94;      // its version; kNone
inline constexpr int kRegionalReceived = 95;     // alerts received (32 bits)
inline constexpr int kRegionalAccepted = 97;     // accepted (32 bits)
inline constexpr int kRegionalRefused = 99;      // refused, every reason (32 bits)
inline constexpr int kRegionalLastRefusal = 101;  // kRegionalRefusalCodes
// The statue sensor (kNone in each without one): its gyroscope's and accelerometer's health
// (kHealthStateCodes), 1 once its rate offset is known, and per axis what its weights say
// (kStatueWeightsCodes; y kNone with one axis) and the effective members x 100.
inline constexpr int kStatueRateHealth = 102;
inline constexpr int kStatueAccelerationHealth = 103;
inline constexpr int kStatueReady = 104;
inline constexpr int kStatueWeightsX = 105;
inline constexpr int kStatueWeightsY = 106;
inline constexpr int kStatueEffectiveMembersX = 107;
inline constexpr int kStatueEffectiveMembersY = 108;
// The event recorder (kNone in health and problem without --record-dir): its health
// (kRecorderHealthCodes), why it failed or its latest loss (kRecorderProblemCodes), and its
// captures written, lost and cut short (32 bits each).
inline constexpr int kRecorderHealth = 109;
inline constexpr int kRecorderProblem = 110;
inline constexpr int kCapturesWritten = 111;
inline constexpr int kCapturesLost = 113;
inline constexpr int kCapturesTruncated = 115;
// The safety rule's (docs/safety.md): the trouble shown beside the level (an input the box
// does not trust: kAlarmCauseCodes, 0 none), and 1 while a collapse is held.
inline constexpr int kTrouble = 117;
inline constexpr int kCollapseHeld = 118;
inline constexpr int kCount = 119;
}  // namespace reg

// Discrete inputs (function 02): one per alarm level, 1 while that level is shown (exactly one
// is 1). Their addresses are the levels' codes.
namespace discrete {
inline constexpr int kCount = 5;
}  // namespace discrete

// Coils (functions 01, 05, 15): write 1 to act; they read 0.
namespace coil {
inline constexpr int kAcknowledge = 0;  // acknowledge the latched level (registers 3 and 5)
inline constexpr int kReset = 1;        // start the monitor again as at power-up
inline constexpr int kStatueStands = 2;  // a person on site states that the statue stands
inline constexpr int kCount = 3;
}  // namespace coil

enum class Table : std::uint8_t { kRegister, kDiscreteInput, kCoil };
enum class Type : std::uint8_t { kUint16, kUint32, kUint64, kAscii, kBit };
enum class Codes : std::uint8_t {
  kPlain,
  kAlarmLevel,
  kAlarmCause,
  kPhase,
  kHealthState,
  kAckOutcome,
  kAxis,
  kStatueWeights,
  kRegionalRefusal,
  kRecorderHealth,
  kRecorderProblem,
};

// What the statue sensor's weights say of an axis (StatueAxisStatus), pinned like the others.
enum class StatueWeights : std::uint8_t {
  kNotMeasured = 0,    // no fresh rate (no sensor, silent, at fault, offset not known yet)
  kUninformative = 1,  // measured, the weights do not yet tell the members apart: worst member
  kWeighted = 2,       // informative and explained: the risk is the weighted members'
  kUnexplained = 3,    // no member explains the motion (cause statue_unexplained)
};
[[nodiscard]] StatueWeights statue_weights(const StatueAxisStatus& axis);

// One row of the map (one line of modbus-map.csv).
struct Point {
  Table table;
  int address;
  int words;  // registers it takes; 1 for a bit
  Type type;
  const char* name;
  const char* scale;  // the quantity is the raw value times this
  const char* unit;   // of the quantity; "" for codes and counts
  bool none;          // kNone (65535; in each register of a uint64) means "no value"
  Codes codes;
  int bit_code;       // a discrete input: 1 while the field's code is this one; -1 otherwise
  const char* json;   // the field of the JSON lines with the same value, "" if none
  const char* meaning;
};

// The rows, in the CSV's order: registers, discrete inputs, coils, each by address.
inline constexpr std::size_t kPointCount = 72;
[[nodiscard]] const std::array<Point, kPointCount>& points();

// The values the server answers with.
struct Image {
  std::array<std::uint16_t, reg::kCount> registers{};
  std::array<std::uint8_t, discrete::kCount> discrete_inputs{};
};

// The registers and discrete inputs of `snapshot`, with `alarm_events` alarm events so far; the
// registers of the run's identity are left as they are.
void fill(const StatusSnapshot& snapshot, std::uint64_t alarm_events, Image& out);

// The registers that stay for a run: the version (36-70) and the files' digests (71-85), from
// `identity`. Once, at start.
void fill_identity(const RunIdentity& identity, Image& out);

// modbus-map.csv: a header, then one line per point.
[[nodiscard]] std::string map_csv();

}  // namespace plinth::firmware::modbus

#include "modbus_map.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "plinth/version/version.h"

namespace plinth::firmware::modbus {

namespace {

constexpr Point word(int address, const char* name, const char* json, const char* meaning,
                     Codes codes = Codes::kPlain, bool none = false) {
  return {Table::kRegister, address, 1, Type::kUint16, name, "1", "", none, codes, -1, json,
          meaning};
}
constexpr Point scaled(int address, const char* name, const char* scale, const char* unit,
                       bool none, const char* json, const char* meaning) {
  return {Table::kRegister, address, 1,    Type::kUint16, name, scale, unit, none,
          Codes::kPlain,     -1,      json, meaning};
}
constexpr Point counter(int address, const char* name, const char* json, const char* meaning) {
  return {Table::kRegister, address, 2,    Type::kUint32, name, "1", "", false,
          Codes::kPlain,     -1,      json, meaning};
}
// A file's two points: given (1 or 0), then its digest's leading 64 bits.
constexpr Point file_given(int address, const char* name, const char* meaning) {
  return word(address, name, "", meaning);
}
constexpr Point file_digest(int address, const char* name, const char* json,
                            const char* meaning) {
  return {Table::kRegister, address, reg::kDigestWords, Type::kUint64, name, "1", "", true,
          Codes::kPlain,     -1,      json,              meaning};
}
constexpr Point level_bit(monitor::AlarmLevel level, const char* name) {
  const int code = kAlarmLevelCodes.code(level);
  return {Table::kDiscreteInput, code, 1, Type::kBit, name, "1", "", false, Codes::kAlarmLevel,
          code, "status.alarm", "1 while this level is shown"};
}
constexpr Point coil_point(int address, const char* name, const char* meaning) {
  return {Table::kCoil, address, 1, Type::kBit, name, "1", "", false, Codes::kPlain, -1, "",
          meaning};
}

constexpr std::array<Point, kPointCount> kPoints = {{
    word(reg::kAlarmLevel, "alarm_level", "status.alarm", "alarm level shown",
         Codes::kAlarmLevel),
    word(reg::kHeartbeat, "heartbeat", "",
         "status reports so far (the JSON status lines), modulo 65536"),
    scaled(reg::kRisk, "risk", "0.0001", "", false, "status.risk",
           "overturning risk, 0 .. 1 (risk 0.4321 reads 4321)"),
    word(reg::kLatchedLevel, "latched_level", "status.latched",
         "level latched until acknowledged; 0: nothing latched", Codes::kAlarmLevel),
    word(reg::kCause, "cause", "alarm.cause", "cause of the latest alarm event",
         Codes::kAlarmCause),
    word(reg::kEventSequence, "event_sequence", "alarm.sequence",
         "sequence of the latest alarm event (0 .. 255); 65535 before the first", Codes::kPlain,
         true),
    word(reg::kAxisCount, "axis_count", "", "axes modelled: 1 or 2"),
    word(reg::kPhaseX, "phase_x", "status.phase", "phase of axis x", Codes::kPhase),
    word(reg::kPhaseY, "phase_y", "", "phase of axis y; 65535 with one axis", Codes::kPhase,
         true),
    word(reg::kEstimating, "estimating", "status.estimating", "1 while the estimators run"),
    word(reg::kSensorHealth, "sensor_health", "status.sensor", "health of the primary sensor",
         Codes::kHealthState),
    word(reg::kSensorsState, "sensors_state", "status.sensors_state", "state of all sensors",
         Codes::kHealthState),
    {Table::kRegister, reg::kUptime, 2, Type::kUint32, "uptime", "1", "s", false, Codes::kPlain,
     -1, "", "s since plinth-monitor started"},
    counter(reg::kSamplesFed, "samples_fed", "summary.sensor.fed",
            "samples of the primary sensor fed to the estimators"),
    counter(reg::kSamplesBridged, "samples_bridged", "summary.sensor.bridged",
            "samples bridged (a short gap interpolated)"),
    counter(reg::kSamplesMissing, "samples_missing", "summary.sensor.missing", "samples missing"),
    counter(reg::kSensorTimeouts, "sensor_timeouts", "summary.sensor.timeouts",
            "sensor timeouts"),
    counter(reg::kSensorFaults, "sensor_faults", "summary.sensor.faults",
            "sensor faults (entries into the fault state)"),
    counter(reg::kSamplesRejected, "samples_rejected", "summary.sensor.rejected",
            "samples rejected (not finite, out of range, undefined status bits)"),
    counter(reg::kEstimatorRestarts, "estimator_restarts", "summary.estimator_restarts",
            "estimator starts (the first included)"),
    word(reg::kLastAcknowledgement, "last_acknowledgement", "command.outcome",
         "outcome of the latest acknowledgement", Codes::kAckOutcome),
    word(reg::kCommands, "commands", "",
         "operator commands carried out (acknowledge and reset), modulo 65536"),
    word(reg::kAlarmEvents, "alarm_events", "", "alarm events so far, modulo 65536"),
    word(reg::kMapVersion, "map_version", "", "the version of this map: 8"),
    scaled(reg::kProbability, "probability", "0.0001", "", false, "status.probability",
           "the forecast's probability of a collapse within its horizon, 0 .. 1"),
    word(reg::kForecastAxis, "forecast_axis", "",
         "axis of that probability; 65535 before the first forecast", Codes::kAxis, true),
    scaled(reg::kCollapseIn, "collapse_in", "1", "ms", true, "status.collapse_forecast_t",
           "time to the forecast collapse (its first member's), 0 once due; 65535: none "
           "forecast"),
    word(reg::kForecastWorstMember, "forecast_worst_member", "",
         "the forecast axis's ensemble member that collapses first; 65535: none",
         Codes::kPlain, true),
    word(reg::kVersionMajor, "version_major", "version.major", "the project's version: major"),
    word(reg::kVersionMinor, "version_minor", "version.minor", "minor"),
    word(reg::kVersionPatch, "version_patch", "version.patch", "patch"),
    {Table::kRegister, reg::kGitDescription, reg::kGitDescriptionWords, Type::kAscii,
     "git_description", "1", "", false, Codes::kPlain, -1, "version.git",
     "git describe of the source at build time (as --version prints it), ASCII, two "
     "characters a register (the first in the high byte), NUL-padded"},
    file_given(reg::kSceneGiven, "scene_given",
               "1: registers 72-75 hold the scene file's digest (--scene; always given)"),
    file_digest(reg::kSceneSha256, "scene_sha256", "first_status.scene_sha256",
                "the scene file's SHA-256, its leading 64 bits (sha256sum's first 16 hex "
                "digits), high word first"),
    file_given(reg::kSceneYGiven, "scene_y_given",
               "1: registers 77-80 hold the second axis's scene file's digest; 0: one axis, no "
               "such file (registers 77-80 read 65535)"),
    file_digest(reg::kSceneYSha256, "scene_y_sha256", "first_status.scene_y_sha256",
                "the second axis's scene file's SHA-256 (--scene-y or monitor.second_scene), "
                "its leading 64 bits, high word first; 65535 in each register without one"),
    file_given(reg::kConfigGiven, "config_given",
               "1: registers 82-85 hold the box file's digest; 0: no --config (registers 82-85 "
               "read 65535)"),
    file_digest(reg::kConfigSha256, "config_sha256", "first_status.config_sha256",
                "the box's configuration file's SHA-256 (--config), its leading 64 bits, high "
                "word first; 65535 in each register without one"),
    word(reg::kRegionalHeld, "regional_held", "status.regional.held",
         "regional alerts held (docs/regional.md)"),
    scaled(reg::kRegionalProbability, "regional_probability", "0.0001", "", false,
           "status.regional.probability",
           "the statue's probability of collapse under the worst held regional alert, 0 .. 1"),
    scaled(reg::kRegionalSArrivalIn, "regional_s_arrival_in", "0.1", "s", true,
           "status.regional.time_to_s_arrival_s",
           "time to that alert's expected S arrival, 0 once due; 65535: none held"),
    scaled(reg::kRegionalPga, "regional_pga", "0.001", "g", true, "status.regional.pga_g",
           "that alert's expected PGA at the site (median); 65535: none held"),
    scaled(reg::kRegionalMagnitude, "regional_magnitude", "0.01", "", true,
           "status.regional.magnitude", "that alert's magnitude; 65535: none held"),
    scaled(reg::kRegionalDistance, "regional_distance", "1", "km", true,
           "status.regional.distance_km", "that alert's epicentral distance; 65535: none held"),
    {Table::kRegister, reg::kRegionalEventId, 2, Type::kUint32, "regional_event_id", "1", "",
     false, Codes::kPlain, -1, "status.regional.event_id",
     "that alert's event id (the bridge's number); 0 when none is held"},
    word(reg::kRegionalVersion, "regional_version", "status.regional.version",
         "that alert's version; 65535: none held", Codes::kPlain, true),
    counter(reg::kRegionalReceived, "regional_received", "status.regional.received",
            "regional alerts received (accepted or refused)"),
    counter(reg::kRegionalAccepted, "regional_accepted", "status.regional.accepted",
            "regional alerts accepted"),
    counter(reg::kRegionalRefused, "regional_refused", "",
            "regional alerts refused, every reason (status.regional.refused)"),
    word(reg::kRegionalLastRefusal, "regional_last_refusal", "status.regional.last_refusal",
         "why the latest refused regional alert was refused", Codes::kRegionalRefusal),
    word(reg::kStatueRateHealth, "statue_rate_health", "status.statue_sensor.rate.health",
         "health of the statue sensor's gyroscope; 65535: no statue sensor", Codes::kHealthState,
         true),
    word(reg::kStatueAccelerationHealth, "statue_acceleration_health",
         "status.statue_sensor.acceleration.health",
         "health of the statue sensor's accelerometer; 65535: no statue sensor",
         Codes::kHealthState, true),
    word(reg::kStatueReady, "statue_ready", "status.statue_sensor.ready",
         "1 once the statue sensor's rate offset is known; 65535: no statue sensor",
         Codes::kPlain, true),
    word(reg::kStatueWeightsX, "statue_weights_x", "status.statue_sensor.weights",
         "what the statue sensor's weights say of axis x (weighted: the risk is the weighted "
         "members'); 65535: no statue sensor",
         Codes::kStatueWeights, true),
    word(reg::kStatueWeightsY, "statue_weights_y", "",
         "the same of axis y; 65535 with one axis or no statue sensor", Codes::kStatueWeights,
         true),
    scaled(reg::kStatueEffectiveMembersX, "statue_effective_members_x", "0.01", "", true,
           "status.statue_sensor.weights",
           "effective ensemble members of axis x, 1 / sum of the squared weights (all members: "
           "nothing learned); 65535: no statue sensor"),
    scaled(reg::kStatueEffectiveMembersY, "statue_effective_members_y", "0.01", "", true, "",
           "the same of axis y; 65535 with one axis or no statue sensor"),
    word(reg::kRecorderHealth, "recorder_health", "status.recorder.health",
         "the event recorder's health (failed: the folder cannot take a capture now; degraded: "
         "a capture was lost or cut short); 65535: no recorder (--record-dir)",
         Codes::kRecorderHealth, true),
    word(reg::kRecorderProblem, "recorder_problem", "status.recorder.problem",
         "why the recorder failed, or its latest loss; 65535: no recorder",
         Codes::kRecorderProblem, true),
    counter(reg::kCapturesWritten, "captures_written", "status.recorder.captures_written",
            "captures written whole (a long one in pieces)"),
    counter(reg::kCapturesLost, "captures_lost", "status.recorder.captures_lost",
            "captures, or pieces of one, that never reached the disk"),
    counter(reg::kCapturesTruncated, "captures_truncated", "status.recorder.captures_truncated",
            "captures on disk that miss frames of their window"),
    word(reg::kTrouble, "trouble", "status.trouble",
         "the trouble shown beside the level: an input the box does not trust (docs/safety.md)",
         Codes::kAlarmCause),
    word(reg::kCollapseHeld, "collapse_held", "",
         "1 while a collapse is held, until a person states that the statue stands (coil 2)"),
    level_bit(monitor::AlarmLevel::kNormal, "level_normal"),
    level_bit(monitor::AlarmLevel::kAdvisory, "level_advisory"),
    level_bit(monitor::AlarmLevel::kWarning, "level_warning"),
    level_bit(monitor::AlarmLevel::kAlarm, "level_alarm"),
    level_bit(monitor::AlarmLevel::kFault, "level_fault"),
    coil_point(coil::kAcknowledge, "acknowledge",
               "write 1: acknowledge the latched level (register 3) quoting the latest event's "
               "sequence (register 5); needs modbus.writes"),
    coil_point(coil::kReset, "reset",
               "write 1: the monitor starts again with its memory (latch, collapse) restored; "
               "refused while an alarm is latched and unacknowledged; needs modbus.writes"),
    coil_point(coil::kStatueStands, "statue_stands",
               "write 1: a person on site states that the statue stands again, quoting the "
               "latest event's sequence (register 5); clears a held collapse; needs "
               "modbus.writes"),
}};

// The registers follow each other without gaps up to reg::kCount, the discrete inputs are the level codes 0 .. discrete::kCount - 1.
constexpr bool contiguous() {
  int next = 0;
  int bits = 0;
  for (const Point& p : kPoints) {
    if (p.table == Table::kRegister) {
      if (p.address != next) return false;
      next += p.words;
    } else if (p.table == Table::kDiscreteInput) {
      if (p.address != bits++) return false;
    }
  }
  return next == reg::kCount && bits == discrete::kCount;
}
static_assert(contiguous());
static_assert(kMapVersion == 8, "the map_version row says 8");

void put16(std::uint16_t* r, int address, std::uint64_t value) {
  r[address] = static_cast<std::uint16_t>(value & 0xFFFFU);
}

// High word first; saturates at 2^32 - 1.
void put32(std::uint16_t* r, int address, std::uint64_t value) {
  const std::uint64_t v = std::min<std::uint64_t>(value, 0xFFFFFFFFULL);
  r[address] = static_cast<std::uint16_t>(v >> 16);
  r[address + 1] = static_cast<std::uint16_t>(v & 0xFFFFU);
}

// 0 .. 1 as x 10000.
std::uint16_t fraction(double value) {
  return static_cast<std::uint16_t>(std::lround(std::clamp(value, 0.0, 1.0) * 1e4));
}

// A count below kNone, or kNone for a negative one.
std::uint16_t index_or_none(int value) {
  return value < 0 ? kNone : static_cast<std::uint16_t>(std::min(value, kNone - 1));
}

// MAJOR.MINOR.PATCH of kProjectVersion.
std::array<std::uint16_t, 3> version_numbers() {
  std::array<std::uint16_t, 3> out{};
  const char* at = version::kProjectVersion;
  for (std::uint16_t& part : out) {
    char* end = nullptr;
    part = static_cast<std::uint16_t>(std::strtoul(at, &end, 10));
    at = *end == '.' ? end + 1 : end;
  }
  return out;
}

void put_text(std::uint16_t* r, int address, int words, const char* text) {
  const std::size_t length = std::strlen(text);
  for (int i = 0; i < words; ++i) {
    const std::size_t at = 2 * static_cast<std::size_t>(i);
    const unsigned high = at < length ? static_cast<unsigned char>(text[at]) : 0U;
    const unsigned low = at + 1 < length ? static_cast<unsigned char>(text[at + 1]) : 0U;
    r[address + i] = static_cast<std::uint16_t>((high << 8) | low);
  }
}

// "0=normal;1=advisory;..."; for a bit that is 1 while the code is `bit_code`: "1=advisory".
template <class Enum, std::size_t N, std::size_t M>
std::string codes_text(const CodeTable<Enum, N>& table, const NameTable<Enum, M>& names,
                       int bit_code = -1) {
  std::string out;
  for (const Code<Enum>& c : table.codes) {
    if (bit_code >= 0) {
      if (c.code == bit_code) out = std::string("1=") + names.name(c.value);
      continue;
    }
    if (!out.empty()) out += ';';
    out += std::to_string(c.code) + "=" + names.name(c.value);
  }
  return out;
}

std::string codes_text(const Point& p) {
  switch (p.codes) {
    case Codes::kPlain:
      return "";
    case Codes::kAlarmLevel:
      return codes_text(kAlarmLevelCodes, monitor::kAlarmLevelNames, p.bit_code);
    case Codes::kAlarmCause:
      return codes_text(kAlarmCauseCodes, monitor::kAlarmCauseNames);
    case Codes::kPhase:
      return codes_text(kPhaseCodes, kPhaseNames);
    case Codes::kHealthState:
      return codes_text(kHealthStateCodes, monitor::kHealthStateNames);
    case Codes::kAckOutcome:
      return codes_text(kAckOutcomeCodes, monitor::kAckOutcomeNames);
    case Codes::kAxis:
      return "0=x;1=y";
    case Codes::kStatueWeights:
      return "0=not_measured;1=uninformative;2=weighted;3=unexplained";
    case Codes::kRegionalRefusal:
      return codes_text(kRegionalRefusalCodes, monitor::kRegionalRefusalNames);
    case Codes::kRecorderHealth:
      return codes_text(kRecorderHealthCodes, kRecorderHealthNames);
    case Codes::kRecorderProblem:
      return codes_text(kRecorderProblemCodes, kRecorderProblemNames);
  }
  return "";
}

constexpr NameTable<Table, 3> kTableNames{{{
    {Table::kRegister, "register"},
    {Table::kDiscreteInput, "discrete_input"},
    {Table::kCoil, "coil"},
}}};
// The function codes that read (and write) each table.
constexpr NameTable<Table, 3> kTableFunctions{{{
    {Table::kRegister, "03 04"},
    {Table::kDiscreteInput, "02"},
    {Table::kCoil, "01 05 15"},
}}};
constexpr NameTable<Type, 5> kTypeNames{{{
    {Type::kUint16, "uint16"},
    {Type::kUint32, "uint32"},
    {Type::kUint64, "uint64"},
    {Type::kAscii, "ascii"},
    {Type::kBit, "bit"},
}}};

// A CSV field (RFC 4180): quoted when it holds a comma, a quote or a semicolon.
std::string field(const std::string& text) {
  if (text.find_first_of(",\";") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace

const std::array<Point, kPointCount>& points() { return kPoints; }

StatueWeights statue_weights(const StatueAxisStatus& axis) {
  if (!axis.measured) return StatueWeights::kNotMeasured;
  if (axis.unexplained) return StatueWeights::kUnexplained;
  return axis.weighted ? StatueWeights::kWeighted : StatueWeights::kUninformative;
}

void fill(const StatusSnapshot& s, std::uint64_t alarm_events, Image& out) {
  std::uint16_t* r = out.registers.data();
  put16(r, reg::kAlarmLevel, kAlarmLevelCodes.code(s.level));
  put16(r, reg::kHeartbeat, s.statuses);
  put16(r, reg::kRisk, fraction(s.risk));
  put16(r, reg::kLatchedLevel, kAlarmLevelCodes.code(s.latched));
  put16(r, reg::kCause, kAlarmCauseCodes.code(s.cause));
  put16(r, reg::kEventSequence, s.any_event ? s.event_sequence : kNone);
  put16(r, reg::kAxisCount, static_cast<std::uint64_t>(s.axis_count));
  put16(r, reg::kPhaseX, kPhaseCodes.code(s.phase[0]));
  put16(r, reg::kPhaseY, s.axis_count > 1 ? kPhaseCodes.code(s.phase[1]) : kNone);
  put16(r, reg::kEstimating, s.estimating ? 1 : 0);
  put16(r, reg::kSensorHealth, kHealthStateCodes.code(s.sensor));
  put16(r, reg::kSensorsState, kHealthStateCodes.code(s.sensors_state));
  put32(r, reg::kUptime,
        static_cast<std::uint64_t>(std::max<std::int64_t>(s.uptime_ns, 0)) / 1'000'000'000ULL);
  const monitor::SensorCounters& c = s.sensor_counters;
  put32(r, reg::kSamplesFed, c.fed);
  put32(r, reg::kSamplesBridged, c.bridged);
  put32(r, reg::kSamplesMissing, c.missing);
  put32(r, reg::kSensorTimeouts, c.timeouts);
  put32(r, reg::kSensorFaults, c.faults);
  put32(r, reg::kSamplesRejected, c.non_finite + c.out_of_range + c.undefined_status);
  put32(r, reg::kEstimatorRestarts, s.estimator_restarts);
  put16(r, reg::kLastAcknowledgement, kAckOutcomeCodes.code(s.last_ack));
  put16(r, reg::kCommands, s.commands);
  put16(r, reg::kAlarmEvents, alarm_events);
  put16(r, reg::kMapVersion, kMapVersion);
  put16(r, reg::kProbability, fraction(s.probability));
  put16(r, reg::kForecastAxis, index_or_none(s.forecast_axis));
  const double collapse_in_ms = std::ceil((s.collapse_forecast_t - s.t) * 1e3);
  put16(r, reg::kCollapseIn,
        !s.collapse_forecast ? kNone
                             : static_cast<std::uint16_t>(std::clamp(collapse_in_ms, 0.0,
                                                                     kNone - 1.0)));
  put16(r, reg::kForecastWorstMember, index_or_none(s.forecast_worst_member));
  const RegionalSnapshot& g = s.regional;
  const bool held = g.held > 0;
  const auto scaled_or_none = [held](double value, double unit) {
    return held ? static_cast<std::uint16_t>(std::clamp(std::round(value / unit), 0.0, kNone - 1.0))
                : kNone;
  };
  put16(r, reg::kRegionalHeld, static_cast<std::uint64_t>(g.held));
  put16(r, reg::kRegionalProbability, fraction(g.probability));
  put16(r, reg::kRegionalSArrivalIn, scaled_or_none(g.time_to_s_arrival_s, 0.1));
  put16(r, reg::kRegionalPga, scaled_or_none(g.pga_g, 0.001));
  put16(r, reg::kRegionalMagnitude, scaled_or_none(g.magnitude, 0.01));
  put16(r, reg::kRegionalDistance, scaled_or_none(g.distance_km, 1.0));
  put32(r, reg::kRegionalEventId, held ? g.event_id : 0);
  put16(r, reg::kRegionalVersion, held ? g.version : kNone);
  put32(r, reg::kRegionalReceived, g.received);
  put32(r, reg::kRegionalAccepted, g.accepted);
  put32(r, reg::kRegionalRefused, g.refused);
  put16(r, reg::kRegionalLastRefusal, kRegionalRefusalCodes.code(g.last_refusal));
  const bool statue = s.has_statue_sensor;
  put16(r, reg::kStatueRateHealth, statue ? kHealthStateCodes.code(s.statue_rate) : kNone);
  put16(r, reg::kStatueAccelerationHealth,
        statue ? kHealthStateCodes.code(s.statue_acceleration) : kNone);
  put16(r, reg::kStatueReady, statue ? (s.statue_ready ? 1 : 0) : kNone);
  for (int i = 0; i < kMaxAxes; ++i) {
    const StatueAxisStatus& a = s.statue_axes[static_cast<std::size_t>(i)];
    const bool shown = statue && i < s.axis_count;
    put16(r, reg::kStatueWeightsX + i,
          shown ? static_cast<std::uint16_t>(statue_weights(a)) : kNone);
    put16(r, reg::kStatueEffectiveMembersX + i,
          shown ? static_cast<std::uint16_t>(std::lround(
                      std::clamp(static_cast<double>(a.effective_members), 0.0, 655.0) * 100.0))
                : kNone);
  }
  const RecorderStatus& recorder = s.recorder;
  put16(r, reg::kRecorderHealth,
        recorder.present ? kRecorderHealthCodes.code(recorder.health) : kNone);
  put16(r, reg::kRecorderProblem,
        recorder.present ? kRecorderProblemCodes.code(recorder.problem) : kNone);
  put32(r, reg::kCapturesWritten, recorder.captures_written);
  put32(r, reg::kCapturesLost, recorder.captures_lost);
  put32(r, reg::kCapturesTruncated, recorder.captures_truncated);
  put16(r, reg::kTrouble, kAlarmCauseCodes.code(s.trouble));
  put16(r, reg::kCollapseHeld, s.collapse_held ? 1 : 0);
  for (int i = 0; i < discrete::kCount; ++i) {
    out.discrete_inputs[static_cast<std::size_t>(i)] = kAlarmLevelCodes.code(s.level) == i ? 1 : 0;
  }
}

void fill_identity(const RunIdentity& identity, Image& out) {
  std::uint16_t* r = out.registers.data();
  const std::array<std::uint16_t, 3> version = version_numbers();
  put16(r, reg::kVersionMajor, version[0]);
  put16(r, reg::kVersionMinor, version[1]);
  put16(r, reg::kVersionPatch, version[2]);
  put_text(r, reg::kGitDescription, reg::kGitDescriptionWords, version::kGitDescription);
  const struct {
    int given;
    int digest;
    const std::optional<Sha256Digest>& value;
  } files[] = {{reg::kSceneGiven, reg::kSceneSha256, identity.scene},
               {reg::kSceneYGiven, reg::kSceneYSha256, identity.scene_y},
               {reg::kConfigGiven, reg::kConfigSha256, identity.config}};
  for (const auto& f : files) {
    put16(r, f.given, f.value ? 1 : 0);
    const std::uint64_t bits = f.value ? leading_64_bits(*f.value) : ~std::uint64_t{0};
    for (int i = 0; i < reg::kDigestWords; ++i) {
      put16(r, f.digest + i, bits >> (16 * (reg::kDigestWords - 1 - i)));
    }
  }
}

std::string map_csv() {
  std::string out = "table,functions,address,words,name,type,scale,unit,none,codes,json,meaning\n";
  for (const Point& p : kPoints) {
    const char* none = !p.none ? "" : p.type == Type::kUint64 ? "18446744073709551615" : "65535";
    out += std::string(kTableNames.name(p.table)) + "," + kTableFunctions.name(p.table) + "," +
           std::to_string(p.address) + "," + std::to_string(p.words) + "," + p.name + "," +
           kTypeNames.name(p.type) + "," + p.scale + "," + p.unit + "," + none + "," +
           field(codes_text(p)) + "," + p.json + "," + field(p.meaning) + "\n";
  }
  return out;
}

}  // namespace plinth::firmware::modbus

// plinth-eval run --fault KIND[:PARAM] --fault-at WHEN: one fault injected into the box's
// inputs, as the box would meet it (the frames' values, the samples it gets or misses, a restart
// with its saved memory), never by reaching into the box (docs/safety.md, "Fault injection").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "plinth/core/name_table.h"
#include "plinth/monitor/alarm_level.h"

namespace plinth::sim {

enum class FaultKind : std::uint8_t {
  kNone,
  // The statue sensor (plinth-eval run --statue-sensor).
  kStatueAtRest,        // reads a statue at rest: its offsets and noise, gravity
  kStatueStuck,         // frozen at what it read at the onset, its noise going on
  kStatueGain,          // PARAM: the gyroscope's gain (its whole reading scaled)
  kStatueBias,          // PARAM: a step bias on every gyroscope axis, deg/s
  kStatueAxesSwapped,   // its x and y exchanged, on both streams
  kStatueSign,          // PARAM: the sensor axis (x, y or z) whose sign is flipped on both streams
  kStatueDelay,         // PARAM: s more behind the ground sensor
  kStatueDropout,       // PARAM: s without a sample of either stream
  kStatueNeighbour,     // reads another statue drawn from the scene's uncertainty
  kStatueOnPlinth,      // reads the plinth: the base's motion, no rotation
  // The ground sensor.
  kGroundGain,          // PARAM: G (on x) or AXIS=G
  kGroundHeading,       // PARAM: turned about the vertical by this many degrees
  // Two ground sensors, one of them wrong as PARAM (gain:..., heading:...): the primary (the
  // first configured, whose samples drive the estimators) or the second.
  kGroundPairPrimary,
  kGroundPairSecond,
  // The box itself, with its memory (Monitor::memory, restore) as plinth-monitor keeps it.
  kReset,    // acknowledged, then reset (refused while an alarm stays latched)
  kRestart,  // a crash or power cut: PARAM s without samples (default 0)
};

inline constexpr NameTable<FaultKind, 17> kFaultKindNames{{{
    {FaultKind::kNone, "none"},
    {FaultKind::kStatueAtRest, "statue_at_rest"},
    {FaultKind::kStatueStuck, "statue_stuck"},
    {FaultKind::kStatueGain, "statue_gain"},
    {FaultKind::kStatueBias, "statue_bias"},
    {FaultKind::kStatueAxesSwapped, "statue_axes_swapped"},
    {FaultKind::kStatueSign, "statue_sign"},
    {FaultKind::kStatueDelay, "statue_delay"},
    {FaultKind::kStatueDropout, "statue_dropout"},
    {FaultKind::kStatueNeighbour, "statue_neighbour"},
    {FaultKind::kStatueOnPlinth, "statue_on_plinth"},
    {FaultKind::kGroundGain, "ground_gain"},
    {FaultKind::kGroundHeading, "ground_heading"},
    {FaultKind::kGroundPairPrimary, "ground_pair_primary"},
    {FaultKind::kGroundPairSecond, "ground_pair_second"},
    {FaultKind::kReset, "reset"},
    {FaultKind::kRestart, "restart"},
}}};

// The input a fault lies about: the trouble that names it (names_faulted_input).
enum class FaultedInput : std::uint8_t { kNone, kStatueSensor, kGroundSensor, kBox };
[[nodiscard]] FaultedInput faulted_input(FaultKind kind);
// The trouble `cause` names `input`: the statue sensor's statue_sensor_fault and
// statue_unexplained; a ground sensor's sensor_fault, sensor_timeout and sensor_disagreement;
// the box's own restart, not_calibrated (its estimators' start-up) and restored.
[[nodiscard]] bool names_faulted_input(FaultedInput input, monitor::AlarmCause cause);

// A ground accelerometer's wrong reading of the statue frame's acceleration a (m/s2): turned
// by heading_rad about the vertical (it reads R_z(heading)^T a), then each of its axes scaled.
struct GroundSensorError {
  Eigen::Vector3d gain = Eigen::Vector3d::Ones();
  double heading_rad = 0.0;

  [[nodiscard]] Eigen::Vector3d read(const Eigen::Vector3d& a) const;
};

// When the fault begins: at the box's first sample (kBoxStart, its quiet lead-in included), or
// offset_s after the record's t = 0, its strong motion's onset (pwave_records.h), the true
// statue's first motion out of full contact, or the box's first alarm (a fault that never
// begins when that never comes).
enum class FaultAnchor : std::uint8_t { kBoxStart, kRecord, kStrongMotion, kMotion, kAlarm };
struct FaultOnset {
  FaultAnchor anchor = FaultAnchor::kBoxStart;
  double offset_s = 0.0;
  std::string text = "start";  // as given
};

struct Fault {
  FaultKind kind = FaultKind::kNone;
  std::string param;  // as given after "KIND:" ("" without one)
  // statue_gain: the gain; statue_bias: rad/s; statue_delay, statue_dropout, restart: s.
  double value = 0.0;
  int axis = 0;  // statue_sign: the sensor axis flipped (0 x, 1 y, 2 z)
  GroundSensorError ground;  // ground_gain, ground_heading, the pair's wrong sensor
  FaultOnset onset;

  [[nodiscard]] bool any() const { return kind != FaultKind::kNone; }
  [[nodiscard]] FaultedInput input() const { return faulted_input(kind); }
};

// "KIND[:PARAM]" (kFaultKindNames; the PARAM each kind takes in docs/safety.md). Throws
// InputError, prefixed "--fault: ", naming what is wrong: an unknown kind, a parameter missing,
// given to a kind without one, or out of its range.
[[nodiscard]] Fault parse_fault(const std::string& text);
// --fault-at: "start", a time in s (from the record's t = 0, >= 0), or "strong", "motion" or
// "alarm", each optionally "+S" (alarm) or "+S"/"-S" (the others) s. Throws InputError, prefixed
// "--fault-at: ".
[[nodiscard]] FaultOnset parse_fault_onset(const std::string& text);

// The kind needs the statue sensor (plinth-eval run --statue-sensor).
[[nodiscard]] bool needs_statue_sensor(FaultKind kind);
// The kind happens at an instant (reset, restart): --fault-at must say when.
[[nodiscard]] bool happens_at_an_instant(FaultKind kind);

}  // namespace plinth::sim

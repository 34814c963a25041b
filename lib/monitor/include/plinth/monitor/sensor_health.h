// Sensor health: one tracker per accelerometer node, between the frame decoder and
// conditioning. Nothing bad passes silently: every sample is fed, fed with a mark, bridged, or
// dropped with a counter and a cause (docs/monitor-components.md, Sensor health).
// Freestanding: no heap, no exceptions.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/name_table.h"
#include "plinth/core/real.h"
#include "plinth/monitor/alarm_level.h"

namespace plinth::monitor {

// Largest max_bridge_samples; sizes the per-sample output.
inline constexpr int kMaxBridgeSamples = 15;
inline constexpr std::size_t kMaxFedPerSample = static_cast<std::size_t>(kMaxBridgeSamples) + 1;

struct SensorHealthSettings {
  Time sample_period_s = Real(0.001);  // the node's nominal sample period, s
  // No accepted sample for this long is a timeout fault, s. Must exceed the longest bridgeable
  // gap, (max_bridge_samples + 1) periods, and stay below 128 periods so that a silence cannot
  // hide behind the 8-bit sequence counter's wrap.
  Time timeout_s = Real(0.05);
  int max_bridge_samples = 3;  // samples, 0..kMaxBridgeSamples: longest gap bridged
  int recovery_samples = 10;   // samples, >= 1: consecutive clean samples that clear a condition
  // samples: this many consecutive bit-identical samples is a stuck sensor; 0 turns the check
  // off (for noise-free synthetic input), else >= 2.
  int stuck_samples = 50;
  Real full_scale_g = 8.0;         // g: |a| at or above this on an axis is saturated
  Real max_valid_g = Real(8.192);  // g, >= full_scale_g: |a| above this is impossible (rejected)
};

// Checks the settings; the Error names the field at fault ("sensor_health.timeout_s", ...).
[[nodiscard]] Error validate(const SensorHealthSettings& settings);

enum class HealthState : std::uint8_t { kOk = 0, kDegraded = 1, kFault = 2 };

enum class HealthCause : std::uint8_t {
  kNone = 0,
  kNoData,              // no sample accepted yet (the initial state)
  kTimeout,             // no sample accepted for timeout_s
  kSequenceGap,         // sequence numbers missing (bridged: degraded; longer: fault)
  kDuplicate,           // a sequence number received again
  kOutOfOrder,          // a sequence number behind the last one
  kNonFinite,           // NaN or infinity on an axis
  kOutOfRange,          // |a| above max_valid_g on an axis
  kUndefinedStatus,     // status bits the protocol does not define
  kSaturated,           // at full scale (flag or value)
  kStuck,               // all axes bit-identical for stuck_samples samples
  kSelfTestFailed,      // the sensor's self-test flag
  kOverTemperature,     // the sensor's over-temperature flag
  kCalibrationInvalid,  // the sensor's calibration-invalid flag
};

inline constexpr NameTable<HealthState, 3> kHealthStateNames{{{
    {HealthState::kOk, "ok"},
    {HealthState::kDegraded, "degraded"},
    {HealthState::kFault, "fault"},
}}};

inline constexpr NameTable<HealthCause, 14> kHealthCauseNames{{{
    {HealthCause::kNone, "none"},
    {HealthCause::kNoData, "no data yet"},
    {HealthCause::kTimeout, "timeout"},
    {HealthCause::kSequenceGap, "sequence gap"},
    {HealthCause::kDuplicate, "duplicate sequence number"},
    {HealthCause::kOutOfOrder, "sequence number out of order"},
    {HealthCause::kNonFinite, "non-finite value"},
    {HealthCause::kOutOfRange, "value out of range"},
    {HealthCause::kUndefinedStatus, "undefined status bits"},
    {HealthCause::kSaturated, "saturated"},
    {HealthCause::kStuck, "stuck values"},
    {HealthCause::kSelfTestFailed, "self-test failed"},
    {HealthCause::kOverTemperature, "over temperature"},
    {HealthCause::kCalibrationInvalid, "calibration invalid"},
}}};

[[nodiscard]] constexpr const char* health_state_name(HealthState state) {
  return kHealthStateNames.name(state);
}
[[nodiscard]] constexpr const char* health_cause_name(HealthCause cause) {
  return kHealthCauseNames.name(cause);
}
// The alarm cause to report for a fault: kSensorTimeout for no_data and timeout, kNone for
// kNone, kSensorFault otherwise.
[[nodiscard]] AlarmCause to_alarm_cause(HealthCause cause);

// Event counts since the tracker was created (samples where a unit is not said).
struct SensorCounters {
  std::uint64_t received = 0;             // on_sample calls
  std::uint64_t fed = 0;                  // samples passed on, bridged ones included
  std::uint64_t bridged = 0;              // interpolated samples passed on
  std::uint64_t held_in_fault = 0;        // accepted samples not passed on: fault or recovering
  std::uint64_t missing = 0;              // sequence numbers never received
  std::uint64_t long_gaps = 0;            // gaps longer than max_bridge_samples (faults)
  std::uint64_t duplicates = 0;
  std::uint64_t out_of_order = 0;
  std::uint64_t non_finite = 0;
  std::uint64_t out_of_range = 0;
  std::uint64_t undefined_status = 0;
  std::uint64_t saturated = 0;
  std::uint64_t stuck_detections = 0;     // stuck runs that reached stuck_samples
  std::uint64_t self_test_failed = 0;     // samples with the flag
  std::uint64_t over_temperature = 0;     // samples with the flag
  std::uint64_t calibration_invalid = 0;  // samples with the flag
  std::uint64_t timeouts = 0;
  std::uint64_t faults = 0;               // entries into the fault state
};

struct SensorHealth {
  HealthState state = HealthState::kFault;
  HealthCause cause = HealthCause::kNoData;
  SensorCounters counters;
};

// One received sample, as decoded from a SensorAcceleration frame.
struct SensorSample {
  std::int64_t receive_time_ns = 0;
  std::uint8_t sequence = 0;
  std::uint8_t status = 0;                                   // sensor_flags (alarm_level.h)
  Vector3r acceleration_g = Vector3r::Zero();                // sensor frame, g
};

// A sample to feed, in order.
struct FedSample {
  std::int64_t time_ns = 0;  // receive time; interpolated for a bridged sample
  std::uint8_t sequence = 0;  // the sensor's number (the missing one's for a bridged sample)
  Vector3r acceleration_g = Vector3r::Zero();  // sensor frame, g
  bool bridged = false;    // interpolated across a gap
  bool restart = false;    // first sample after a fault: does not connect to the one before
  bool saturated = false;  // at full scale: the true |a| on some axis is at least this
};

// What happened to one input sample.
enum class SampleVerdict : std::uint8_t {
  kFed,           // passed on (after any bridged samples)
  kHeldInFault,   // accepted, but the state is fault: not passed on
  kDuplicate,     // dropped
  kOutOfOrder,    // dropped
  kRejected,      // bad values or status bits: dropped, its slot is part of a gap
};

struct SensorUpdate {
  std::array<FedSample, kMaxFedPerSample> fed{};  // fed[0 .. fed_count)
  std::size_t fed_count = 0;
  SampleVerdict verdict = SampleVerdict::kFed;
  SensorHealth health;  // after this sample
};

// Health state and recovery: every condition on_sample() finds marks the sample unclean and
// raises the state to the condition's severity (ok < degraded < fault; the cause is the latest
// condition of the highest severity held). The state returns to ok after recovery_samples
// consecutive clean samples (accepted, valid, no flags, not saturated, not stuck; a dropped or
// rejected sample breaks the run). A gap or a timeout belongs to the time before the sample
// that ends it: that sample, if clean itself, is the first of the run.
//
// Stream across a fault: while the state is fault nothing is fed (accepted samples are counted
// as held_in_fault) and nothing is bridged across it. The sample that completes recovery is
// fed with `restart` set: the stream before it does not connect to it (what happened meanwhile
// is unknown). A tracker starts in fault (cause no_data), so the first fed sample is a restart.
//
// Times are int64 ns on the receive clock (hal::TimedFrame::timestamp_ns); a time earlier than
// the last counts as no time elapsed.
class SensorHealthTracker {
 public:
  SensorHealthTracker() = default;

  // Fails on invalid settings (the Error names the field); `out` is then left untouched.
  [[nodiscard]] static Error create(const SensorHealthSettings& settings,
                                    SensorHealthTracker& out);

  // One received sample of this node: the samples to feed, in order (0 to max_bridge_samples +
  // 1 of them), the state and its cause. Its checks, in this order:
  //   timeout   no sample accepted for timeout_s: a timeout fault; the stream re-synchronises
  //             (this sample starts it afresh, no gap counted across).
  //   sequence  against the last sample past this check, d = (seq - last) mod 256: d = 0 a
  //             duplicate, d >= 128 out of order; both dropped, counted, degraded. More than
  //             max_bridge_samples out of order in a row: the node restarted its counter, a
  //             fault, and the next sample re-synchronises. 1 < d < 128: d - 1 missed.
  //   values    non-finite, |a| > max_valid_g on an axis, undefined status bits: rejected
  //             (counted); its slot becomes part of the gap.
  //   gap       the slots since the last accepted sample (missed and rejected): up to
  //             max_bridge_samples are bridged linearly (values and receive times), each
  //             bridged sample marked: degraded; more is a fault (at once when a rejected
  //             sample takes the open gap past the limit).
  //   flags     self-test failed, calibration invalid: fault (the values cannot be trusted);
  //             over-temperature: degraded, fed; saturation (the flag, or |a| >= full_scale_g
  //             on an axis): degraded, fed marked `saturated`.
  //   stuck     stuck_samples consecutive accepted samples bit-identical on all three axes:
  //             fault; the first stuck_samples - 1 were fed (not told from noise).
  [[nodiscard]] SensorUpdate on_sample(const SensorSample& sample);
  // Call periodically (at least every timeout_s / 2): detects the timeout while no sample
  // arrives. Returns the health after the check.
  const SensorHealth& tick(std::int64_t now_ns);

  [[nodiscard]] const SensorHealth& health() const { return health_; }
  [[nodiscard]] const SensorHealthSettings& settings() const { return settings_; }

 private:
  void note(HealthState severity, HealthCause cause);
  void declare_timeout();
  [[nodiscard]] bool check_sequence(std::uint8_t sequence, SampleVerdict& verdict);
  [[nodiscard]] HealthCause value_problem(const SensorSample& sample) const;
  void check_flags_and_stuck(const SensorSample& sample, bool& saturated);
  void feed(SensorUpdate& update, const SensorSample& sample, bool bridge_first, bool restart,
            bool saturated);

  SensorHealthSettings settings_;
  std::int64_t timeout_ns_ = 0;
  SensorHealth health_;

  // The stream reference: false at start, after a timeout and after a counter restart.
  bool have_reference_ = false;
  std::uint8_t last_received_sequence_ = 0;  // last sample past the sequence check
  // The last accepted sample (valid values): the start of the next gap and of bridging.
  std::uint8_t last_accepted_sequence_ = 0;
  std::int64_t last_accepted_time_ns_ = 0;
  Vector3r last_accepted_g_ = Vector3r::Zero();

  int rejected_in_gap_ = 0;     // rejected samples since the last accepted one
  HealthCause last_rejection_ = HealthCause::kNone;  // why the latest of them was rejected
  int out_of_order_run_ = 0;    // consecutive out-of-order samples
  int identical_run_ = 0;       // consecutive accepted samples bit-identical, this one included
  int clean_run_ = 0;           // consecutive clean samples
  bool sample_clean_ = true;    // the sample being processed has no condition so far
};

}  // namespace plinth::monitor

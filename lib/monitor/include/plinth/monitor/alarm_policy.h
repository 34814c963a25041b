// Alarm policy: the risk, the forecast's probability, the block's phase and the fault state in;
// alarm levels, events and the heartbeat out, for the building's alarm system (the AlarmEvent
// frames, the status lines). Levels and causes: alarm_level.h; every rule and default:
// docs/monitor-components.md, Alarm policy. Freestanding: no heap, no exceptions.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "plinth/core/error.h"
#include "plinth/core/name_table.h"
#include "plinth/core/real.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/optional_part.h"

namespace plinth::monitor {

struct RiskThresholds {
  Real on = 0.0;   // risk (dimensionless, 0..1) at or above which the condition starts
  Real off = 0.0;  // risk below which it ends; off < on
};

struct AlarmPolicySettings {
  // Calibrated with plinth-eval (docs/forecast.md): on the worst member's risk and the
  // forecast's probability together, the alarm rule that missed none of 1,078 collapses with
  // the fewest false alarms; warning and advisory below it.
  RiskThresholds advisory{Real(0.1),
                          Real(0.05)};  // also active while the block is out of full contact
  RiskThresholds warning{Real(0.5), Real(0.4)};
  RiskThresholds alarm{Real(0.65), Real(0.55)};
  // On the forecast's probability of a collapse within its horizon (0 while no forecast has
  // completed).
  RiskThresholds advisory_forecast{Real(0.125), Real(0.0625)};
  RiskThresholds warning_forecast{Real(0.25), Real(0.1875)};
  RiskThresholds alarm_forecast{Real(0.375), Real(0.3125)};
  // On the P-wave stage's probability of collapse (warning only). Calibrated with plinth-eval on
  // the bundled three-component records (docs/pwave.md): the longest median lead where the P
  // wave comes 3 s early, within 5 points more unneeded warnings than the box without it.
  // None in a build without the stage (kPWaveStageBuiltIn).
  [[no_unique_address]] OptionalPart<RiskThresholds, kPWaveStageBuiltIn> warning_pwave =
      part_if<kPWaveStageBuiltIn>(RiskThresholds{Real(0.75), Real(0.6)});
  // On the probability of collapse under the worst held regional alert (regional_alert.h;
  // warning only): a guess about the coming ground motion, not the statue's physics. Calibrated
  // with plinth-eval --regional on the bundled three-component records (docs/regional.md): the
  // longest median lead within 5 points more unneeded warnings (0.5 cost 8 points held out).
  // None in a build without regional alerts (kRegionalAlertBuiltIn).
  [[no_unique_address]] OptionalPart<RiskThresholds, kRegionalAlertBuiltIn> warning_regional =
      part_if<kRegionalAlertBuiltIn>(RiskThresholds{Real(0.7), Real(0.6)});
  // s, >= 0: a condition holds this long before its level rises. 0: the sample it starts (a
  // margin run out is news at once), so plinth-eval's rules are exactly what the box applies;
  // 0.1 s missed a collapse they caught and cost 0.1-0.2 s of lead (docs/forecast.md).
  Time raise_hold_s = 0.0;
  Time lower_hold_s = 2.0;    // s, >= 0: a condition (or fault) is gone this long before it lowers
  bool latch_warning = true;  // a raised warning holds until acknowledged
  bool latch_alarm = true;    // a raised alarm holds until acknowledged (a collapse always does)
  Time heartbeat_period_s = 1.0;  // s, > 0: longest time between two status messages
};

// Checks the settings; the Error names the field at fault ("alarm_policy.warning.off", ...).
// Thresholds (risk, forecast, P wave and regional alike): finite, in [0, 1], off < on per level,
// and ordered across levels (advisory <= warning <= alarm, for on and for off; warning_pwave and
// warning_regional have no other level to be ordered with).
[[nodiscard]] Error validate(const AlarmPolicySettings& settings);

// An operator's acknowledgement (on the bus: the Acknowledge frame, without its source id).
struct Acknowledgement {
  AlarmLevel level = AlarmLevel::kNormal;  // the latched level acknowledged
  std::uint8_t event_sequence = 0;         // the sequence of the latest event the operator saw
};

struct AlarmInput {
  std::int64_t time_ns = 0;          // monitor time since start, ns
  Real risk = 0.0;                   // overturning risk, dimensionless, [0, 1]
  Real probability = 0.0;            // forecast probability of a collapse, [0, 1]
  Real pwave_probability = 0.0;      // the P-wave stage's probability of collapse, [0, 1]
  Real regional_probability = 0.0;   // under the worst held regional alert, [0, 1]
  // (Both read only in a build with their part: kPWaveStageBuiltIn, kRegionalAlertBuiltIn.)
  bool out_of_full_contact = false;  // the block slides or rocks (motion started)
  bool collapse_detected = false;    // the block overturned or fell
  bool fault_active = false;         // sensor or bus trouble: the risk is stale
  AlarmCause fault_cause = AlarmCause::kSensorFault;  // reported while fault_active
  // A supplementary input refused (kNone: none): the risk given is the box's without it, still
  // valid, so the trouble is shown beside the level, never in place of one (AlarmPolicy).
  AlarmCause input_fault = AlarmCause::kNone;
  bool not_calibrated = false;  // no trusted offset or initial state (AlarmPolicy, below)
  bool acknowledged = false;  // `acknowledgement` arrived since the last update
  Acknowledgement acknowledgement;
  // A person on site stated that the statue stands again: a held collapse is cleared, unless
  // this input still says collapse (StandsOutcome).
  bool statue_stands = false;
  std::uint8_t statue_stands_sequence = 0;  // the latest event's sequence the person saw
};

enum class AckOutcome : std::uint8_t {
  kNone = 0,                // no acknowledgement in this update
  kReleased,                // latch released; the level follows its (lower) condition
  kReleasedConditionHolds,  // latch released; the condition still holds, so does the level
  kStale,                   // the sequence is not the latest event's: nothing changed
  kWrongLevel,              // the level is not the latched one: nothing changed
  kNothingLatched,          // no level is latched: nothing changed
};

// What a person's statement that the statue stands again did.
enum class StandsOutcome : std::uint8_t {
  kNone = 0,          // no statement in this update
  kCleared,           // the held collapse cleared; the level follows its conditions
  kNothingHeld,       // no collapse was held: nothing changed
  kStale,             // the sequence is not the latest event's: nothing changed
  kStillCollapsed,    // an input still says overturned or fallen: nothing changed
};

enum class InputProblem : std::uint8_t {
  kNone = 0,
  kRiskInvalid,   // risk or a probability not finite or outside [0, 1]: an internal fault
  kTimeWentBack,  // time earlier than the last update's: the update was refused
};

inline constexpr NameTable<AckOutcome, 6> kAckOutcomeNames{{{
    {AckOutcome::kNone, "none"},
    {AckOutcome::kReleased, "released"},
    {AckOutcome::kReleasedConditionHolds, "released, condition holds"},
    {AckOutcome::kStale, "stale sequence"},
    {AckOutcome::kWrongLevel, "wrong level"},
    {AckOutcome::kNothingLatched, "nothing latched"},
}}};

inline constexpr NameTable<InputProblem, 3> kInputProblemNames{{{
    {InputProblem::kNone, "none"},
    {InputProblem::kRiskInvalid, "risk not finite or outside [0, 1]"},
    {InputProblem::kTimeWentBack, "time went back"},
}}};

inline constexpr NameTable<StandsOutcome, 5> kStandsOutcomeNames{{{
    {StandsOutcome::kNone, "none"},
    {StandsOutcome::kCleared, "cleared"},
    {StandsOutcome::kNothingHeld, "no collapse held"},
    {StandsOutcome::kStale, "stale sequence"},
    {StandsOutcome::kStillCollapsed, "still collapsed"},
}}};

[[nodiscard]] constexpr const char* stands_outcome_name(StandsOutcome outcome) {
  return kStandsOutcomeNames.name(outcome);
}
[[nodiscard]] constexpr const char* ack_outcome_name(AckOutcome outcome) {
  return kAckOutcomeNames.name(outcome);
}
[[nodiscard]] constexpr const char* input_problem_name(InputProblem problem) {
  return kInputProblemNames.name(problem);
}

struct AlarmEventRecord {
  AlarmLevel level = AlarmLevel::kNormal;
  AlarmLevel previous_level = AlarmLevel::kNormal;
  AlarmCause cause = AlarmCause::kNone;
  bool latched = false;      // a level is latched, awaiting acknowledgement
  // The trouble shown beside the level (kNone: none): a fault, not calibrated or a refused
  // input, whatever level it leaves shown.
  AlarmCause trouble = AlarmCause::kNone;
  std::int64_t time_ns = 0;  // the update's time
  std::uint8_t sequence = 0;
};

// What must outlive the process (AlarmPolicy::memory, restore): the latched level with its
// cause, and a collapse seen.
struct AlarmMemory {
  AlarmLevel latched_level = AlarmLevel::kNormal;  // kNormal: nothing latched
  AlarmCause latched_cause = AlarmCause::kNone;
  bool collapse_held = false;
  std::uint8_t next_sequence = 0;  // the events' numbering goes on where it stopped
};

inline constexpr std::size_t kMaxEventsPerUpdate = 2;

struct AlarmOutput {
  std::array<AlarmEventRecord, kMaxEventsPerUpdate> events{};  // events[0 .. event_count)
  std::size_t event_count = 0;
  AlarmLevel level = AlarmLevel::kNormal;          // the level shown after this update
  AlarmLevel latched_level = AlarmLevel::kNormal;  // kNormal when nothing is latched
  AlarmCause trouble = AlarmCause::kNone;          // shown beside the level (the events')
  bool collapse_held = false;                      // a collapse holds the alarm (sticky)
  AckOutcome acknowledgement = AckOutcome::kNone;
  StandsOutcome statue_stands = StandsOutcome::kNone;
  InputProblem input_problem = InputProblem::kNone;
};

namespace detail {
// A boolean that changes only after the wanted value has differed for a hold time.
struct HeldCondition {
  bool active = false;
  bool changing = false;       // the wanted value differs from `active`
  std::int64_t since_ns = 0;   // since when it differs
  void update(bool wanted, std::int64_t now_ns, std::int64_t raise_hold_ns,
              std::int64_t lower_hold_ns);
};
}  // namespace detail

// Conditions, each with on/off thresholds on the risk and on the forecast's probability
// (hysteresis: a condition starts at risk >= on or probability >= on, ends when both are below
// their off) and holds (raise_hold_s before its level rises, lower_hold_s absent before it
// lowers); the condition level is the highest level whose condition is active:
//   advisory  risk >= advisory.on, probability >= advisory_forecast.on, or out of full contact
//   warning   risk >= warning.on, or probability >= warning_forecast.on, or the P-wave
//             stage's probability of collapse >= warning_pwave.on (p_wave.h), or the regional
//             alert's probability of collapse >= warning_regional.on (never more than warning:
//             both guess the coming ground, not the statue's physics)
//   alarm     risk >= alarm.on, or probability >= alarm_forecast.on; or a collapse held
// Collapse: collapse_detected raises the alarm at once (no hold) and latches it; the collapse
// is then held, whatever later inputs, acknowledgements or restarts (restore) say, until a
// person states that the statue stands again (statue_stands; refused while an input still says
// collapse).
// Latching: a rise of the condition level into warning (latch_warning) or alarm (latch_alarm,
// any collapse) latches it: the level shown stays at least there until acknowledged. An
// acknowledgement names the latched level and quotes the latest event's sequence, else it
// changes nothing and the outcome says why; an accepted one releases the latch and the level
// follows its condition (an alarm whose condition holds stays, and lowers later by itself).
// Trouble, shown beside the level (AlarmOutput::trouble, each event's):
//  - fault_active (or an invalid risk input: an internal fault): the risk is stale. Shown at
//    once, held lower_hold_s after it clears. The level: alarm if the risk level (condition or
//    latch) is alarm, else a latched warning, else fault: a fault never hides an alarm or a
//    latched warning; it hides the live warning or advisory, which show again when it ends.
//  - not_calibrated: the same, cause kNotCalibrated, exactly while it lasts (no hold: a state
//    of knowledge); an active fault's own cause is reported instead.
//  - input_fault (a supplementary input refused; the risk is the box's without it): held as a
//    fault; the level is the risk level, fault only while that is normal. It hides nothing.
// Events: one each time the level shown, its latched flag or the trouble changes, at most two
// per update (an acknowledgement or a statement first, against what the operator saw, then the
// new input); sequences from 0, wrapping 255 -> 0. Cause: why the new level holds
// (risk_threshold; collapse_forecast when the forecast alone holds it; p_wave when the P-wave
// stage alone holds the warning, else regional_alert when the regional alert alone holds it;
// phase_change, overturn_detected, the fault's cause; restored for a level a restart brought
// back), none back to normal, acknowledged or statue_stands for a change a person made, the
// trouble's cause when only the trouble changed.
// Times are int64 ns of monitor time since start, never decreasing: an update with an earlier
// time is refused (InputProblem::kTimeWentBack).
class AlarmPolicy {
 public:
  AlarmPolicy() = default;

  // Fails on invalid settings (the Error names the field); `out` is then left untouched.
  [[nodiscard]] static Error create(const AlarmPolicySettings& settings, AlarmPolicy& out);

  [[nodiscard]] AlarmOutput update(const AlarmInput& input);

  [[nodiscard]] AlarmLevel level() const { return level_; }
  [[nodiscard]] AlarmLevel latched_level() const { return latched_level_; }
  [[nodiscard]] bool collapse_held() const { return collapse_held_; }
  // `sequence` is the latest event's (what an acknowledgement or a statement must quote).
  [[nodiscard]] bool sequence_is_latest(std::uint8_t sequence) const {
    return any_event_ && sequence == last_event_sequence_;
  }

  // What a restart must not lose; restore() it into a new policy before its first update: the
  // latch and the held collapse come back with cause kRestored, shown by the first update.
  [[nodiscard]] AlarmMemory memory() const;
  void restore(const AlarmMemory& memory);
  // Heartbeat: a status is due every heartbeat_period_s after the last heartbeat_sent(), and at
  // once after an event. When the next is due, ns (the lowest int64 before the first: due).
  [[nodiscard]] std::int64_t next_heartbeat_ns() const { return next_heartbeat_ns_; }
  [[nodiscard]] bool heartbeat_due(std::int64_t now_ns) const {
    return now_ns >= next_heartbeat_ns_;
  }
  void heartbeat_sent(std::int64_t now_ns);

  [[nodiscard]] const AlarmPolicySettings& settings() const { return settings_; }

 private:
  [[nodiscard]] AckOutcome acknowledge(const Acknowledgement& ack);
  [[nodiscard]] StandsOutcome statue_stands(std::uint8_t sequence, bool collapse_now);
  [[nodiscard]] AlarmLevel condition_level() const;
  [[nodiscard]] AlarmCause trouble() const;
  void evaluate_conditions(const AlarmInput& input, bool risk_valid);
  [[nodiscard]] AlarmLevel shown_level() const;
  [[nodiscard]] AlarmCause cause_of(AlarmLevel level) const;
  [[nodiscard]] AlarmCause condition_cause(AlarmLevel level) const;
  // by_person: the cause a person's command gives a change (kNone: the input's).
  void emit_if_changed(AlarmOutput& out, std::int64_t time_ns, AlarmCause by_person);

  AlarmPolicySettings settings_;
  std::int64_t raise_hold_ns_ = 0;
  std::int64_t lower_hold_ns_ = 0;
  std::int64_t heartbeat_period_ns_ = 0;

  detail::HeldCondition advisory_;
  detail::HeldCondition warning_;
  detail::HeldCondition alarm_;
  detail::HeldCondition fault_;
  detail::HeldCondition input_fault_;  // a supplementary input refused (held as a fault)
  AlarmCause input_fault_cause_ = AlarmCause::kNone;
  bool input_fault_input_ = false;  // the latest input's input_fault
  bool collapse_ = false;      // the latest input's collapse_detected
  bool collapse_held_ = false;  // a collapse seen, until a person says the statue stands
  bool collapse_restored_ = false;  // the held collapse came from restore()
  // The forecast alone holds the warning / alarm condition; the P wave alone, else the regional
  // alert alone, the warning (for the cause).
  bool warning_by_forecast_ = false;
  bool warning_by_pwave_ = false;
  bool warning_by_regional_ = false;
  bool alarm_by_forecast_ = false;
  bool out_of_contact_ = false;  // the latest input's out_of_full_contact
  bool not_calibrated_ = false;  // the latest input's not_calibrated
  bool fault_input_ = false;     // the latest input's fault (fault_active or an invalid risk)
  AlarmCause fault_cause_ = AlarmCause::kNone;
  AlarmLevel condition_level_ = AlarmLevel::kNormal;
  AlarmLevel latched_level_ = AlarmLevel::kNormal;
  AlarmCause latched_cause_ = AlarmCause::kNone;

  AlarmLevel level_ = AlarmLevel::kNormal;  // shown
  bool latched_shown_ = false;              // the latched flag of the last event
  AlarmCause trouble_shown_ = AlarmCause::kNone;  // the trouble of the last event
  bool restored_ = false;  // restore() brought something back: the first event says so
  bool any_event_ = false;
  std::uint8_t next_sequence_ = 0;
  std::uint8_t last_event_sequence_ = 0;
  bool started_ = false;
  std::int64_t last_time_ns_ = 0;
  std::int64_t next_heartbeat_ns_ = std::numeric_limits<std::int64_t>::min();
};

}  // namespace plinth::monitor

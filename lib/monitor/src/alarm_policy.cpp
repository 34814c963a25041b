#include "plinth/monitor/alarm_policy.h"

#include <cmath>

#include "settings_checks.h"

namespace plinth::monitor {

namespace {

constexpr int rank(AlarmLevel level) { return static_cast<int>(level); }

constexpr AlarmLevel higher(AlarmLevel a, AlarmLevel b) { return rank(a) >= rank(b) ? a : b; }

Error check_thresholds(const RiskThresholds& t, const char* on_field, const char* off_field) {
  if (!std::isfinite(t.on)) return {ErrorCode::kNotFinite, on_field, "must be finite"};
  if (!std::isfinite(t.off)) return {ErrorCode::kNotFinite, off_field, "must be finite"};
  if (t.on < Real(0) || t.on > Real(1)) {
    return {ErrorCode::kOutOfRange, on_field, "must lie in [0, 1]", Real(1)};
  }
  if (t.off < Real(0) || t.off > Real(1)) {
    return {ErrorCode::kOutOfRange, off_field, "must lie in [0, 1]", Real(1)};
  }
  if (t.off >= t.on) {
    return {ErrorCode::kInconsistent, off_field, "must be below the level's on threshold", t.on};
  }
  return ok_error();
}
// A warning-only input's thresholds in a build without its part: nothing to check.
[[maybe_unused]] Error check_thresholds(NotBuilt, const char*, const char*) { return ok_error(); }

// A level's thresholds must not lie below those of the level beneath it.
Error check_order(const RiskThresholds& lower, const RiskThresholds& upper, const char* on_field,
                  const char* off_field) {
  if (upper.on < lower.on) {
    return {ErrorCode::kInconsistent, on_field, "must not be below the lower level's on",
            lower.on};
  }
  if (upper.off < lower.off) {
    return {ErrorCode::kInconsistent, off_field, "must not be below the lower level's off",
            lower.off};
  }
  return ok_error();
}

// A threshold with hysteresis: start at `on`, hold down to `off`.
bool above(const detail::HeldCondition& held, const RiskThresholds& t, Real value) {
  return value >= (held.active ? t.off : t.on);
}
// A warning-only input in a build without its part: never.
// (unused in a build that has every part: clang's -Wunused-function, the fuzz preset)
[[maybe_unused]] constexpr bool above(const detail::HeldCondition&, NotBuilt, Real) {
  return false;
}

bool valid_fraction(Real v) { return std::isfinite(v) && v >= Real(0) && v <= Real(1); }

}  // namespace

void detail::HeldCondition::update(bool wanted, std::int64_t now_ns, std::int64_t raise_hold_ns,
                                   std::int64_t lower_hold_ns) {
  if (wanted == active) {
    changing = false;
    return;
  }
  if (!changing) {
    changing = true;
    since_ns = now_ns;
  }
  if (now_ns - since_ns >= (wanted ? raise_hold_ns : lower_hold_ns)) {
    active = wanted;
    changing = false;
  }
}

Error validate(const AlarmPolicySettings& s) {
  // The warning-only inputs' thresholds (none to check in a build without their part).
  PLINTH_TRY(check_thresholds(s.warning_pwave, "alarm_policy.warning_pwave.on",
                              "alarm_policy.warning_pwave.off"));
  PLINTH_TRY(check_thresholds(s.warning_regional, "alarm_policy.warning_regional.on",
                              "alarm_policy.warning_regional.off"));
  return detail::first_error({
      check_thresholds(s.advisory, "alarm_policy.advisory.on", "alarm_policy.advisory.off"),
      check_thresholds(s.warning, "alarm_policy.warning.on", "alarm_policy.warning.off"),
      check_thresholds(s.alarm, "alarm_policy.alarm.on", "alarm_policy.alarm.off"),
      check_order(s.advisory, s.warning, "alarm_policy.warning.on", "alarm_policy.warning.off"),
      check_order(s.warning, s.alarm, "alarm_policy.alarm.on", "alarm_policy.alarm.off"),
      check_thresholds(s.advisory_forecast, "alarm_policy.advisory_forecast.on",
                       "alarm_policy.advisory_forecast.off"),
      check_thresholds(s.warning_forecast, "alarm_policy.warning_forecast.on",
                       "alarm_policy.warning_forecast.off"),
      check_thresholds(s.alarm_forecast, "alarm_policy.alarm_forecast.on",
                       "alarm_policy.alarm_forecast.off"),
      check_order(s.advisory_forecast, s.warning_forecast, "alarm_policy.warning_forecast.on",
                  "alarm_policy.warning_forecast.off"),
      check_order(s.warning_forecast, s.alarm_forecast, "alarm_policy.alarm_forecast.on",
                  "alarm_policy.alarm_forecast.off"),
      detail::check_duration(s.raise_hold_s, "alarm_policy.raise_hold_s", true),
      detail::check_duration(s.lower_hold_s, "alarm_policy.lower_hold_s", true),
      detail::check_duration(s.heartbeat_period_s, "alarm_policy.heartbeat_period_s", false),
  });
}

Error AlarmPolicy::create(const AlarmPolicySettings& settings, AlarmPolicy& out) {
  PLINTH_TRY(validate(settings));
  out = AlarmPolicy{};
  out.settings_ = settings;
  out.raise_hold_ns_ = detail::to_ns(settings.raise_hold_s);
  out.lower_hold_ns_ = detail::to_ns(settings.lower_hold_s);
  out.heartbeat_period_ns_ = detail::to_ns(settings.heartbeat_period_s);
  return ok_error();
}

void AlarmPolicy::heartbeat_sent(std::int64_t now_ns) {
  next_heartbeat_ns_ = now_ns + heartbeat_period_ns_;
}

// Against the state the operator saw: the latest event and the latched level.
AckOutcome AlarmPolicy::acknowledge(const Acknowledgement& ack) {
  if (latched_level_ == AlarmLevel::kNormal) return AckOutcome::kNothingLatched;
  if (!any_event_ || ack.event_sequence != last_event_sequence_) return AckOutcome::kStale;
  if (ack.level != latched_level_) return AckOutcome::kWrongLevel;
  latched_level_ = AlarmLevel::kNormal;
  latched_cause_ = AlarmCause::kNone;
  return rank(condition_level_) >= rank(ack.level) ? AckOutcome::kReleasedConditionHolds
                                                   : AckOutcome::kReleased;
}

// A person's statement, against the latest event they saw: the held collapse clears, unless an
// input still says collapse.
StandsOutcome AlarmPolicy::statue_stands(std::uint8_t sequence, bool collapse_now) {
  if (!collapse_held_) return StandsOutcome::kNothingHeld;
  if (!sequence_is_latest(sequence)) return StandsOutcome::kStale;
  if (collapse_now) return StandsOutcome::kStillCollapsed;
  collapse_held_ = false;
  collapse_restored_ = false;
  collapse_ = false;
  condition_level_ = condition_level();
  return StandsOutcome::kCleared;
}

AlarmMemory AlarmPolicy::memory() const {
  return {latched_level_, latched_cause_, collapse_held_, next_sequence_};
}

void AlarmPolicy::restore(const AlarmMemory& m) {
  const bool latch = m.latched_level == AlarmLevel::kWarning || m.latched_level == AlarmLevel::kAlarm;
  latched_level_ = latch ? m.latched_level : AlarmLevel::kNormal;
  latched_cause_ = latch ? AlarmCause::kRestored : AlarmCause::kNone;
  collapse_held_ = m.collapse_held;
  collapse_restored_ = m.collapse_held;
  next_sequence_ = m.next_sequence;
  restored_ = latch || m.collapse_held;
  condition_level_ = condition_level();
}

// The highest level whose condition holds.
AlarmLevel AlarmPolicy::condition_level() const {
  return collapse_held_ || alarm_.active ? AlarmLevel::kAlarm
         : warning_.active               ? AlarmLevel::kWarning
         : advisory_.active              ? AlarmLevel::kAdvisory
                                         : AlarmLevel::kNormal;
}

void AlarmPolicy::evaluate_conditions(const AlarmInput& in, bool risk_valid) {
  // An invalid risk leaves the risk conditions as they were (their holds keep running).
  if (risk_valid) {
    const bool advisory = above(advisory_, settings_.advisory, in.risk) ||
                          above(advisory_, settings_.advisory_forecast, in.probability) ||
                          in.out_of_full_contact;
    const bool warning_risk = above(warning_, settings_.warning, in.risk);
    const bool warning_forecast = above(warning_, settings_.warning_forecast, in.probability);
    const bool alarm_risk = above(alarm_, settings_.alarm, in.risk);
    const bool alarm_forecast = above(alarm_, settings_.alarm_forecast, in.probability);
    const bool warning_pwave = above(warning_, settings_.warning_pwave, in.pwave_probability);
    const bool warning_regional =
        above(warning_, settings_.warning_regional, in.regional_probability);
    const bool warning = warning_risk || warning_forecast || warning_pwave || warning_regional;
    const bool alarm = alarm_risk || alarm_forecast;
    warning_by_forecast_ = warning_forecast && !warning_risk;
    warning_by_pwave_ = warning_pwave && !warning_risk && !warning_forecast;
    warning_by_regional_ =
        warning_regional && !warning_risk && !warning_forecast && !warning_pwave;
    alarm_by_forecast_ = alarm_forecast && !alarm_risk;
    advisory_.update(advisory, in.time_ns, raise_hold_ns_, lower_hold_ns_);
    warning_.update(warning, in.time_ns, raise_hold_ns_, lower_hold_ns_);
    alarm_.update(alarm, in.time_ns, raise_hold_ns_, lower_hold_ns_);
  }
  const bool collapse_began = in.collapse_detected && !collapse_;
  collapse_ = in.collapse_detected;
  if (collapse_) {
    collapse_held_ = true;
    collapse_restored_ = collapse_restored_ && !collapse_began;
  }
  out_of_contact_ = in.out_of_full_contact;
  not_calibrated_ = in.not_calibrated;

  // Trouble is shown at once; it clears only after lower_hold_s without it.
  const bool fault = in.fault_active || !risk_valid;
  fault_input_ = fault;
  fault_.update(fault, in.time_ns, 0, lower_hold_ns_);
  if (fault) fault_cause_ = risk_valid ? in.fault_cause : AlarmCause::kInternalFault;
  const bool input_fault = in.input_fault != AlarmCause::kNone;
  input_fault_input_ = input_fault;
  input_fault_.update(input_fault, in.time_ns, 0, lower_hold_ns_);
  if (input_fault) input_fault_cause_ = in.input_fault;

  const AlarmLevel previous = condition_level_;
  condition_level_ = condition_level();

  // Latch on a rise into a latching level (the highest one passed); a collapse latches the
  // alarm when it begins, whatever came before. A condition that stays up does not latch again.
  AlarmLevel latch = AlarmLevel::kNormal;
  if (collapse_began) {
    latch = AlarmLevel::kAlarm;
  } else if (rank(condition_level_) > rank(previous)) {
    if (condition_level_ == AlarmLevel::kAlarm && settings_.latch_alarm) {
      latch = AlarmLevel::kAlarm;
    } else if (rank(condition_level_) >= rank(AlarmLevel::kWarning) &&
               rank(previous) < rank(AlarmLevel::kWarning) && settings_.latch_warning) {
      latch = AlarmLevel::kWarning;
    }
  }
  if (latch != AlarmLevel::kNormal && rank(latch) >= rank(latched_level_)) {
    latched_level_ = latch;
    latched_cause_ = collapse_began ? AlarmCause::kOverturnDetected : condition_cause(latch);
  }
}

// Alarm above all; then a latched warning; then fault (held, or not calibrated); then the risk
// level, or fault in its place while a refused input's trouble holds and the level is normal.
AlarmLevel AlarmPolicy::shown_level() const {
  const AlarmLevel risk_level = higher(condition_level_, latched_level_);
  if (risk_level == AlarmLevel::kAlarm) return AlarmLevel::kAlarm;
  if (fault_.active || not_calibrated_) {
    return latched_level_ == AlarmLevel::kWarning ? AlarmLevel::kWarning : AlarmLevel::kFault;
  }
  if (input_fault_.active && risk_level == AlarmLevel::kNormal) return AlarmLevel::kFault;
  return risk_level;
}

// The trouble beside the level: a fault now, else not calibrated, else a refused input now;
// while none is active but a fault or a refused input is still held (lower_hold_s), the trouble
// last shown stays (a hold is no news).
AlarmCause AlarmPolicy::trouble() const {
  if (fault_input_) return fault_cause_;
  if (not_calibrated_) return AlarmCause::kNotCalibrated;
  if (input_fault_input_) return input_fault_cause_;
  if (!fault_.active && !input_fault_.active) return AlarmCause::kNone;
  if (trouble_shown_ != AlarmCause::kNone) return trouble_shown_;
  return fault_.active ? fault_cause_ : input_fault_cause_;
}

// Why `level` holds now.
AlarmCause AlarmPolicy::cause_of(AlarmLevel level) const {
  switch (level) {
    case AlarmLevel::kNormal: return AlarmCause::kNone;
    case AlarmLevel::kFault: return trouble();
    case AlarmLevel::kAdvisory:
      return out_of_contact_ ? AlarmCause::kPhaseChange : AlarmCause::kRiskThreshold;
    case AlarmLevel::kWarning:
    case AlarmLevel::kAlarm:
      if (collapse_held_ && level == AlarmLevel::kAlarm) {
        return collapse_restored_ ? AlarmCause::kRestored : AlarmCause::kOverturnDetected;
      }
      // Held by its latch alone: the cause it latched with.
      if (rank(condition_level_) < rank(level) && latched_level_ == level) return latched_cause_;
      return condition_cause(level);
  }
  return AlarmCause::kNone;
}

// Which signal holds the warning or alarm condition: the risk, else the forecast, else (warning
// only) the P wave measured on site, else the regional alert.
AlarmCause AlarmPolicy::condition_cause(AlarmLevel level) const {
  if (level == AlarmLevel::kAlarm) {
    return alarm_by_forecast_ ? AlarmCause::kCollapseForecast : AlarmCause::kRiskThreshold;
  }
  if (warning_by_forecast_) return AlarmCause::kCollapseForecast;
  if (kPWaveStageBuiltIn && warning_by_pwave_) return AlarmCause::kPWave;
  return kRegionalAlertBuiltIn && warning_by_regional_ ? AlarmCause::kRegionalAlert
                                                       : AlarmCause::kRiskThreshold;
}

void AlarmPolicy::emit_if_changed(AlarmOutput& out, std::int64_t time_ns, AlarmCause by_person) {
  const AlarmLevel shown = shown_level();
  const bool latched = latched_level_ != AlarmLevel::kNormal;
  const AlarmCause trouble_now = trouble();
  if (shown == level_ && latched == latched_shown_ && trouble_now == trouble_shown_) return;

  AlarmEventRecord& e = out.events[out.event_count++];
  e.level = shown;
  e.previous_level = level_;
  e.latched = latched;
  e.trouble = trouble_now;
  e.time_ns = time_ns;
  e.sequence = next_sequence_;
  if (by_person != AlarmCause::kNone) {
    e.cause = by_person;
  } else if (restored_) {
    e.cause = AlarmCause::kRestored;  // the first event after a restart that restored a level
  } else if (shown != level_) {
    e.cause = cause_of(shown);
  } else if (latched != latched_shown_) {
    e.cause = latched_cause_;  // only the latch changed: a level latched beneath a fault
  } else {
    // Only the trouble changed: its cause, or the level's own once it cleared.
    e.cause = trouble_now != AlarmCause::kNone ? trouble_now : cause_of(shown);
  }
  restored_ = false;
  last_event_sequence_ = next_sequence_;
  next_sequence_ = static_cast<std::uint8_t>(next_sequence_ + 1);
  any_event_ = true;
  level_ = shown;
  latched_shown_ = latched;
  trouble_shown_ = trouble_now;
  // A change is reported at once: the next status is due now.
  if (time_ns < next_heartbeat_ns_) next_heartbeat_ns_ = time_ns;
}

AlarmOutput AlarmPolicy::update(const AlarmInput& in) {
  AlarmOutput out;
  if (started_ && in.time_ns < last_time_ns_) {
    out.input_problem = InputProblem::kTimeWentBack;
  } else {
    started_ = true;
    last_time_ns_ = in.time_ns;
    if (in.acknowledged) {
      out.acknowledgement = acknowledge(in.acknowledgement);
      emit_if_changed(out, in.time_ns, AlarmCause::kAcknowledged);
    } else if (in.statue_stands) {
      out.statue_stands = statue_stands(in.statue_stands_sequence, in.collapse_detected);
      emit_if_changed(out, in.time_ns, AlarmCause::kStatueStands);
    }
    const bool risk_valid =
        valid_fraction(in.risk) && valid_fraction(in.probability) &&
        (!kPWaveStageBuiltIn || valid_fraction(in.pwave_probability)) &&
        (!kRegionalAlertBuiltIn || valid_fraction(in.regional_probability));
    if (!risk_valid) out.input_problem = InputProblem::kRiskInvalid;
    evaluate_conditions(in, risk_valid);
    emit_if_changed(out, in.time_ns, AlarmCause::kNone);
  }
  out.level = level_;
  out.latched_level = latched_level_;
  out.trouble = trouble_shown_;
  out.collapse_held = collapse_held_;
  return out;
}

}  // namespace plinth::monitor

// Alarm policy: hysteresis, minimum durations, latching and acknowledgement, collapse, faults,
// event sequence numbers and the heartbeat.
#include "plinth/monitor/alarm_policy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "settings_support.h"

namespace plinth::monitor {
namespace {

constexpr std::int64_t kMs = 1'000'000;  // ns

// Settings with no holds and no latches: levels follow the thresholds at once. The thresholds
// are the tests' own (the defaults are calibrated, docs/forecast.md, and may move).
AlarmPolicySettings immediate() {
  AlarmPolicySettings s;
  s.advisory = {0.1, 0.05};
  s.warning = {0.5, 0.4};
  s.alarm = {0.8, 0.7};
  s.advisory_forecast = {0.2, 0.1};
  s.warning_forecast = {0.5, 0.4};
  s.alarm_forecast = {0.9, 0.8};
  s.warning_pwave = {0.6, 0.3};
  s.warning_regional = {0.6, 0.3};
  s.raise_hold_s = 0.0;
  s.lower_hold_s = 0.0;
  s.latch_warning = false;
  s.latch_alarm = false;
  return s;
}

// immediate(), latching the levels asked for.
AlarmPolicySettings latching(bool warning, bool alarm) {
  AlarmPolicySettings s = immediate();
  s.latch_warning = warning;
  s.latch_alarm = alarm;
  return s;
}

class Policy {
 public:
  explicit Policy(const AlarmPolicySettings& settings = {}) {
    const Error e = AlarmPolicy::create(settings, policy);
    EXPECT_TRUE(e.ok()) << e.field << ": " << e.reason;
  }

  // One update at time_ms with the given risk; the other inputs from `base`.
  AlarmOutput at(std::int64_t time_ms, double risk) {
    AlarmInput in = base;
    in.time_ns = time_ms * kMs;
    in.risk = risk;
    return policy.update(in);
  }
  AlarmOutput ack(std::int64_t time_ms, double risk, AlarmLevel level, std::uint8_t sequence) {
    AlarmInput in = base;
    in.time_ns = time_ms * kMs;
    in.risk = risk;
    in.acknowledged = true;
    in.acknowledgement = {level, sequence};
    return policy.update(in);
  }

  // A person states that the statue stands, quoting `sequence`.
  AlarmOutput stands(std::int64_t time_ms, double risk, std::uint8_t sequence) {
    AlarmInput in = base;
    in.time_ns = time_ms * kMs;
    in.risk = risk;
    in.statue_stands = true;
    in.statue_stands_sequence = sequence;
    return policy.update(in);
  }

  AlarmPolicy policy;
  AlarmInput base;
};

void expect_event(const AlarmOutput& out, std::size_t index, AlarmLevel level,
                  AlarmLevel previous, AlarmCause cause, bool latched) {
  ASSERT_GT(out.event_count, index);
  const AlarmEventRecord& e = out.events[index];
  EXPECT_EQ(e.level, level) << alarm_level_name(e.level);
  EXPECT_EQ(e.previous_level, previous) << alarm_level_name(e.previous_level);
  EXPECT_EQ(e.cause, cause) << alarm_cause_name(e.cause);
  EXPECT_EQ(e.latched, latched);
}

// The output's level is `level`, and its first event reports the change from `previous`.
void expect_change(const AlarmOutput& out, AlarmLevel level, AlarmLevel previous,
                   AlarmCause cause, bool latched) {
  EXPECT_EQ(out.level, level);
  expect_event(out, 0, level, previous, cause, latched);
}

// ---------------------------------------------------------------------------------------------
// Settings

// create() validates: the Error names the field.
void expect_refused(const AlarmPolicySettings& s, const char* field, ErrorCode code) {
  plinth::testing::expect_create_refused<AlarmPolicy>(s, field, code);
}

TEST(AlarmPolicySettings, DefaultsAreValidAndThresholdsAreChecked) {
  EXPECT_TRUE(validate(AlarmPolicySettings{}).ok());
  AlarmPolicySettings s;
  s.warning.off = 0.5;  // equal to on: no hysteresis
  expect_refused(s, "alarm_policy.warning.off", ErrorCode::kInconsistent);
  s = {};
  s.alarm.on = 1.01;
  expect_refused(s, "alarm_policy.alarm.on", ErrorCode::kOutOfRange);
  s = {};
  s.advisory.off = -0.01;
  expect_refused(s, "alarm_policy.advisory.off", ErrorCode::kOutOfRange);
  s = {};
  s.advisory.on = std::numeric_limits<double>::quiet_NaN();
  expect_refused(s, "alarm_policy.advisory.on", ErrorCode::kNotFinite);
  s = {};
  s.warning.on = 0.85;  // above alarm.on
  expect_refused(s, "alarm_policy.alarm.on", ErrorCode::kInconsistent);
  s = {};
  s.advisory.off = 0.09;  // just below its on, 0.1
  EXPECT_TRUE(validate(s).ok());
  s.warning = {0.5, 0.04};  // off below advisory.off 0.09
  expect_refused(s, "alarm_policy.warning.off", ErrorCode::kInconsistent);
  s = {};
  s.warning_forecast = {0.95, 0.4};  // above alarm_forecast.on
  expect_refused(s, "alarm_policy.alarm_forecast.on", ErrorCode::kInconsistent);
  s = {};
  s.advisory_forecast.off = 0.2;  // equal to its on
  expect_refused(s, "alarm_policy.advisory_forecast.off", ErrorCode::kInconsistent);
  s = {};
  s.warning_pwave = {0.3, 0.3};
  expect_refused(s, "alarm_policy.warning_pwave.off", ErrorCode::kInconsistent);
  s.warning_pwave = {1.2, 0.3};
  expect_refused(s, "alarm_policy.warning_pwave.on", ErrorCode::kOutOfRange);
  s.warning_pwave = {0.05, 0.01};  // below the other warnings: a level of its own, not ordered
  EXPECT_TRUE(validate(s).ok());
  s = {};
  s.warning_regional = {0.3, 0.3};
  expect_refused(s, "alarm_policy.warning_regional.off", ErrorCode::kInconsistent);
  s.warning_regional = {1.2, 0.3};
  expect_refused(s, "alarm_policy.warning_regional.on", ErrorCode::kOutOfRange);
  s.warning_regional = {0.05, 0.01};  // below the other warnings: a level of its own
  EXPECT_TRUE(validate(s).ok());
  s = {};
  s.alarm.on = 1.0;  // the edges of [0, 1] are allowed
  s.advisory.off = 0.0;
  EXPECT_TRUE(validate(s).ok());
}

TEST(AlarmPolicySettings, DurationsAreChecked) {
  AlarmPolicySettings s;
  s.raise_hold_s = -0.001;
  expect_refused(s, "alarm_policy.raise_hold_s", ErrorCode::kOutOfRange);
  s = {};
  s.lower_hold_s = std::numeric_limits<double>::infinity();
  expect_refused(s, "alarm_policy.lower_hold_s", ErrorCode::kNotFinite);
  s = {};
  s.heartbeat_period_s = 0.0;
  expect_refused(s, "alarm_policy.heartbeat_period_s", ErrorCode::kOutOfRange);
  s = {};
  s.raise_hold_s = 0.0;  // zero holds are allowed
  s.lower_hold_s = 0.0;
  EXPECT_TRUE(validate(s).ok());
}

// ---------------------------------------------------------------------------------------------
// Thresholds and holds

TEST(AlarmPolicy, HysteresisBoundary) {
  Policy p(immediate());
  EXPECT_EQ(p.at(0, 0.0999).level, AlarmLevel::kNormal);
  EXPECT_EQ(p.at(1, 0.1).level, AlarmLevel::kAdvisory);
  EXPECT_EQ(p.at(2, 0.4999).level, AlarmLevel::kAdvisory);
  const AlarmOutput on = p.at(3, 0.5);
  expect_change(on, AlarmLevel::kWarning, AlarmLevel::kAdvisory, AlarmCause::kRiskThreshold, false);
  EXPECT_EQ(p.at(4, 0.4).level, AlarmLevel::kWarning);  // at off: still on
  const AlarmOutput off = p.at(5, 0.3999);
  expect_change(off, AlarmLevel::kAdvisory, AlarmLevel::kWarning, AlarmCause::kRiskThreshold,
                false);
  EXPECT_EQ(p.at(6, 0.4999).level, AlarmLevel::kAdvisory);  // below on again: stays off
  EXPECT_EQ(p.at(7, 0.8).level, AlarmLevel::kAlarm);
  EXPECT_EQ(p.at(8, 0.7).level, AlarmLevel::kAlarm);
  EXPECT_EQ(p.at(9, 0.6999).level, AlarmLevel::kWarning);
  const AlarmOutput normal = p.at(10, 0.0499);
  expect_change(normal, AlarmLevel::kNormal, AlarmLevel::kWarning, AlarmCause::kNone, false);
}

TEST(AlarmPolicy, MinimumDurationBeforeRaisingAndLowering) {
  AlarmPolicySettings s = immediate();
  s.raise_hold_s = 0.1;
  s.lower_hold_s = 0.5;
  Policy p(s);
  // Warning condition from t = 1000 ms, updates every 10 ms: raised at 1100 ms, not 1090.
  for (std::int64_t t = 1000; t < 1100; t += 10) {
    ASSERT_EQ(p.at(t, 0.6).level, AlarmLevel::kNormal) << t;
  }
  const AlarmOutput raised = p.at(1100, 0.6);
  // Warning and advisory both held 100 ms.
  expect_change(raised, AlarmLevel::kWarning, AlarmLevel::kNormal, AlarmCause::kRiskThreshold,
                false);
  EXPECT_EQ(raised.events[0].time_ns, 1100 * kMs);
  // Gone from t = 2000 ms: lowered at 2500 ms.
  EXPECT_EQ(p.at(2000, 0.0).level, AlarmLevel::kWarning);
  EXPECT_EQ(p.at(2499, 0.0).level, AlarmLevel::kWarning);
  EXPECT_EQ(p.at(2500, 0.0).level, AlarmLevel::kNormal);
}

TEST(AlarmPolicy, AnInterruptedConditionStartsItsHoldAgain) {
  AlarmPolicySettings s = immediate();
  s.raise_hold_s = 0.1;
  Policy p(s);
  (void)p.at(0, 0.6);
  (void)p.at(90, 0.6);
  (void)p.at(95, 0.45);  // below on (not yet raised, so on applies): the hold restarts
  EXPECT_EQ(p.at(100, 0.6).level, AlarmLevel::kAdvisory);  // advisory held since 0
  EXPECT_EQ(p.at(199, 0.6).level, AlarmLevel::kAdvisory);
  EXPECT_EQ(p.at(200, 0.6).level, AlarmLevel::kWarning);
}

TEST(AlarmPolicy, AdvisoryWhenTheBlockLeavesFullContact) {
  AlarmPolicySettings s = immediate();
  s.raise_hold_s = 0.05;
  Policy p(s);
  p.base.out_of_full_contact = true;
  EXPECT_EQ(p.at(0, 0.0).level, AlarmLevel::kNormal);
  const AlarmOutput out = p.at(50, 0.0);
  expect_change(out, AlarmLevel::kAdvisory, AlarmLevel::kNormal, AlarmCause::kPhaseChange, false);
}

// ---------------------------------------------------------------------------------------------
// Latching and acknowledgement

TEST(AlarmPolicy, WarningLatchesUntilAcknowledged) {
  Policy p(latching(true, false));
  const AlarmOutput raised = p.at(0, 0.6);
  expect_event(raised, 0, AlarmLevel::kWarning, AlarmLevel::kNormal, AlarmCause::kRiskThreshold,
               true);
  EXPECT_EQ(raised.events[0].sequence, 0);
  EXPECT_EQ(raised.latched_level, AlarmLevel::kWarning);
  const AlarmOutput calm = p.at(10, 0.0);  // the condition is gone, the latch holds
  EXPECT_EQ(calm.level, AlarmLevel::kWarning);
  EXPECT_EQ(calm.event_count, 0U);
  const AlarmOutput acked = p.ack(20, 0.0, AlarmLevel::kWarning, 0);
  EXPECT_EQ(acked.acknowledgement, AckOutcome::kReleased);
  EXPECT_EQ(acked.level, AlarmLevel::kNormal);
  ASSERT_EQ(acked.event_count, 1U);
  expect_event(acked, 0, AlarmLevel::kNormal, AlarmLevel::kWarning, AlarmCause::kAcknowledged,
               false);
  EXPECT_EQ(acked.events[0].sequence, 1);
}

TEST(AlarmPolicy, AcknowledgingAnAlarmWhoseConditionHoldsKeepsIt) {
  Policy p(latching(false, true));
  (void)p.at(0, 0.9);
  const AlarmOutput acked = p.ack(10, 0.9, AlarmLevel::kAlarm, 0);
  EXPECT_EQ(acked.acknowledgement, AckOutcome::kReleasedConditionHolds);
  EXPECT_EQ(acked.level, AlarmLevel::kAlarm);
  EXPECT_EQ(acked.latched_level, AlarmLevel::kNormal);
  ASSERT_EQ(acked.event_count, 1U);  // the latch went: reported, level unchanged
  expect_event(acked, 0, AlarmLevel::kAlarm, AlarmLevel::kAlarm, AlarmCause::kAcknowledged, false);
  EXPECT_EQ(p.at(20, 0.9).event_count, 0U);  // no new latch while the condition stays up
  // It lowers with its condition, without another acknowledgement.
  const AlarmOutput lower = p.at(30, 0.2);
  EXPECT_EQ(lower.level, AlarmLevel::kAdvisory);
  // A new rise latches again.
  const AlarmOutput again = p.at(40, 0.95);
  expect_event(again, 0, AlarmLevel::kAlarm, AlarmLevel::kAdvisory, AlarmCause::kRiskThreshold,
               true);
}

TEST(AlarmPolicy, StaleWrongLevelAndNeedlessAcknowledgementsChangeNothing) {
  Policy p(latching(true, true));
  EXPECT_EQ(p.ack(0, 0.0, AlarmLevel::kWarning, 0).acknowledgement, AckOutcome::kNothingLatched);
  (void)p.at(10, 0.6);  // event 0: warning, latched
  (void)p.at(20, 0.9);  // event 1: alarm, latched
  const AlarmOutput stale = p.ack(30, 0.0, AlarmLevel::kAlarm, 0);  // before the alarm was seen
  EXPECT_EQ(stale.acknowledgement, AckOutcome::kStale);
  EXPECT_EQ(stale.event_count, 0U);
  EXPECT_EQ(stale.level, AlarmLevel::kAlarm);
  EXPECT_EQ(stale.latched_level, AlarmLevel::kAlarm);
  const AlarmOutput wrong = p.ack(40, 0.0, AlarmLevel::kWarning, 1);
  EXPECT_EQ(wrong.acknowledgement, AckOutcome::kWrongLevel);
  EXPECT_EQ(wrong.level, AlarmLevel::kAlarm);
  const AlarmOutput right = p.ack(50, 0.0, AlarmLevel::kAlarm, 1);
  EXPECT_EQ(right.acknowledgement, AckOutcome::kReleased);
  EXPECT_EQ(right.level, AlarmLevel::kNormal);  // the warning latch went with the alarm's
}

TEST(AlarmPolicy, CollapseGoesStraightToAlarmAndLatches) {
  AlarmPolicySettings s;
  s.raise_hold_s = 0.1;   // holds of 0.1 s and 2 s: the collapse does not wait for them
  s.latch_alarm = false;  // a collapse latches all the same
  Policy p(s);
  p.base.collapse_detected = true;
  const AlarmOutput fell = p.at(0, 0.3);
  expect_change(fell, AlarmLevel::kAlarm, AlarmLevel::kNormal, AlarmCause::kOverturnDetected, true);
  // Acknowledged while the block lies overturned: the alarm stays, unlatched.
  const AlarmOutput acked = p.ack(10, 0.3, AlarmLevel::kAlarm, 0);
  EXPECT_EQ(acked.acknowledgement, AckOutcome::kReleasedConditionHolds);
  EXPECT_EQ(acked.level, AlarmLevel::kAlarm);
  EXPECT_EQ(p.at(20, 0.3).latched_level, AlarmLevel::kNormal);  // not latched again
  // The detector restarts (collapse cleared): the collapse is held all the same.
  p.base.collapse_detected = false;
  const AlarmOutput held = p.at(30, 0.0);
  EXPECT_EQ(held.level, AlarmLevel::kAlarm);
  EXPECT_TRUE(held.collapse_held);
  // A person says the statue stands: the alarm follows its condition at once.
  const AlarmOutput stood = p.stands(40, 0.0, 1);
  EXPECT_EQ(stood.statue_stands, StandsOutcome::kCleared);
  expect_change(stood, AlarmLevel::kNormal, AlarmLevel::kAlarm, AlarmCause::kStatueStands, false);
  EXPECT_FALSE(stood.collapse_held);
}

// A collapse outlives its detection, its acknowledgement and a fault: only a person's statement
// that the statue stands clears it, quoting the latest event, and not while an input still
// says collapse.
TEST(AlarmPolicy, ACollapseIsHeldUntilAPersonSaysTheStatueStands) {
  Policy p(immediate());
  p.base.collapse_detected = true;
  (void)p.at(0, 0.0);  // event 0: alarm, overturn_detected, latched
  EXPECT_EQ(p.stands(5, 0.0, 0).statue_stands, StandsOutcome::kStillCollapsed);
  p.base.collapse_detected = false;
  const AlarmOutput later = p.at(10, 0.0);
  EXPECT_EQ(later.level, AlarmLevel::kAlarm);
  EXPECT_EQ(later.latched_level, AlarmLevel::kAlarm);
  const AlarmOutput acked = p.ack(20, 0.0, AlarmLevel::kAlarm, 0);  // event 1: unlatched
  EXPECT_EQ(acked.acknowledgement, AckOutcome::kReleasedConditionHolds);
  EXPECT_EQ(acked.level, AlarmLevel::kAlarm);
  // Not calibrated, a sensor fault: still the alarm, its cause the collapse.
  p.base.not_calibrated = true;
  p.base.fault_active = true;
  const AlarmOutput faulty = p.at(30, 0.0);  // event 2: the trouble
  EXPECT_EQ(faulty.level, AlarmLevel::kAlarm);
  EXPECT_EQ(faulty.trouble, AlarmCause::kSensorFault);
  p.base.not_calibrated = false;
  p.base.fault_active = false;
  EXPECT_EQ(p.stands(40, 0.0, 1).statue_stands, StandsOutcome::kStale);  // event 3: trouble gone
  EXPECT_EQ(p.at(41, 0.0).level, AlarmLevel::kAlarm);
  const AlarmOutput stood = p.stands(42, 0.0, 3);  // event 4: normal
  EXPECT_EQ(stood.statue_stands, StandsOutcome::kCleared);
  EXPECT_EQ(stood.level, AlarmLevel::kNormal);
  EXPECT_EQ(p.stands(50, 0.0, 4).statue_stands, StandsOutcome::kNothingHeld);
}

// What a restart must not lose comes back into a new policy: the latch, with cause restored,
// and the held collapse; the events' numbering goes on.
TEST(AlarmPolicy, MemoryRestoredAfterARestart) {
  Policy p(latching(true, true));
  p.base.collapse_detected = true;
  (void)p.at(0, 0.9);  // event 0
  const AlarmMemory m = p.policy.memory();
  EXPECT_EQ(m.latched_level, AlarmLevel::kAlarm);
  EXPECT_EQ(m.latched_cause, AlarmCause::kOverturnDetected);
  EXPECT_TRUE(m.collapse_held);
  EXPECT_EQ(m.next_sequence, 1);

  Policy q(latching(true, true));
  q.policy.restore(m);
  q.base.not_calibrated = true;  // a restarted box: its estimators untrusted
  const AlarmOutput first = q.at(0, 0.0);
  expect_change(first, AlarmLevel::kAlarm, AlarmLevel::kNormal, AlarmCause::kRestored, true);
  EXPECT_EQ(first.events[0].sequence, 1);
  EXPECT_EQ(first.trouble, AlarmCause::kNotCalibrated);
  EXPECT_TRUE(first.collapse_held);
  // Acknowledged: the held collapse keeps the alarm; its cause says it was restored.
  const AlarmOutput acked = q.ack(10, 0.0, AlarmLevel::kAlarm, 1);
  EXPECT_EQ(acked.acknowledgement, AckOutcome::kReleasedConditionHolds);
  EXPECT_EQ(acked.level, AlarmLevel::kAlarm);

  // A latched warning alone comes back shown through the restart's not-calibrated fault.
  AlarmMemory warning;
  warning.latched_level = AlarmLevel::kWarning;
  warning.latched_cause = AlarmCause::kRiskThreshold;
  Policy r(latching(true, true));
  r.policy.restore(warning);
  r.base.not_calibrated = true;
  expect_change(r.at(0, 0.0), AlarmLevel::kWarning, AlarmLevel::kNormal, AlarmCause::kRestored,
                true);
  // Nothing to restore: a fresh start.
  Policy fresh(latching(true, true));
  fresh.policy.restore(AlarmMemory{});
  fresh.base.not_calibrated = true;
  expect_change(fresh.at(0, 0.0), AlarmLevel::kFault, AlarmLevel::kNormal,
                AlarmCause::kNotCalibrated, false);
}

// A supplementary input refused (input_fault): the trouble beside the level, never in its place
// (the risk is the box's without that input); the fault level only while the level is normal.
TEST(AlarmPolicy, ARefusedInputShowsTroubleBesideTheLevel) {
  AlarmPolicySettings s = immediate();
  s.lower_hold_s = 0.5;
  Policy p(s);
  p.base.input_fault = AlarmCause::kStatueSensorFault;
  expect_change(p.at(0, 0.0), AlarmLevel::kFault, AlarmLevel::kNormal,
                AlarmCause::kStatueSensorFault, false);
  const AlarmOutput warning = p.at(10, 0.6);
  expect_change(warning, AlarmLevel::kWarning, AlarmLevel::kFault, AlarmCause::kRiskThreshold,
                false);
  EXPECT_EQ(warning.trouble, AlarmCause::kStatueSensorFault);
  EXPECT_EQ(warning.events[0].trouble, AlarmCause::kStatueSensorFault);
  // The input corroborated again: the trouble clears after the lower hold, with an event.
  p.base.input_fault = AlarmCause::kNone;
  EXPECT_EQ(p.at(100, 0.6).trouble, AlarmCause::kStatueSensorFault);
  EXPECT_EQ(p.at(599, 0.6).trouble, AlarmCause::kStatueSensorFault);
  const AlarmOutput cleared = p.at(600, 0.6);
  expect_change(cleared, AlarmLevel::kWarning, AlarmLevel::kWarning, AlarmCause::kRiskThreshold,
                false);
  EXPECT_EQ(cleared.trouble, AlarmCause::kNone);
  // Beside an alarm: the trouble's own event, the level kept.
  p.base.input_fault = AlarmCause::kStatueUnexplained;
  const AlarmOutput alarm = p.at(700, 0.9);
  EXPECT_EQ(alarm.level, AlarmLevel::kAlarm);
  EXPECT_EQ(alarm.trouble, AlarmCause::kStatueUnexplained);
}

// ---------------------------------------------------------------------------------------------
// Faults

TEST(AlarmPolicy, FaultIsShownAtOnceAndClearsAfterTheLowerHold) {
  AlarmPolicySettings s = immediate();
  s.lower_hold_s = 0.5;
  Policy p(s);
  p.base.fault_active = true;
  p.base.fault_cause = AlarmCause::kSensorTimeout;
  const AlarmOutput fault = p.at(0, 0.0);
  expect_change(fault, AlarmLevel::kFault, AlarmLevel::kNormal, AlarmCause::kSensorTimeout, false);
  p.base.fault_active = false;
  EXPECT_EQ(p.at(100, 0.0).level, AlarmLevel::kFault);
  EXPECT_EQ(p.at(599, 0.0).level, AlarmLevel::kFault);
  const AlarmOutput cleared = p.at(600, 0.0);
  expect_change(cleared, AlarmLevel::kNormal, AlarmLevel::kFault, AlarmCause::kNone, false);
}

// Not calibrated: the fault level at once and for exactly as long as it lasts (no lower hold);
// an active fault beneath it reports its own cause; an alarm shows above it.
TEST(AlarmPolicy, NotCalibratedIsAFaultWithoutHold) {
  AlarmPolicySettings s = latching(false, true);
  Policy p(s);
  p.base.not_calibrated = true;
  expect_change(p.at(0, 0.0), AlarmLevel::kFault, AlarmLevel::kNormal, AlarmCause::kNotCalibrated,
                false);
  EXPECT_EQ(p.at(100, 0.95).level, AlarmLevel::kAlarm);  // event 1: alarm, latched
  EXPECT_EQ(p.at(150, 0.0).level, AlarmLevel::kAlarm);   // held by its latch
  const AlarmOutput acked = p.ack(200, 0.0, AlarmLevel::kAlarm, 1);
  expect_change(acked, AlarmLevel::kFault, AlarmLevel::kAlarm, AlarmCause::kAcknowledged, false);
  p.base.not_calibrated = false;
  expect_change(p.at(201, 0.0), AlarmLevel::kNormal, AlarmLevel::kFault, AlarmCause::kNone, false);

  // A sensor fault and not calibrated: the fault's cause; the fault's hold outlasts it.
  s.lower_hold_s = 0.5;
  Policy q(s);
  q.base.not_calibrated = true;
  q.base.fault_active = true;
  q.base.fault_cause = AlarmCause::kSensorTimeout;
  expect_change(q.at(0, 0.0), AlarmLevel::kFault, AlarmLevel::kNormal, AlarmCause::kSensorTimeout,
                false);
  q.base.fault_active = false;
  q.base.not_calibrated = false;
  EXPECT_EQ(q.at(10, 0.0).level, AlarmLevel::kFault);
  EXPECT_EQ(q.at(509, 0.0).level, AlarmLevel::kFault);
  EXPECT_EQ(q.at(510, 0.0).level, AlarmLevel::kNormal);
}

TEST(AlarmPolicy, AFaultNeverHidesAnAlarm) {
  Policy p(latching(false, true));
  (void)p.at(0, 0.9);  // event 0: alarm
  p.base.fault_active = true;
  // The level stays; the trouble shows beside it, with an event of its own.
  const AlarmOutput both = p.at(10, 0.9);
  EXPECT_EQ(both.level, AlarmLevel::kAlarm);
  expect_event(both, 0, AlarmLevel::kAlarm, AlarmLevel::kAlarm, AlarmCause::kSensorFault, true);
  EXPECT_EQ(both.trouble, AlarmCause::kSensorFault);
  // The alarm latched, its condition gone, still above the fault...
  EXPECT_EQ(p.at(20, 0.0).level, AlarmLevel::kAlarm);
  // ...until acknowledged: then the fault shows.
  const AlarmOutput acked = p.ack(30, 0.0, AlarmLevel::kAlarm, 1);
  expect_change(acked, AlarmLevel::kFault, AlarmLevel::kAlarm, AlarmCause::kAcknowledged, false);
}

// A fault hides the live warning (its risk is stale), never a latched one: a warning raised
// while the input was trusted stays shown until acknowledged.
TEST(AlarmPolicy, AFaultHidesALiveWarningNotALatchedOne) {
  Policy p(latching(true, false));
  (void)p.at(0, 0.6);  // event 0: warning, latched
  p.base.fault_active = true;
  const AlarmOutput fault = p.at(10, 0.0);
  expect_event(fault, 0, AlarmLevel::kWarning, AlarmLevel::kWarning, AlarmCause::kSensorFault,
               true);
  EXPECT_EQ(fault.level, AlarmLevel::kWarning);
  // Acknowledged under the fault: the fault shows.
  expect_change(p.ack(20, 0.0, AlarmLevel::kWarning, 1), AlarmLevel::kFault, AlarmLevel::kWarning,
                AlarmCause::kAcknowledged, false);
  // A live warning (not latching) is hidden by the fault, and shows again after it.
  Policy q(latching(false, false));
  (void)q.at(0, 0.6);  // event 0: warning
  q.base.fault_active = true;
  expect_change(q.at(10, 0.6), AlarmLevel::kFault, AlarmLevel::kWarning, AlarmCause::kSensorFault,
                false);
  q.base.fault_active = false;
  expect_change(q.at(20, 0.6), AlarmLevel::kWarning, AlarmLevel::kFault,
                AlarmCause::kRiskThreshold, false);
}

TEST(AlarmPolicy, AWarningLatchedBeneathAFaultShows) {
  Policy p(latching(true, false));
  p.base.fault_active = true;
  (void)p.at(0, 0.0);  // event 0: fault
  const AlarmOutput latched = p.at(10, 0.6);
  expect_change(latched, AlarmLevel::kWarning, AlarmLevel::kFault, AlarmCause::kRiskThreshold,
                true);
  EXPECT_EQ(latched.latched_level, AlarmLevel::kWarning);
  EXPECT_EQ(latched.trouble, AlarmCause::kSensorFault);
}

TEST(AlarmPolicy, AnInvalidRiskIsAnInternalFault) {
  Policy p(immediate());
  (void)p.at(0, 0.6);
  const AlarmOutput nan = p.at(10, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(nan.input_problem, InputProblem::kRiskInvalid);
  expect_event(nan, 0, AlarmLevel::kFault, AlarmLevel::kWarning, AlarmCause::kInternalFault, false);
  EXPECT_EQ(p.at(20, 0.6).level, AlarmLevel::kWarning);  // the warning held beneath
  EXPECT_EQ(p.at(30, 1.0001).input_problem, InputProblem::kRiskInvalid);
  EXPECT_EQ(p.at(40, -0.0001).level, AlarmLevel::kFault);
  EXPECT_EQ(p.at(50, 1.0).input_problem, InputProblem::kNone);
}

// The forecast's probability raises the levels as the risk does, with its own thresholds; the
// cause says which of the two holds the level.
TEST(AlarmPolicy, TheForecastRaisesLevelsWithItsOwnCause) {
  Policy p(immediate());
  const auto at = [&p](std::int64_t ms, double risk, double probability) {
    p.base.probability = probability;
    return p.at(ms, risk);
  };
  EXPECT_EQ(at(0, 0.0, 0.1999).level, AlarmLevel::kNormal);
  EXPECT_EQ(at(1, 0.0, 0.2).level, AlarmLevel::kAdvisory);
  expect_change(at(2, 0.0, 0.5), AlarmLevel::kWarning, AlarmLevel::kAdvisory,
                AlarmCause::kCollapseForecast, false);
  expect_change(at(3, 0.0, 0.9), AlarmLevel::kAlarm, AlarmLevel::kWarning,
                AlarmCause::kCollapseForecast, false);
  EXPECT_EQ(at(4, 0.0, 0.8).level, AlarmLevel::kAlarm);  // at off: still on
  // Both below their off: lowered; the risk alone at alarm: cause risk_threshold.
  EXPECT_EQ(at(5, 0.0, 0.7999).level, AlarmLevel::kWarning);
  expect_change(at(6, 0.8, 0.0), AlarmLevel::kAlarm, AlarmLevel::kWarning,
                AlarmCause::kRiskThreshold, false);
  // An invalid probability is an internal fault, as an invalid risk is.
  const AlarmOutput nan = at(7, 0.0, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(nan.input_problem, InputProblem::kRiskInvalid);
  EXPECT_EQ(at(8, 0.0, 1.5).input_problem, InputProblem::kRiskInvalid);
}

TEST(AlarmPolicy, ALevelLatchedByTheForecastKeepsItsCause) {
  Policy p(latching(true, true));
  p.base.probability = 0.95;
  expect_change(p.at(0, 0.0), AlarmLevel::kAlarm, AlarmLevel::kNormal,
                AlarmCause::kCollapseForecast, true);
  p.base.probability = 0.0;
  const AlarmOutput held = p.at(10, 0.0);
  EXPECT_EQ(held.level, AlarmLevel::kAlarm);
  EXPECT_EQ(held.latched_level, AlarmLevel::kAlarm);
}

// A probability of collapse that guesses the coming ground (the P-wave stage's, a regional
// alert's: `probability`, a member of AlarmInput) raises `warning`, never `alarm`, with its own
// cause; the risk and the forecast name the cause when they hold the level too.
void expect_warning_only_with_its_cause(decltype(AlarmInput::risk) AlarmInput::*probability,
                                        AlarmCause cause) {
  Policy p(immediate());
  const auto at = [&p, probability](std::int64_t ms, double risk, double value) {
    p.base.*probability = value;
    return p.at(ms, risk);
  };
  EXPECT_EQ(at(0, 0.0, 0.5999).level, AlarmLevel::kNormal);
  expect_change(at(1, 0.0, 0.6), AlarmLevel::kWarning, AlarmLevel::kNormal, cause, false);
  EXPECT_EQ(at(2, 0.0, 1.0).level, AlarmLevel::kWarning);  // never alarm
  EXPECT_EQ(at(3, 0.0, 0.3).level, AlarmLevel::kWarning);  // at off: still on
  EXPECT_EQ(at(4, 0.0, 0.2999).level, AlarmLevel::kNormal);
  // With the risk at warning too, the risk is the cause; the guess holds it once the risk falls.
  expect_change(at(5, 0.55, 0.9), AlarmLevel::kWarning, AlarmLevel::kNormal,
                AlarmCause::kRiskThreshold, false);
  expect_change(at(6, 0.85, 0.9), AlarmLevel::kAlarm, AlarmLevel::kWarning,
                AlarmCause::kRiskThreshold, false);
  expect_change(at(7, 0.0, 0.9), AlarmLevel::kWarning, AlarmLevel::kAlarm, cause, false);
  // With the forecast at warning (the statue's own forecast comes first), it is the cause.
  p.base.probability = 0.6;
  expect_change(at(8, 0.85, 0.9), AlarmLevel::kAlarm, AlarmLevel::kWarning,
                AlarmCause::kRiskThreshold, false);
  expect_change(at(9, 0.0, 0.9), AlarmLevel::kWarning, AlarmLevel::kAlarm,
                AlarmCause::kCollapseForecast, false);
  p.base.probability = 0.0;
  // An invalid probability is an internal fault, as an invalid risk is.
  EXPECT_EQ(at(10, 0.0, std::numeric_limits<double>::quiet_NaN()).input_problem,
            InputProblem::kRiskInvalid);
  EXPECT_EQ(at(11, 0.0, -0.1).input_problem, InputProblem::kRiskInvalid);
  EXPECT_EQ(at(12, 0.0, 1.5).input_problem, InputProblem::kRiskInvalid);
}

TEST(AlarmPolicy, ThePWaveRaisesTheWarningAloneWithItsOwnCause) {
  expect_warning_only_with_its_cause(&AlarmInput::pwave_probability, AlarmCause::kPWave);
}

TEST(AlarmPolicy, ARegionalAlertRaisesTheWarningAloneWithItsOwnCause) {
  expect_warning_only_with_its_cause(&AlarmInput::regional_probability,
                                     AlarmCause::kRegionalAlert);
}

// Both guesses holding the warning: the P wave, measured on site, is the cause.
TEST(AlarmPolicy, ThePWaveNamesTheCauseBeforeARegionalAlert) {
  Policy p(immediate());
  p.base.pwave_probability = 0.9;
  p.base.regional_probability = 0.9;
  expect_change(p.at(0, 0.0), AlarmLevel::kWarning, AlarmLevel::kNormal, AlarmCause::kPWave,
                false);
  expect_change(p.at(1, 0.85), AlarmLevel::kAlarm, AlarmLevel::kWarning,
                AlarmCause::kRiskThreshold, false);
  p.base.pwave_probability = 0.0;
  expect_change(p.at(2, 0.0), AlarmLevel::kWarning, AlarmLevel::kAlarm,
                AlarmCause::kRegionalAlert, false);
}

// A warning latched by either guess keeps its cause after the guess falls.
void expect_latched_with_its_cause(decltype(AlarmInput::risk) AlarmInput::*probability,
                                   AlarmCause cause) {
  Policy p(latching(true, true));
  p.base.*probability = 0.7;
  expect_change(p.at(0, 0.0), AlarmLevel::kWarning, AlarmLevel::kNormal, cause, true);
  p.base.*probability = 0.0;
  const AlarmOutput held = p.at(10, 0.0);
  EXPECT_EQ(held.level, AlarmLevel::kWarning);
  EXPECT_EQ(held.latched_level, AlarmLevel::kWarning);
  EXPECT_EQ(held.event_count, 0U);
}

TEST(AlarmPolicy, AWarningLatchedByThePWaveKeepsItsCause) {
  expect_latched_with_its_cause(&AlarmInput::pwave_probability, AlarmCause::kPWave);
}

TEST(AlarmPolicy, AWarningLatchedByARegionalAlertKeepsItsCause) {
  expect_latched_with_its_cause(&AlarmInput::regional_probability, AlarmCause::kRegionalAlert);
}

TEST(AlarmPolicy, AnUpdateFromThePastIsRefused) {
  Policy p(immediate());
  (void)p.at(100, 0.6);
  const AlarmOutput past = p.at(99, 0.0);
  EXPECT_EQ(past.input_problem, InputProblem::kTimeWentBack);
  EXPECT_EQ(past.level, AlarmLevel::kWarning);
  EXPECT_EQ(past.event_count, 0U);
  EXPECT_EQ(p.at(100, 0.0).level, AlarmLevel::kNormal);  // the same time is fine
}

// ---------------------------------------------------------------------------------------------
// Events and heartbeat

TEST(AlarmPolicy, EventSequenceIncrementsAndWraps) {
  Policy p(immediate());
  for (int i = 0; i < 300; ++i) {
    const AlarmOutput out = p.at(i, i % 2 == 0 ? 0.6 : 0.0);
    ASSERT_EQ(out.event_count, 1U) << i;
    EXPECT_EQ(out.events[0].sequence, static_cast<std::uint8_t>(i % 256)) << i;
  }
}

TEST(AlarmPolicy, AnAcknowledgementAndANewRiseGiveTwoEventsInOrder) {
  Policy p(latching(true, true));
  (void)p.at(0, 0.6);  // event 0: warning latched
  (void)p.at(10, 0.0);
  const AlarmOutput out = p.ack(20, 0.9, AlarmLevel::kWarning, 0);
  EXPECT_EQ(out.acknowledgement, AckOutcome::kReleased);
  ASSERT_EQ(out.event_count, 2U);
  expect_event(out, 0, AlarmLevel::kNormal, AlarmLevel::kWarning, AlarmCause::kAcknowledged, false);
  expect_event(out, 1, AlarmLevel::kAlarm, AlarmLevel::kNormal, AlarmCause::kRiskThreshold, true);
  EXPECT_EQ(out.events[0].sequence, 1);
  EXPECT_EQ(out.events[1].sequence, 2);
}

TEST(AlarmPolicy, HeartbeatIsDueEveryPeriodAndAtOnceAfterAnEvent) {
  AlarmPolicySettings s = immediate();
  s.heartbeat_period_s = 0.5;
  Policy p(s);
  EXPECT_TRUE(p.policy.heartbeat_due(0));  // nothing sent yet
  p.policy.heartbeat_sent(1000 * kMs);
  EXPECT_EQ(p.policy.next_heartbeat_ns(), 1500 * kMs);
  EXPECT_FALSE(p.policy.heartbeat_due(1500 * kMs - 1));
  EXPECT_TRUE(p.policy.heartbeat_due(1500 * kMs));
  (void)p.at(1200, 0.6);  // an event: the next status goes out now
  EXPECT_EQ(p.policy.next_heartbeat_ns(), 1200 * kMs);
  p.policy.heartbeat_sent(1200 * kMs);
  EXPECT_EQ(p.policy.next_heartbeat_ns(), 1700 * kMs);
  (void)p.at(1300, 0.6);  // no event: unchanged
  EXPECT_EQ(p.policy.next_heartbeat_ns(), 1700 * kMs);
}

TEST(AlarmPolicy, NamesReadBothWays) {
  EXPECT_STREQ(alarm_level_name(AlarmLevel::kWarning), "warning");
  EXPECT_STREQ(alarm_cause_name(AlarmCause::kOverturnDetected), "overturn_detected");
  EXPECT_STREQ(alarm_level_name(static_cast<AlarmLevel>(9)), "invalid");
  AlarmLevel level = AlarmLevel::kNormal;
  EXPECT_TRUE(kAlarmLevelNames.parse("fault", level));
  EXPECT_EQ(level, AlarmLevel::kFault);
  AlarmCause cause = AlarmCause::kNone;
  EXPECT_FALSE(kAlarmCauseNames.parse("overturned", cause));
  EXPECT_EQ(cause, AlarmCause::kNone);
  EXPECT_STREQ(ack_outcome_name(AckOutcome::kStale), "stale sequence");
  EXPECT_STREQ(input_problem_name(InputProblem::kTimeWentBack), "time went back");
}

// The risk levels: advisory, warning, alarm, lowest first, each at its own index (plinth-eval's
// per-level columns).
TEST(AlarmLevels, RiskLevelsAreTheRisksInOrder) {
  ASSERT_EQ(kRiskLevels.size(), 3U);
  EXPECT_STREQ(alarm_level_name(kRiskLevels[0]), "advisory");
  EXPECT_STREQ(alarm_level_name(kRiskLevels[2]), "alarm");
  for (std::size_t i = 0; i < kRiskLevels.size(); ++i) {
    EXPECT_EQ(risk_level_index(kRiskLevels[i]), i);
    if (i > 0) {
      EXPECT_GT(kRiskLevels[i], kRiskLevels[i - 1]);
    }
  }
}

}  // namespace
}  // namespace plinth::monitor

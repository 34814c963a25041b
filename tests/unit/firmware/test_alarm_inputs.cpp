// The alarm policy's input from the box's status (alarm_inputs.h): each cause from the part of
// the status it comes from, the faults in their order of precedence.
#include <gtest/gtest.h>

#include "plinth/firmware/alarm_inputs.h"

namespace plinth::firmware {
namespace {

using monitor::AlarmCause;
using monitor::HealthCause;
using monitor::HealthState;

// Estimating, calibrated, every sensor ok, one axis at rest.
BoxStatus healthy() {
  BoxStatus s;
  s.estimating = true;
  s.calibrated = true;
  s.sensor.state = HealthState::kOk;
  s.sensor.cause = HealthCause::kNone;
  return s;
}

TEST(AlarmInputs, AHealthyQuietBoxRaisesNothing) {
  const monitor::AlarmInput in = alarm_input(healthy(), MonitorConfig{}, false);
  EXPECT_FALSE(in.fault_active);
  EXPECT_FALSE(in.not_calibrated);
  EXPECT_FALSE(in.out_of_full_contact);
  EXPECT_FALSE(in.collapse_detected);
  EXPECT_EQ(in.risk, Real(0));
}

TEST(AlarmInputs, RiskProbabilityAndTimeAreTheStatussOwn) {
  BoxStatus s = healthy();
  s.time_ns = 123'456'789;
  s.risk = 0.625;
  s.probability = 0.25;
  const monitor::AlarmInput in = alarm_input(s, MonitorConfig{}, false);
  EXPECT_EQ(in.time_ns, 123'456'789);
  EXPECT_EQ(in.risk, Real(0.625));
  EXPECT_EQ(in.probability, Real(0.25));
}

// Motion and collapse of any modelled axis; an axis beyond axis_count is not modelled.
// The regional room's probability of collapse under its worst held alert (regional_alert.h).
TEST(AlarmInputs, TheRegionalProbabilityIsTheRegionalRooms) {
  BoxStatus s = healthy();
  EXPECT_EQ(alarm_input(s, MonitorConfig{}, false).regional_probability, Real(0));
  s.regional.held = 1;
  s.regional.probability = Real(0.75);
  EXPECT_EQ(alarm_input(s, MonitorConfig{}, false).regional_probability, Real(0.75));
}

TEST(AlarmInputs, MotionAndCollapseOfAnyModelledAxis) {
  BoxStatus s = healthy();
  s.axes[1].mode.phase = Phase::kOverturned;
  EXPECT_FALSE(alarm_input(s, MonitorConfig{}, false).collapse_detected);
  s.axis_count = 2;
  const monitor::AlarmInput two = alarm_input(s, MonitorConfig{}, false);
  EXPECT_TRUE(two.collapse_detected);
  EXPECT_TRUE(two.out_of_full_contact);
  s.axes[1].mode.phase = Phase::kSliding;
  const monitor::AlarmInput sliding = alarm_input(s, MonitorConfig{}, false);
  EXPECT_TRUE(sliding.out_of_full_contact);
  EXPECT_FALSE(sliding.collapse_detected);
}

// The primary's fault names its own cause and comes first; then a plate mismatch where it raises
// the fault, then the bus. Ground sensors that disagree are an input fault beside them (the risk
// follows the most dangerous healthy reading, still valid), before the statue sensor's.
TEST(AlarmInputs, FaultsInTheirOrder) {
  BoxStatus s = healthy();
  MonitorConfig config;
  EXPECT_EQ(alarm_input(s, config, true).fault_cause, AlarmCause::kBusError);
  EXPECT_TRUE(alarm_input(s, config, true).fault_active);
  s.plate_mismatch = true;
  EXPECT_FALSE(alarm_input(s, config, false).fault_active);  // a mismatch alone: degraded
  config.plate.raises_fault = true;
  EXPECT_EQ(alarm_input(s, config, true).fault_cause, AlarmCause::kSensorDisagreement);
  s.plate_mismatch = false;
  s.disagreement = true;
  s.input_fault = AlarmCause::kStatueSensorFault;
  EXPECT_FALSE(alarm_input(s, config, false).fault_active);
  EXPECT_EQ(alarm_input(s, config, false).input_fault, AlarmCause::kSensorDisagreement);
  EXPECT_EQ(alarm_input(s, config, true).fault_cause, AlarmCause::kBusError);
  s.disagreement = false;
  EXPECT_EQ(alarm_input(s, config, false).input_fault, AlarmCause::kStatueSensorFault);
  s.disagreement = true;
  s.sensor.state = HealthState::kFault;
  s.sensor.cause = HealthCause::kTimeout;
  const monitor::AlarmInput in = alarm_input(s, config, true);
  EXPECT_TRUE(in.fault_active);
  EXPECT_EQ(in.fault_cause, AlarmCause::kSensorTimeout);
  s.sensor.state = HealthState::kDegraded;  // a degraded primary is no fault
  s.disagreement = false;
  EXPECT_FALSE(alarm_input(s, config, false).fault_active);
}

// An estimate outside the model (a member lifted off, Phase::kLiftedOff: EnsembleRisk's
// outside_model) is a fault of any modelled axis while the estimators run, its cause after the
// others'; a lift-off is no collapse.
TEST(AlarmInputs, OutsideTheModelIsAFaultAfterTheOthers) {
  BoxStatus s = healthy();
  s.axes[1].outside_model = true;
  EXPECT_FALSE(alarm_input(s, MonitorConfig{}, false).fault_active);  // axis 2 not modelled
  s.axis_count = 2;
  const monitor::AlarmInput in = alarm_input(s, MonitorConfig{}, false);
  EXPECT_TRUE(in.fault_active);
  EXPECT_EQ(in.fault_cause, AlarmCause::kOutsideModel);
  s.axes[1].mode.phase = Phase::kLiftedOff;
  EXPECT_FALSE(alarm_input(s, MonitorConfig{}, false).collapse_detected);
  EXPECT_EQ(alarm_input(s, MonitorConfig{}, true).fault_cause, AlarmCause::kBusError);
  s.sensor.state = HealthState::kFault;
  s.sensor.cause = HealthCause::kTimeout;
  EXPECT_EQ(alarm_input(s, MonitorConfig{}, false).fault_cause, AlarmCause::kSensorTimeout);
  s = healthy();
  s.axes[0].outside_model = true;
  s.estimating = false;  // stale: the estimators start again from rest
  EXPECT_FALSE(alarm_input(s, MonitorConfig{}, false).fault_active);
}

TEST(AlarmInputs, NotCalibratedUntilTheEstimatorsRunOnATrustedStart) {
  BoxStatus s = healthy();
  s.calibrated = false;
  EXPECT_TRUE(alarm_input(s, MonitorConfig{}, false).not_calibrated);
  s.calibrated = true;
  s.estimating = false;
  EXPECT_TRUE(alarm_input(s, MonitorConfig{}, false).not_calibrated);
}

}  // namespace
}  // namespace plinth::firmware

#include "plinth/firmware/alarm_inputs.h"

namespace plinth::firmware {

monitor::AlarmInput alarm_input(const BoxStatus& status, const MonitorConfig& config,
                                bool bus_fault) {
  monitor::AlarmInput input;
  bool outside_model = false;
  input.time_ns = status.time_ns;
  input.risk = static_cast<Real>(status.risk);
  input.probability = static_cast<Real>(status.probability);
  if (const auto* regional = monitor::built_part<monitor::RegionalAlertStatus>(status.regional)) {
    input.regional_probability = regional->probability;
  }
  if (const auto* pwave = monitor::built_part<monitor::PWaveStatus>(status.pwave)) {
    input.pwave_probability = status.has_pwave ? pwave->probability : Real(0);
  }
  for (int i = 0; i < status.axis_count; ++i) {
    const AxisStatus& axis = status.axes[static_cast<std::size_t>(i)];
    const Mode& mode = axis.mode;
    input.out_of_full_contact = input.out_of_full_contact || mode.phase != Phase::kFullContact;
    input.collapse_detected = input.collapse_detected || mode.collapsed();
    outside_model = outside_model || (status.estimating && axis.outside_model);
  }
  const bool sensor_fault = status.sensor.state == monitor::HealthState::kFault;
  const bool disagreement = status.disagreement;
  const bool mismatch_fault = status.plate_mismatch && config.plate.raises_fault;
  input.fault_active = sensor_fault || mismatch_fault || bus_fault || outside_model;
  input.fault_cause = sensor_fault     ? monitor::to_alarm_cause(status.sensor.cause)
                      : mismatch_fault ? monitor::AlarmCause::kSensorDisagreement
                      : bus_fault      ? monitor::AlarmCause::kBusError
                                       : monitor::AlarmCause::kOutsideModel;
  // Ground sensors that disagree: the risk follows the most dangerous healthy reading, still
  // valid, so the trouble shows beside the level; then the statue sensor's.
  input.input_fault = disagreement ? monitor::AlarmCause::kSensorDisagreement : status.input_fault;
  input.not_calibrated = !status.estimating || !status.calibrated;
  return input;
}

}  // namespace plinth::firmware

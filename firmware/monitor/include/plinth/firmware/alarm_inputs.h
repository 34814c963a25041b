// What the alarm policy is told after each input: the box's status read as the policy's
// conditions (lib/monitor alarm_policy.h, docs/monitor.md: Alarm levels). Every cause the box
// can raise comes from here, but an operator's acknowledgement, which the monitor adds.
// Freestanding.
#pragma once

#include "plinth/firmware/box_status.h"
#include "plinth/firmware/config.h"
#include "plinth/monitor/alarm_policy.h"

namespace plinth::firmware {

// The alarm policy's input from `status` (after the axes and the sensors were updated):
//  - risk and probability: the worst axis's risk and forecast probability;
//  - regional probability: the statue's probability of collapse under the worst held regional
//    alert (regional_alert);
//  - out of full contact (phase_change), collapse (overturn_detected): any axis's nominal statue;
//  - fault, by the first that holds: the primary sensor's fault (its cause: sensor_timeout,
//    sensor_fault), with config.plate.raises_fault a plate mismatch (sensor_disagreement),
//    `bus_fault` (bus_error),
//    an estimate outside the model (outside_model: a member of an axis's ensemble lifted off,
//    while the estimators run: the box cannot vouch for what it no longer models);
//  - input fault (trouble beside the level, the risk still valid): a ground sensor that disagrees
//    with the primary (sensor_disagreement: the risk then follows the most dangerous healthy
//    reading), else status.input_fault, which the monitor sets while the statue sensor is
//    unusable or not corroborated (statue_sensor_fault, statue_unexplained; docs/safety.md);
//  - not calibrated: the estimators do not run, or run on an untrusted start (the start-up rule).
[[nodiscard]] monitor::AlarmInput alarm_input(const BoxStatus& status, const MonitorConfig& config,
                                              bool bus_fault);

}  // namespace plinth::firmware

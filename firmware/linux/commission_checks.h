// plinth-commission's procedure and checks (docs/commissioning.md): the steps a box file asks
// for, each step's windows (given by the prompts or options, or found in the data), and what
// each sensor read in them against what its box-file mounting says it must read. Host code:
// allocates.
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "commission_session.h"
#include "commission_settings.h"
#include "plinth/firmware/config.h"

namespace plinth::firmware {

// One accelerometer (a ground or plate sensor, or the statue sensor's, with its gyroscope) as
// the box file declares it.
struct CommissionedSensor {
  int index = -1;  // in the box file's sensor order (resolved_sensors); -1: the statue sensor
  std::uint8_t node = 1;
  bool statue = false;
  SensorRole role = SensorRole::kGround;
  std::string label;  // "node 2 (ground, sensor[1])", "statue sensor (node 4)"
  Eigen::Matrix3d to_statue = Eigen::Matrix3d::Identity();  // sensor_to_statue
  double unit_scale = 1.0;                                  // the declared unit to m/s2
  std::string unit_name = "g";                              // "g", "m/s2"
  double max_rest_std_m_s2 = 0.05;                          // its conditioning.startup_max_std_m_s2
};

// The box file's sensors, in its order, the statue sensor last.
[[nodiscard]] std::vector<CommissionedSensor> commissioned_sensors(const MonitorConfig& config);

enum class StepKind : std::uint8_t { kRest, kWedge, kStatueRaise, kFinalRest };

// One step of the procedure. Names: "rest", "tilt-x:N" and "tilt-y:N" (node N on the wedge, its
// +x or +y side raised), "statue-x" and "statue-y" (the statue's +x or +y side raised; with
// "-before" and "-after", the statue standing just before and after), "final-rest".
struct Step {
  std::string name;
  StepKind kind = StepKind::kRest;
  int sensor = -1;  // in commissioned_sensors (wedge, statue raise)
  int axis = 0;     // 0: +x raised, 1: +y raised
};

// The steps for these sensors: rest; each ground and plate sensor on the wedge, +x then +y; the
// statue raised on its +x side, and on its +y side with a second axis (axis_count 2); the final
// rest.
[[nodiscard]] std::vector<Step> plan_steps(const std::vector<CommissionedSensor>& sensors,
                                           int axis_count);

enum class WindowSource : std::uint8_t { kNone, kData, kOption, kPrompt };
[[nodiscard]] const char* window_source_name(WindowSource source);

struct Window {
  double t0 = 0.0;  // s from the session's first frame
  double t1 = 0.0;
  WindowSource source = WindowSource::kNone;
  [[nodiscard]] bool found() const { return source != WindowSource::kNone; }
};

// A step's windows: the hold (the rest itself for rests), and for a statue raise the statue
// standing before and after it.
struct StepWindows {
  Step step;
  Window hold;
  Window before;
  Window after;
};

// One check's verdict. `subject` names the sensor ("node 2 (ground, sensor[1])") or "bus".
struct CheckResult {
  std::string subject;
  std::string check;  // "heard", "rate", "gravity", "level", "tilt-x:2", "statue-x", ...
  bool passed = false;
  std::string measured;  // with units
  std::string expected;
  std::string message;  // what is wrong (a failure) or what was seen (a pass)
};

// A sensor's readings over the session, for the picture: the raise of its +x and +y sides
// (deg, statue frame, from its rest reading) by its accelerometer, and for the statue sensor by
// its gyroscope over each raise (NaN elsewhere).
struct SensorTrace {
  std::string label;
  int sensor = 0;  // in commissioned_sensors
  bool statue = false;
  std::vector<double> t;
  std::vector<double> raise_x_deg;
  std::vector<double> raise_y_deg;
  std::vector<double> gyro_t;
  std::vector<double> gyro_raise_x_deg;
  std::vector<double> gyro_raise_y_deg;
};

struct CommissionResult {
  bool passed = false;
  std::vector<CheckResult> checks;
  std::vector<StepWindows> windows;  // one per step, in plan order
  std::vector<SensorTrace> traces;   // one per sensor heard, in commissioned order
  std::vector<std::string> notes;    // what the custodian should know that is no failure
  // "subject: message" of each failed check, in order.
  [[nodiscard]] std::vector<std::string> failures() const;
};

// What a window of a step is called in options and prompts: "statue-x-before", ...
[[nodiscard]] std::string window_name(const Step& step, const char* part);

struct CommissionInput {
  const SessionRecording* session = nullptr;
  std::vector<CommissionedSensor> sensors;
  std::vector<Step> steps;
  CommissioningSettings settings;
  double sample_rate_hz = 200.0;  // estimator.sample_rate_hz: every node's rate
  // Windows given by name (window_name; a step's hold by the step's name): from the prompts of
  // a live session or --window; every other window is found in the data.
  std::map<std::string, Window> given;
};

// The whole check: the bus census, then each step's checks.
[[nodiscard]] CommissionResult commission(const CommissionInput& input);

// The checks of one step alone (a live session tells the custodian at once), against the rest
// window: the steps before it must have their windows in `input.given`.
[[nodiscard]] std::vector<CheckResult> check_step(const CommissionInput& input, const Step& step);

}  // namespace plinth::firmware

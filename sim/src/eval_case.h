// One plinth-eval run: a record at one scale under one true statue. The truth is the solver on
// the true statue; the box is firmware/monitor's Monitor, started with the scene file's
// ensemble (the nominal statue and the corners of its [uncertainty]), fed the same motion as
// an ideal ground sensor at the box's rate after a quiet lead-in, as plinth-monitor --replay
// feeds it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "eval_fault.h"
#include "plinth/core/forecast.h"
#include "plinth/core/scene.h"
#include "plinth/host/eval_metrics.h"
#include "plinth/host/pwave_records.h"
#include "plinth/host/record_io.h"
#include "plinth/host/regional_eval.h"
#include "plinth/host/scene_toml.h"
#include "plinth/monitor/alarm_policy.h"

namespace plinth::sim {

struct BoxSettings {
  double rate_hz = 200.0;          // the ground sensor's sample rate, Hz
  int steps_per_sample = 4;        // the estimator's solver steps per sample
  ForecastSettings forecast;       // forecast.enabled false: the reactive box alone
  Time raise_hold_s = monitor::AlarmPolicySettings{}.raise_hold_s;  // s, the policy's hold
  double startup_window_s = 2.0;   // s: the quiet lead-in that estimates the sensor's offset
  // A box given the true statue (one member, no uncertainty) instead of the scene file: what
  // knowing the statue exactly would buy, against the same truth (docs/forecast.md).
  bool knows_true_statue = false;
  // The on-site P-wave stage (docs/pwave.md) beside the box, fed the same samples; its
  // probability's first crossings of grids.pwave go to the runs file. The scene must give its
  // [fragility].
  bool pwave = false;
  // A statue sensor (firmware statue_sensor.h) simulated from the truth: its gyroscope and
  // accelerometer as StatueImuModel says, at the box's rate.
  bool statue_sensor = false;
  // Regional alerts simulated by this model (plinth-eval run --regional on; docs/regional.md,
  // "Evaluation"): one alert per run, its probability from the box's regional room with the
  // scene's [fragility]. Needs each case's source.
  std::optional<host::RegionalAlertModel> regional;
  // One fault injected into the box's inputs (plinth-eval run --fault; eval_fault.h).
  Fault fault;
};

// A MEMS IMU a museum would mount on a statue. Its gyroscope: a Bosch BMI088's typical figures as
// Bosch Sensortec's application engineer gives them (the data sheet's table not found; source in
// docs/forecast.md): rate noise density 0.014 deg/s/sqrt(Hz), zero-rate offset +-1 deg/s (each
// run draws one per axis, uniformly), and a delay of one 200 Hz sample (its output filter's
// group delay at 200 Hz ODR and the CAN frame's transit). Its accelerometer, at the same rate and
// delay: a noise density of 175 ug/sqrt(Hz) (the BMI088 accelerometer's as commonly quoted: an
// assumption, its data sheet's table not found) and a zero-g offset within +-50 mg per axis
// (Bosch's BMA280 in the CISS manual, +-50 mg; the BMI160's and BMA255's +-60 mg: the order of a
// consumer MEMS accelerometer's; docs/forecast.md), at the mount's default place, 1 m up on the
// block's axis.
struct StatueImuModel {
  double noise_density_deg_s_rthz = 0.014;  // deg/s/sqrt(Hz)
  double zero_rate_offset_deg_s = 1.0;      // deg/s, the offset's bound
  double delay_s = 0.005;                   // s, behind the ground sensor's sample
  double acceleration_noise_density_ug_rthz = 175.0;  // ug/sqrt(Hz)
  double zero_g_offset_mg = 50.0;                     // mg, the offset's bound
};

struct TruthSettings {
  double step_s = 5e-4;  // s, the solver's fixed step on the true statue
};

// The case's inputs, shared read-only between threads.
struct EvalCase {
  const host::Record* record = nullptr;
  std::string record_name;  // file name, for the runs file
  const host::UncertainScene* scene = nullptr;
  std::string scene_name;
  int statue = 0;
  std::uint32_t seed = 0;  // the statues' draw (plinth-eval run --seed): with the above, the case
  host::PgaGrid grid;      // the grid the case runs up
  const Scene* true_statue = nullptr;
  double scale_g = 0.0;  // the record's PGA in this run, g
  host::RecordPhases phases;  // the record's (the same at every scale)
  const host::RecordSource* source = nullptr;  // the record's earthquake (--record-info)
  // The fault statue_neighbour: the statue the sensor is on, drawn as the true statues are.
  const Scene* neighbour_statue = nullptr;
};

// Which runs the box runs on: all, or only those whose truth collapsed (plinth-eval run
// --collapses-only: a fault's silenced collapses and lost lead need no more).
enum class BoxRuns { kAll, kCollapses };

// The truth and the box's timeline for one case (times from the record's t = 0, s); nullopt
// when `runs` is kCollapses and the truth stood (the box not run). Throws InputError when the
// scaled record or the scene cannot be run (naming which).
[[nodiscard]] std::optional<host::EvalRun> run_case(const EvalCase& c, const BoxSettings& box,
                                                    const TruthSettings& truth,
                                                    const host::CrossingGrids& grids,
                                                    BoxRuns runs = BoxRuns::kAll);

}  // namespace plinth::sim

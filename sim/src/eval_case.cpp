#include "eval_case.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <string>

#include "plinth/core/excitation.h"
#include "plinth/core/simulator.h"
#include "plinth/core/statue_filter.h"
#include "plinth/firmware/monitor.h"
#include "plinth/firmware/record_replay.h"
#include "plinth/host/input_error.h"
#include "plinth/host/record_sampling.h"
#include "plinth/monitor/p_wave.h"

namespace plinth::sim {
namespace {

namespace fw = firmware;
using host::EvalRun;
using host::InputError;

// After the record ends the block may still rock to a collapse: the truth and the box run on
// this long with the ground at rest.
constexpr double kFreeRockingTailS = 3.0;

struct Truth {
  bool collapsed = false;
  double collapse_time_s = -1.0;
  double lift_off_s = -1.0;  // the statue lifted off then: the model, and the truth, end
  double peak_ratio = 0.0;  // max |theta| / alpha of the corner it rocks on
  double first_motion_s = -1.0;  // s: first out of full contact; -1: never
  double step_s = 0.0;
  std::vector<double> rotation_rate;  // theta' at each step's end, rad/s ([0]: t = 0)
  // With the statue sensor: the specific force its accelerometer reads at each step's end, in
  // the statue's x-z plane (simulated_specific_force), m/s2 ([0]: at rest, (0, g)).
  std::vector<double> specific_force_x;
  std::vector<double> specific_force_z;

  // theta' at time t (s from the record's start), linear between steps; 0 before the start,
  // the last one after the end.
  [[nodiscard]] double rate_at(double t) const { return at(rotation_rate, t, 0.0); }
  [[nodiscard]] Eigen::Vector2d specific_force_at(double t) const {
    return {at(specific_force_x, t, 0.0), at(specific_force_z, t, kStandardGravity)};
  }

 private:
  [[nodiscard]] double at(const std::vector<double>& steps, double t, double before) const {
    if (t <= 0.0 || steps.empty()) return before;
    const double x = t / step_s;
    const auto i = static_cast<std::size_t>(x);
    if (i + 1 >= steps.size()) return steps.back();
    const double w = x - static_cast<double>(i);
    return (1.0 - w) * steps[i] + w * steps[i + 1];
  }
};

Excitation scaled(const host::Record& record, double gamma) {
  return Excitation::record(record.horizontal_signal(),
                            record.vertical.empty() ? SampledSignal{} : record.vertical_signal(),
                            gamma);
}

// `mount`: where the statue sensor's accelerometer sits (nullptr: none to simulate).
Truth simulate_truth(const EvalCase& c, double gamma, const TruthSettings& settings,
                     const StatueAccelerometerMount* mount) {
  SolverSettings solver;
  solver.step = settings.step_s;
  Simulator sim;
  const Error e = Simulator::create(*c.true_statue, scaled(*c.record, gamma), solver, sim);
  if (!e.ok()) {
    throw InputError(c.scene_name + ", statue " + std::to_string(c.statue) + ": solver: " +
                     e.field + " " + e.reason);
  }
  sim.start_at_rest();
  const Scene& s = *c.true_statue;
  const double t_end = c.record->duration() + kFreeRockingTailS;
  Truth truth;
  truth.step_s = solver.step;
  truth.rotation_rate.push_back(0.0);
  if (mount != nullptr) {
    truth.specific_force_x.push_back(0.0);
    truth.specific_force_z.push_back(s.g);
  }
  while (sim.time() < t_end - 0.5 * solver.step && !sim.mode().terminal()) {
    sim.step();
    truth.rotation_rate.push_back(sim.state()[kThetaDot]);
    if (mount != nullptr) {
      const Vector2r f = simulated_specific_force(s, sim.mode(), sim.state(), sim.accelerations(),
                                                  sim.ground(sim.time()), *mount);
      truth.specific_force_x.push_back(f.x());
      truth.specific_force_z.push_back(f.y());
    }
    if (truth.first_motion_s < 0.0 && sim.mode().phase != Phase::kFullContact) {
      truth.first_motion_s = sim.time();
    }
    const double theta = sim.state()[kTheta];
    const double ratio = theta >= 0.0 ? theta / s.corner1.critical_angle
                                      : -theta / s.corner2.critical_angle;
    truth.peak_ratio = std::max(truth.peak_ratio, ratio);
  }
  if (sim.mode().phase == Phase::kLiftedOff) {
    truth.lift_off_s = sim.time();
  } else if (sim.mode().collapsed()) {
    truth.collapsed = true;
    truth.collapse_time_s = sim.time();
    truth.peak_ratio = std::max(truth.peak_ratio, 1.0);
  }
  return truth;
}

// The box's configuration: a record replay's (firmware/box record_replay.h), as plinth-monitor
// --replay sets it, with the evaluation's rate, steps, forecast and start-up window.
fw::MonitorConfig box_config(const BoxSettings& box) {
  fw::MonitorConfig config = fw::box_defaults();
  config.estimator.steps_per_sample = box.steps_per_sample;
  config.forecast = box.forecast;
  config.alarm.raise_hold_s = box.raise_hold_s;
  config.conditioning.startup_window_s = box.startup_window_s;
  fw::configure_record_replay(config, box.rate_hz);
  if (box.statue_sensor) fw::configure_replay_statue_sensor(config);
  return config;
}

// Where the box's configuration puts the statue sensor's accelerometer (axis 0's plane).
StatueAccelerometerMount statue_accelerometer_mount(const fw::MonitorConfig& config) {
  const auto* statue = monitor::built_part<fw::StatueSensorSettings>(config.statue_sensor);
  if (statue == nullptr) return {};
  return {statue->height_m, statue->offset_x_m};
}

// A run's own seed: the case's key (record, scene, statue, scale) hashed, so that a run draws the
// same in every shard.
std::uint64_t run_seed(const EvalCase& c) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  const std::string key = c.record_name + "|" + c.scene_name + "|" + std::to_string(c.statue) +
                          "|" + std::to_string(c.scale_g);
  for (const char ch : key) h = (h ^ static_cast<unsigned char>(ch)) * 1099511628211ULL;
  return h;
}

// The statue sensor's samples of one run: the truth's theta' and specific force through
// StatueImuModel's noise, offsets and delay, as an IMU whose axes are the statue's (theta'_0 =
// -omega_y, statue_sensor.h). Seeded by the case, so a run is the same in every shard; the
// accelerometer draws from a stream of its own (the gyroscope's draws are those of a run
// without it).
class StatueImu {
 public:
  StatueImu(const EvalCase& c, double rate_hz, const StatueImuModel& model)
      : model_(model),
        random_(run_seed(c)),
        acceleration_random_(run_seed(c) ^ kAccelerometerSalt) {
    const double to_rad = std::numbers::pi / 180.0;
    std::uniform_real_distribution<double> offset(-model.zero_rate_offset_deg_s,
                                                  model.zero_rate_offset_deg_s);
    for (double& o : offset_rad_s_) o = offset(random_) * to_rad;
    // White noise of the density over the output's band (half the rate).
    noise_rad_s_ = model.noise_density_deg_s_rthz * std::sqrt(rate_hz / 2.0) * to_rad;
    std::uniform_real_distribution<double> zero_g(-model.zero_g_offset_mg, model.zero_g_offset_mg);
    for (double& o : offset_g_) o = zero_g(acceleration_random_) * 1e-3;
    noise_g_ = model.acceleration_noise_density_ug_rthz * 1e-6 * std::sqrt(rate_hz / 2.0);
  }
  fw::StatueSample sample(const fw::MonitorConfig& config, std::int64_t n, double rate_rad_s) {
    fw::StatueSample s = fw::replay_statue_sample(config, n, static_cast<Real>(rate_rad_s), 0);
    for (int i = 0; i < 3; ++i) {
      s.rotation_rate_rad_s[i] += static_cast<Real>(offset_rad_s_[static_cast<std::size_t>(i)] +
                                                    noise_rad_s_ * gauss_(random_));
    }
    return s;
  }
  // The accelerometer's sample n (g, sensor frame = statue frame) of the specific force
  // `statue_m_s2` (the statue's x-z plane, m/s2).
  monitor::SensorSample acceleration(const fw::MonitorConfig& config, std::int64_t n,
                                     const Eigen::Vector2d& statue_m_s2) {
    monitor::SensorSample s = fw::record_replay_sample(config, n, Eigen::Vector3d::Zero(), 0);
    const Eigen::Vector3d g(statue_m_s2.x(), 0.0, statue_m_s2.y());
    for (int i = 0; i < 3; ++i) {
      s.acceleration_g[i] = static_cast<Real>(g[i] / kStandardGravity +
                                              offset_g_[static_cast<std::size_t>(i)] +
                                              noise_g_ * acceleration_gauss_(acceleration_random_));
    }
    return s;
  }
  [[nodiscard]] double delay_s() const { return model_.delay_s; }

 private:
  static constexpr std::uint64_t kAccelerometerSalt = 0xa5a5a5a55a5a5a5aULL;
  StatueImuModel model_;
  std::mt19937_64 random_;
  std::mt19937_64 acceleration_random_;
  std::normal_distribution<double> gauss_;
  std::normal_distribution<double> acceleration_gauss_;  // its own: a distribution keeps draws
  std::array<double, 3> offset_rad_s_{};
  std::array<double, 3> offset_g_{};
  double noise_rad_s_ = 0.0;
  double noise_g_ = 0.0;
};

// First time each threshold of `grid` was reached by `value`.
void note_crossings(const std::vector<double>& grid, double value, double t,
                    std::vector<double>& first) {
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (first[i] < 0.0 && value >= grid[i]) first[i] = t;
  }
}

void note_level(monitor::AlarmLevel shown, double t,
                std::array<double, monitor::kRiskLevels.size()>& first) {
  if (shown == monitor::AlarmLevel::kFault) return;
  for (const monitor::AlarmLevel level : monitor::kRiskLevels) {
    double& first_shown = first[monitor::risk_level_index(level)];
    if (shown >= level && first_shown < 0.0) first_shown = t;
  }
}

// The P-wave stage the box would run, with the scene's fragility (docs/pwave.md).
monitor::PWaveStage pwave_stage(const EvalCase& c, double rate_hz) {
  if (!c.scene->fragility) {
    throw InputError(c.scene_name + ": --pwave on needs the scene's [fragility] table (median_g, "
                     "beta: plinth-eval fragility fits them; docs/scene-format.md)");
  }
  monitor::PWaveSettings s;
  s.sample_period_s = 1.0 / rate_hz;
  s.fragility_known = true;
  s.fragility = *c.scene->fragility;
  monitor::PWaveStage stage;
  const Error e = monitor::PWaveStage::create(s, stage);
  if (!e.ok()) throw InputError(c.scene_name + ": the P-wave stage: " + e.field + " " + e.reason);
  return stage;
}

// The box on the case's motion; stops at the true collapse (what comes after cannot make a hit)
// or the true statue's lift-off (nothing after it is known), else at the end of the record and
// its tail.
// `config`: box_config(box).
void run_box(const EvalCase& c, double gamma, const BoxSettings& box,
             const fw::MonitorConfig& config, const host::CrossingGrids& grids,
             const Truth& truth, EvalRun& run) {
  const double stop_s = truth.collapsed ? truth.collapse_time_s : truth.lift_off_s;
  auto monitor = std::make_unique<fw::Monitor>();  // an ensemble is too big for the stack
  const std::span<const Scene> members = box.knows_true_statue
                                             ? std::span<const Scene>(c.true_statue, 1)
                                             : std::span<const Scene>(c.scene->members);
  const Error e = monitor->start(config, {members, {}});
  if (!e.ok()) {
    throw InputError(c.scene_name + ": the box refuses it: " + e.field + " " + e.reason);
  }
  const double rate = box.rate_hz;
  const std::size_t count = host::sample_count(c.record->duration() + kFreeRockingTailS, rate);
  const std::vector<double> h = host::resample(c.record->horizontal_signal(), rate, count);
  const std::vector<double> v = c.record->vertical.empty()
                                    ? std::vector<double>()
                                    : host::resample(c.record->vertical_signal(), rate, count);
  const auto lead_in = static_cast<std::size_t>(fw::record_replay_lead_in(config));
  run.risk_crossing_s.assign(grids.risk.size(), -1.0);
  run.probability_crossing_s.assign(grids.probability.size(), -1.0);
  run.nominal_risk_crossing_s.assign(grids.risk.size(), -1.0);
  std::optional<StatueImu> imu;
  if (box.statue_sensor) imu.emplace(c, rate, StatueImuModel{});
  std::optional<monitor::PWaveStage> stage;
  if (box.pwave) {
    stage = pwave_stage(c, rate);
    run.pwave_crossing_s.assign(grids.pwave.size(), -1.0);
    run.p_pick_s = c.phases.p_pick_s;
    run.strong_motion_s = c.phases.strong_motion_s;
  }
  const double lead_in_s = static_cast<double>(lead_in) / rate;
  for (std::size_t n = 0; n < lead_in + count; ++n) {
    const std::size_t k = n < lead_in ? 0 : n - lead_in;
    const Eigen::Vector3d ground(gamma * h[k], 0.0,
                                 kStandardGravity + (v.empty() ? 0.0 : gamma * v[k]));
    const monitor::SensorSample s =
        fw::record_replay_sample(config, static_cast<std::int64_t>(n), ground, kStandardGravity);
    const double t = static_cast<double>(k) / rate;
    if (imu) {
      const double then = n < lead_in ? 0.0 : t - imu->delay_s();
      const auto i = static_cast<std::int64_t>(n);
      (void)monitor->on_statue_sample(imu->sample(config, i, truth.rate_at(then)));
      (void)monitor->on_statue_acceleration(
          imu->acceleration(config, i, truth.specific_force_at(then)));
    }
    const fw::MonitorUpdate update = monitor->on_sample(s);
    if (stage) {
      // What the box's conditioning gives it: the replay's lead-in is at rest (0 g horizontal,
      // 1 g vertical: record_replay_sample), its offset taken away, then the record as it is
      // (a record that starts away from 0 steps there, for the box as for the truth).
      const Vector3r conditioned = n < lead_in ? Vector3r::Zero()
                                               : Vector3r(gamma * h[k], 0.0,
                                                          v.empty() ? 0.0 : gamma * v[k]);
      const monitor::PWaveStatus& p = stage->update(conditioned);
      if (p.triggers > 0 && run.pwave_trigger_s < 0.0 && n >= lead_in) {
        run.pwave_trigger_s = std::max(0.0, p.onset_s - lead_in_s);
      }
      if (n >= lead_in) {
        note_crossings(grids.pwave, p.probability, static_cast<double>(k) / rate,
                       run.pwave_crossing_s);
      }
    }
    if (n < lead_in) continue;
    if (stop_s >= 0.0 && t >= stop_s) break;
    const fw::BoxStatus& status = *update.status;
    note_level(status.alarm, t, run.first_shown_s);
    if (!status.estimating) continue;
    note_crossings(grids.risk, status.risk, t, run.risk_crossing_s);
    note_crossings(grids.probability, status.probability, t, run.probability_crossing_s);
    note_crossings(grids.risk, status.axes[0].nominal_risk.total, t, run.nominal_risk_crossing_s);
  }
}

// The run's simulated regional alert (regional_eval.h), beside the box: it changes nothing of
// the box's run; the report takes the earlier of the box's warning and the alert's.
EvalRun::Regional regional_alert(const EvalCase& c, const host::RegionalAlertModel& model) {
  if (!c.scene->fragility) {
    throw InputError(c.scene_name + ": --regional on needs the scene's [fragility] table "
                     "(median_g, beta: plinth-eval fragility fits them; docs/scene-format.md)");
  }
  if (c.source == nullptr) throw InputError(c.record_name + ": --regional on needs its source");
  constexpr std::uint64_t kRegionalSalt = 0x9e3779b97f4a7c15ULL;  // not the gyroscope's draws
  const host::SimulatedRegionalAlert a = host::simulate_regional_alert(
      model, *c.source, c.phases, c.scale_g, *c.scene->fragility, run_seed(c) ^ kRegionalSalt);
  return {c.source->magnitude, c.source->rhyp_km, a.origin_s,  a.alert_s,
          a.s_arrival_s,       a.pga_g,           a.sigma_ln, a.probability};
}

}  // namespace

EvalRun run_case(const EvalCase& c, const BoxSettings& box, const TruthSettings& truth_settings,
                 const host::CrossingGrids& grids) {
  const double peak = c.record->peak_horizontal();
  if (!(peak > 0.0)) throw InputError(c.record_name + ": the record is all zeros");
  const double gamma = c.scale_g * kStandardGravity / peak;
  EvalRun run;
  run.record = c.record_name;
  run.scene = c.scene_name;
  run.statue = c.statue;
  run.seed = c.seed;
  run.grid = c.grid;
  run.scale_g = c.scale_g;
  const fw::MonitorConfig config = box_config(box);
  const StatueAccelerometerMount mount = statue_accelerometer_mount(config);
  const Truth truth =
      simulate_truth(c, gamma, truth_settings, box.statue_sensor ? &mount : nullptr);
  run.collapsed = truth.collapsed;
  run.collapse_time_s = truth.collapse_time_s;
  run.peak_ratio = truth.peak_ratio;
  run.model_valid_until_s = truth.lift_off_s;
  run.first_motion_s = truth.first_motion_s;
  run_box(c, gamma, box, config, grids, truth, run);
  if (box.regional) run.regional = regional_alert(c, *box.regional);
  return run;
}

}  // namespace plinth::sim

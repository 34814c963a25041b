#include "eval_case.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <utility>

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
  // For the fault statue_on_plinth: the base's specific force at each step's end (the plinth's
  // absolute acceleration u'' + u_G'' and the ground's vertical one, gravity added), m/s2.
  std::vector<double> base_force_x;
  std::vector<double> base_force_z;
  // Where a collapsed or lifted-off statue rests after the model ended (read by the fault
  // statue_neighbour: the neighbour's sensor goes on): lying on its side (theta = +-90 degrees)
  // after a collapse, at its last tilt after a lift-off.
  double ended_s = -1.0;  // -1: the model held to the end
  Eigen::Vector2d resting_force{0.0, kStandardGravity};

  // theta' at time t (s from the record's start), linear between steps; 0 before the start,
  // the last one after the end, 0 after a collapse or a lift-off.
  [[nodiscard]] double rate_at(double t) const {
    return after_end(t) ? 0.0 : at(rotation_rate, t, 0.0);
  }
  [[nodiscard]] Eigen::Vector2d specific_force_at(double t) const {
    if (after_end(t)) return resting_force;
    return {at(specific_force_x, t, 0.0), at(specific_force_z, t, kStandardGravity)};
  }
  [[nodiscard]] Eigen::Vector2d base_force_at(double t) const {
    return {at(base_force_x, t, 0.0), at(base_force_z, t, kStandardGravity)};
  }

 private:
  [[nodiscard]] bool after_end(double t) const { return ended_s >= 0.0 && t > ended_s; }
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

// The solver on `statue` (the case's true statue, or the statue_neighbour fault's). `mount`:
// where the statue sensor's accelerometer sits (nullptr: none to simulate); `base_force`: also
// the base's specific force (statue_on_plinth).
Truth simulate_truth(const EvalCase& c, const Scene& statue, double gamma,
                     const TruthSettings& settings, const StatueAccelerometerMount* mount,
                     bool base_force = false) {
  SolverSettings solver;
  solver.step = settings.step_s;
  Simulator sim;
  const Error e = Simulator::create(statue, scaled(*c.record, gamma), solver, sim);
  if (!e.ok()) {
    throw InputError(c.scene_name + ", statue " + std::to_string(c.statue) + ": solver: " +
                     e.field + " " + e.reason);
  }
  sim.start_at_rest();
  const Scene& s = statue;
  const double t_end = c.record->duration() + kFreeRockingTailS;
  Truth truth;
  truth.step_s = solver.step;
  truth.rotation_rate.push_back(0.0);
  if (mount != nullptr) {
    truth.specific_force_x.push_back(0.0);
    truth.specific_force_z.push_back(s.g);
  }
  if (base_force) {
    truth.base_force_x.push_back(0.0);
    truth.base_force_z.push_back(s.g);
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
    if (base_force) {
      const GroundAcceleration ground = sim.ground(sim.time());
      truth.base_force_x.push_back(sim.accelerations().u + ground.horizontal);
      truth.base_force_z.push_back(ground.vertical + s.g);
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
  if (sim.mode().terminal()) {
    // At rest where it ended, tilted by theta: f = R(-theta) (0, g) = g (sin theta, cos theta).
    const double theta = sim.mode().collapsed()
                             ? std::copysign(std::numbers::pi / 2.0, sim.state()[kTheta])
                             : sim.state()[kTheta];
    truth.ended_s = sim.time();
    truth.resting_force = s.g * Eigen::Vector2d(std::sin(theta), std::cos(theta));
  }
  return truth;
}

// The second ground sensor's node (the replay's ground sensor is node 1, its statue sensor 2).
constexpr std::uint8_t kSecondGroundNode = 3;

[[nodiscard]] bool two_ground_sensors(FaultKind kind) {
  return kind == FaultKind::kGroundPairPrimary || kind == FaultKind::kGroundPairSecond;
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
  if (two_ground_sensors(box.fault.kind)) {
    // The replay's ideal sensor twice, in the sensor list: the first (preferred) is the primary.
    config.sensor_count = 2;
    for (std::size_t i = 0; i < 2; ++i) {
      config.sensors[i] = {i == 0 ? config.ground_node : kSecondGroundNode,
                           fw::SensorRole::kGround, config.conditioning, config.sensor_health};
    }
  }
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

// The box's trouble at t (`status`), `input` the fault's while it is on: when the statue sensor's
// troubles and the faulted input's were first raised, and what shows now (the run's end, when
// it is the last). The statue sensor's are raised when the box refuses it (input_fault), but not
// on the estimators' first sample after a start (`starting`), which the filters have not yet
// measured: there the box refuses it at every start, and shows it for lower_hold_s
// (docs/safety.md, "Fault injection"). The other inputs' trouble is raised when shown.
void note_trouble(const fw::BoxStatus& status, double t, bool starting, FaultedInput input,
                  EvalRun::Faults& faults) {
  using monitor::AlarmCause;
  const auto first = [&](bool raised, double& first_s) {
    if (raised && first_s < 0.0) first_s = t;
  };
  const AlarmCause refused = starting ? AlarmCause::kNone : status.input_fault;
  first(refused == AlarmCause::kStatueSensorFault, faults.first_statue_fault_s);
  first(refused == AlarmCause::kStatueUnexplained, faults.first_statue_unexplained_s);
  const bool shown = names_faulted_input(input, status.trouble);
  const bool raised =
      input == FaultedInput::kStatueSensor ? shown && names_faulted_input(input, refused) : shown;
  first(raised, faults.first_trouble_s);
  faults.trouble_at_end = shown && faults.first_trouble_s >= 0.0;
  faults.trouble_at_end_cause = status.trouble;
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

// When the run's fault begins, s from the record's t = 0 (FaultOnset): known from the start but
// for the alarm's anchor, which the box's first alarm sets; never when its anchor never comes.
class FaultClock {
 public:
  FaultClock(const Fault& fault, const EvalCase& c, const Truth& truth)
      : alarm_offset_s_(fault.onset.offset_s) {
    if (!fault.any()) return;
    const double offset = fault.onset.offset_s;
    switch (fault.onset.anchor) {
      case FaultAnchor::kBoxStart: onset_s_ = -kNever; break;
      case FaultAnchor::kRecord: onset_s_ = offset; break;
      case FaultAnchor::kStrongMotion: onset_s_ = c.phases.strong_motion_s + offset; break;
      case FaultAnchor::kMotion:
        if (truth.first_motion_s >= 0.0) onset_s_ = truth.first_motion_s + offset;
        break;
      case FaultAnchor::kAlarm: waits_for_alarm_ = true; break;
    }
  }
  // The box showed `alarm` first at t.
  void alarm_shown(double t) {
    if (waits_for_alarm_ && onset_s_ == kNever) onset_s_ = t + alarm_offset_s_;
  }
  // The fault is on at t_box (s from the record's t = 0, negative in the lead-in).
  [[nodiscard]] bool on(double t_box) const { return t_box >= onset_s_; }

 private:
  static constexpr double kNever = std::numeric_limits<double>::infinity();
  double alarm_offset_s_ = 0.0;
  bool waits_for_alarm_ = false;
  double onset_s_ = kNever;
};

// The statue sensor's two samples of one input.
struct StatueReadings {
  fw::StatueSample rate;
  monitor::SensorSample acceleration;
};

// The statue sensor of a run as the fault leaves it: what it senses (the true statue; at rest,
// the plinth or the neighbour while the fault is on, a delay more, or frozen at the onset)
// through StatueImu's offsets and noise (drawn for every input, sent or not, so that a fault
// changes nothing else of the run), then its reading changed (gain, bias, axes, sign) or not
// sent (a drop-out).
class FaultyStatueSensor {
 public:
  FaultyStatueSensor(const EvalCase& c, double rate_hz, const Fault& fault, const Truth& truth,
                     const Truth* neighbour)
      : imu_(c, rate_hz, StatueImuModel{}), fault_(fault), truth_(truth), neighbour_(neighbour) {}

  // Input n at `t` (s from the record's t = 0; 0 in the lead-in, `lead_in`), the fault `on`
  // since `began_s`; nullopt: nothing sent.
  std::optional<StatueReadings> read(const fw::MonitorConfig& config, std::int64_t n, double t,
                                     bool lead_in, bool on, double began_s) {
    const FaultKind kind = on ? fault_.kind : FaultKind::kNone;
    const double delay = imu_.delay_s() + (kind == FaultKind::kStatueDelay ? fault_.value : 0.0);
    Sensed sensed = sense(lead_in ? 0.0 : t - delay, kind);
    if (kind == FaultKind::kStatueStuck) {
      if (!frozen_) frozen_ = sensed;
      sensed = *frozen_;
    }
    StatueReadings r{imu_.sample(config, n, sensed.rate_rad_s),
                     imu_.acceleration(config, n, sensed.force_m_s2)};
    Vector3r& w = r.rate.rotation_rate_rad_s;
    Vector3r& a = r.acceleration.acceleration_g;
    switch (kind) {
      case FaultKind::kStatueGain: w *= static_cast<Real>(fault_.value); break;
      case FaultKind::kStatueBias: w += Vector3r::Constant(static_cast<Real>(fault_.value)); break;
      case FaultKind::kStatueAxesSwapped:
        std::swap(w.x(), w.y());
        std::swap(a.x(), a.y());
        break;
      case FaultKind::kStatueSign:
        w[fault_.axis] = -w[fault_.axis];
        a[fault_.axis] = -a[fault_.axis];
        break;
      case FaultKind::kStatueDropout:
        if (t < began_s + fault_.value) return std::nullopt;
        break;
      default: break;
    }
    return r;
  }

 private:
  // What the sensor senses: theta' (rad/s) and the specific force in the statue's x-z plane.
  struct Sensed {
    double rate_rad_s = 0.0;
    Eigen::Vector2d force_m_s2;
  };
  [[nodiscard]] Sensed sense(double then, FaultKind kind) const {
    switch (kind) {
      case FaultKind::kStatueAtRest: return {0.0, truth_.specific_force_at(0.0)};
      case FaultKind::kStatueOnPlinth: return {0.0, truth_.base_force_at(then)};
      case FaultKind::kStatueNeighbour:
        return {neighbour_->rate_at(then), neighbour_->specific_force_at(then)};
      default: return {truth_.rate_at(then), truth_.specific_force_at(then)};
    }
  }

  StatueImu imu_;
  const Fault& fault_;
  const Truth& truth_;
  const Truth* neighbour_;
  std::optional<Sensed> frozen_;  // statue_stuck: what it sensed at the onset
};

// The box started with the case's members, and a restarted one's memory restored.
std::unique_ptr<fw::Monitor> start_box(const EvalCase& c, const fw::MonitorConfig& config,
                                       std::span<const Scene> members,
                                       const fw::BoxMemory* memory = nullptr) {
  auto monitor = std::make_unique<fw::Monitor>();  // an ensemble is too big for the stack
  const Error e = monitor->start(config, {members, {}});
  if (!e.ok()) {
    throw InputError(c.scene_name + ": the box refuses it: " + e.field + " " + e.reason);
  }
  if (memory != nullptr) monitor->restore(*memory);
  return monitor;
}

// The box on the case's motion; stops at the true collapse (what comes after cannot make a hit)
// or the true statue's lift-off (nothing after it is known), else at the end of the record and
// its tail. The fault (box.fault) goes in through the box's inputs: the samples' values, the
// samples sent, a restart with the box's memory (eval_fault.h).
// `config`: box_config(box); `neighbour`: the statue_neighbour fault's truth.
void run_box(const EvalCase& c, double gamma, const BoxSettings& box,
             const fw::MonitorConfig& config, const host::CrossingGrids& grids,
             const Truth& truth, const Truth* neighbour, EvalRun& run) {
  const double stop_s = truth.collapsed ? truth.collapse_time_s : truth.lift_off_s;
  const std::span<const Scene> members = box.knows_true_statue
                                             ? std::span<const Scene>(c.true_statue, 1)
                                             : std::span<const Scene>(c.scene->members);
  std::unique_ptr<fw::Monitor> monitor = start_box(c, config, members);
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
  const Fault& fault = box.fault;
  std::optional<FaultyStatueSensor> statue_sensor;
  if (box.statue_sensor) statue_sensor.emplace(c, rate, fault, truth, neighbour);
  std::optional<monitor::PWaveStage> stage;
  if (box.pwave) {
    stage = pwave_stage(c, rate);
    run.pwave_crossing_s.assign(grids.pwave.size(), -1.0);
    run.p_pick_s = c.phases.p_pick_s;
    run.strong_motion_s = c.phases.strong_motion_s;
  }
  EvalRun::Faults& faults = run.faults.emplace();
  if (fault.any()) {
    faults.fault = kFaultKindNames.name(fault.kind);
    faults.param = fault.param;
    faults.at = fault.onset.text;
  }
  FaultClock clock(fault, c, truth);
  const bool ground_fault =
      fault.input() == FaultedInput::kGroundSensor && !two_ground_sensors(fault.kind);
  std::uint8_t latest_event = 0;  // the sequence of the latest alarm event (an acknowledgement's)
  const auto take = [&](const fw::MonitorUpdate& update) {
    if (update.event_count > 0) latest_event = update.events[update.event_count - 1].sequence;
  };
  double down_until_s = -std::numeric_limits<double>::infinity();  // restart: the box is off
  std::uint64_t restarts_seen = 0;  // the box's estimator_restarts at the previous sample
  const double lead_in_s = static_cast<double>(lead_in) / rate;
  for (std::size_t n = 0; n < lead_in + count; ++n) {
    const std::size_t k = n < lead_in ? 0 : n - lead_in;
    const double t = static_cast<double>(k) / rate;
    const double t_box = static_cast<double>(n) / rate - lead_in_s;
    const bool on = clock.on(t_box);
    if (on && !faults.began_s) {
      faults.began_s = t_box;
      if (happens_at_an_instant(fault.kind)) {
        // plinth-monitor's reset (acknowledged first: anyone on the network may press both) or a
        // restart after a crash: a new box with the memory the old one kept; a reset is refused
        // while an alarm stays latched.
        const fw::BoxStatus& before = monitor->status();
        if (fault.kind == FaultKind::kReset && before.latched != monitor::AlarmLevel::kNormal) {
          take(monitor->acknowledge({before.latched, latest_event}));
        }
        if (fault.kind == FaultKind::kRestart ||
            monitor->status().latched != monitor::AlarmLevel::kAlarm) {
          const fw::BoxMemory memory = monitor->memory();
          monitor = start_box(c, config, members, &memory);
          down_until_s = t_box + fault.value;
          restarts_seen = 0;
        }
      }
    }
    const bool down = t_box < down_until_s;
    const Eigen::Vector3d ground(gamma * h[k], 0.0,
                                 kStandardGravity + (v.empty() ? 0.0 : gamma * v[k]));
    monitor::SensorSample s =
        fw::record_replay_sample(config, static_cast<std::int64_t>(n), ground, kStandardGravity);
    monitor::SensorSample second = s;
    if (on && (ground_fault || two_ground_sensors(fault.kind))) {
      monitor::SensorSample& wrong = fault.kind == FaultKind::kGroundPairSecond ? second : s;
      wrong.acceleration_g = fault.ground.read(wrong.acceleration_g.cast<double>()).cast<Real>();
    }
    if (statue_sensor) {
      const std::optional<StatueReadings> r = statue_sensor->read(
          config, static_cast<std::int64_t>(n), t, n < lead_in, on, faults.began_s.value_or(0.0));
      if (r && !down) {
        take(monitor->on_statue_sample(r->rate));
        take(monitor->on_statue_acceleration(r->acceleration));
      }
    }
    if (!down) {
      take(monitor->on_sample(s));
      if (two_ground_sensors(fault.kind)) take(monitor->on_sensor_sample(1, second));
    }
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
    if (down) {
      faults.level_at_end = host::kBoxDown;
      faults.trouble_at_end_cause = monitor::AlarmCause::kNone;
      faults.trouble_at_end = false;
      continue;
    }
    const fw::BoxStatus& status = monitor->status();
    note_level(status.alarm, t, run.first_shown_s);
    faults.level_at_end = monitor::alarm_level_name(status.alarm);
    const double alarm_s =
        run.first_shown_s[monitor::risk_level_index(monitor::AlarmLevel::kAlarm)];
    if (alarm_s >= 0.0) clock.alarm_shown(alarm_s);
    const bool starting = status.estimator_restarts != restarts_seen;
    restarts_seen = status.estimator_restarts;
    note_trouble(status, t, starting, on ? fault.input() : FaultedInput::kNone, faults);
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

std::optional<EvalRun> run_case(const EvalCase& c, const BoxSettings& box,
                                const TruthSettings& truth_settings,
                                const host::CrossingGrids& grids, BoxRuns runs) {
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
  const Truth truth = simulate_truth(c, *c.true_statue, gamma, truth_settings,
                                     box.statue_sensor ? &mount : nullptr,
                                     box.fault.kind == FaultKind::kStatueOnPlinth);
  run.collapsed = truth.collapsed;
  run.collapse_time_s = truth.collapse_time_s;
  run.peak_ratio = truth.peak_ratio;
  run.model_valid_until_s = truth.lift_off_s;
  run.first_motion_s = truth.first_motion_s;
  if (runs == BoxRuns::kCollapses && !truth.collapsed) return std::nullopt;
  std::optional<Truth> neighbour;
  if (box.fault.kind == FaultKind::kStatueNeighbour) {
    if (c.neighbour_statue == nullptr) throw InputError("statue_neighbour: no neighbour drawn");
    neighbour = simulate_truth(c, *c.neighbour_statue, gamma, truth_settings, &mount);
  }
  run_box(c, gamma, box, config, grids, truth, neighbour ? &*neighbour : nullptr, run);
  run.faults->collapses_only = runs == BoxRuns::kCollapses;
  if (box.regional) run.regional = regional_alert(c, *box.regional);
  return run;
}

}  // namespace plinth::sim

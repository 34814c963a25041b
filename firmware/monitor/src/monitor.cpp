#include "plinth/firmware/monitor.h"

#include <cmath>

#include "plinth/firmware/alarm_inputs.h"
#include "plinth/firmware/can_frames.h"

namespace plinth::firmware {

// The CAN protocol (hal/can_codec).
namespace can = hal::can;

namespace {

// How far a phase is from standing: full contact, moving (sliding, rocking), lifted off,
// collapsed. The statue sensor uncorroborated may show a phase only further than the box's own.
int phase_severity(const Mode& mode) {
  if (mode.collapsed()) return 3;
  if (mode.phase == Phase::kLiftedOff) return 2;
  return mode.phase == Phase::kFullContact ? 0 : 1;
}

// The first collapse forecast among the members in `counted` (bit m: member m), s from the
// forecast's start; -1: none of them collapses.
double first_counted_collapse(const ForecastOutcome& f, std::uint32_t counted, int& member) {
  double first = -1.0;
  member = -1;
  for (int m = 0; m < f.members && m < kMaxEnsembleMembers; ++m) {
    const std::uint32_t bit = std::uint32_t{1} << static_cast<unsigned>(m);
    if ((f.collapsing_members & counted & bit) == 0U) continue;
    const double at = static_cast<double>(f.member_collapse_in_s[static_cast<std::size_t>(m)]);
    if (member < 0 || at < first) {
      first = at;
      member = m;
    }
  }
  return first;
}

// s beyond the statue sensor's offset window that its offset may take before its absence is
// trouble (a window restarts whenever the statue or the sensor moves).
constexpr double kStatueOffsetGraceS = 10.0;

// The smallest probability a CollapseForecast frame carries above 0 (its resolution, 1e-4):
// below half of it the frame says 0, and so does the status.
constexpr double kSmallestShownProbability = 0.5e-4;

}  // namespace

Error Monitor::start(const MonitorConfig& config,
                     const std::array<const Scene*, kMaxAxes>& scenes) {
  std::array<std::span<const Scene>, kMaxAxes> ensembles{};
  for (std::size_t i = 0; i < kMaxAxes; ++i) {
    if (scenes[i] != nullptr) ensembles[i] = std::span<const Scene>(scenes[i], 1);
  }
  return start(config, ensembles);
}

Error Monitor::start(const MonitorConfig& config,
                     const std::array<std::span<const Scene>, kMaxAxes>& ensembles) {
  PLINTH_TRY(validate(config));
  for (int i = 0; i < config.axis_count; ++i) {
    const std::span<const Scene> members = ensembles[static_cast<std::size_t>(i)];
    if (members.empty()) {
      return {ErrorCode::kInconsistent, "monitor.axis_count", "names an axis without a scene"};
    }
    PLINTH_TRY(ensembles_[static_cast<std::size_t>(i)].start(members, config.estimator,
                                                             config.forecast, config.risk));
    for (OtherReading& other : others_) {
      PLINTH_TRY(other.ensembles[static_cast<std::size_t>(i)].start(
          members, config.estimator, config.forecast, config.risk));
    }
  }
  for (OtherReading& other : others_) {
    other.running = false;
    other.seen = 0;
  }
  config_ = config;
  config_.conditioning.sample_period_s = config.estimator.sample_period();
  config_.sensor_health.sample_period_s = config.estimator.sample_period();
  status_ = BoxStatus{};
  status_.axis_count = config.axis_count;
  PLINTH_TRY(sensors_.start(config_, status_));
  PLINTH_TRY(monitor::AlarmPolicy::create(config_.alarm, alarm_));
  // The regional alerts' room, its settings and its status: all or none (kRegionalAlertBuiltIn).
  auto* regional_state = monitor::built_part<monitor::RegionalAlertState>(regional_);
  if (const auto* regional = monitor::built_part<monitor::RegionalAlertSettings>(config_.regional);
      regional_state != nullptr && regional != nullptr) {
    PLINTH_TRY(monitor::RegionalAlertState::create(*regional, *regional_state));
  }
  if (monitor::PWaveSettings* pwave = monitor::built_part<monitor::PWaveSettings>(config_.pwave);
      pwave != nullptr && pwave->enabled) {
    pwave->sample_period_s = config.estimator.sample_period();
    if (!pwave->fragility_known) {
      return {ErrorCode::kInconsistent, "pwave",
              "needs the statue's fragility (the scene file's [fragility]: median_g, beta)"};
    }
    PLINTH_TRY(monitor::PWaveStage::create(*pwave, *pwave_stage()));
  }
  status_.has_pwave = pwave_present();
  for (int i = 0; i < config.axis_count; ++i) {
    status_.axes[static_cast<std::size_t>(i)].members = ensemble(i).size();
  }
  const StatueSensorSettings* statue =
      monitor::built_part<StatueSensorSettings>(config.statue_sensor);
  status_.has_statue_sensor = statue != nullptr && statue->present;
  if (status_.has_statue_sensor) {
    PLINTH_TRY(room().sensor.start(*statue, config.estimator.sample_period()));
    for (int i = 0; i < config.axis_count; ++i) {
      // The accelerometer's lever arm in axis i's plane: x-z for axis 0, y-z for axis 1.
      const StatueAccelerometerMount mount{statue->height_m,
                                           i == 0 ? statue->offset_x_m : statue->offset_y_m};
      PLINTH_TRY(room().filters[static_cast<std::size_t>(i)].start(
          statue->filter, config.estimator, config.risk, ensemble(i).size(), mount));
    }
    note_statue_health();
  }
  if (statue_present()) {
    room().measured.fill(false);
    room().restarts = 0;
  }
  last_ground_.setZero();
  frames_not_encoded_ = 0;
  have_epoch_ = false;
  bus_fault_ = false;
  held_fault_ = monitor::AlarmCause::kNone;
  pending_ack_ = false;
  pending_stands_ = false;
  evaluated_ = false;
  status_interval_ns_ = std::llround(config.status_interval_s * 1e9);
  next_status_ns_ = 0;
  status_sequence_ = 0;
  return ok_error();
}

void Monitor::set_event_sink(int axis, EventSink* sink) {
  if (axis < 0 || axis >= kMaxAxes) return;
  ensembles_[static_cast<std::size_t>(axis)].set_event_sink(sink);
}

std::int64_t Monitor::monitor_time(std::int64_t receive_time_ns) {
  if (!have_epoch_) {
    have_epoch_ = true;
    epoch_ns_ = receive_time_ns;
  }
  const std::int64_t t = receive_time_ns - epoch_ns_;
  return t > status_.time_ns ? t : status_.time_ns;  // never backwards
}

// Quiet: every member of every axis in full contact, and the worst risk low (the offset is
// tracked only then; the same for every member, whatever their order).
bool Monitor::quiet() const {
  bool quiet = status_.estimating && status_.calibrated && status_.risk < config_.quiet_risk;
  for (int i = 0; i < status_.axis_count && quiet; ++i) quiet = ensemble(i).in_full_contact();
  return quiet;
}

MonitorUpdate Monitor::new_update() const {
  MonitorUpdate update;
  update.status = &status_;
  return update;
}

MonitorUpdate Monitor::on_sensor_sample(int sensor, const monitor::SensorSample& sample) {
  MonitorUpdate update = new_update();
  take_sample(sensor, sample, update);
  return update;
}

void Monitor::take_sample(int sensor, const monitor::SensorSample& sample, MonitorUpdate& update) {
  if (sensor < 0 || sensor >= sensors_.count()) {
    report_state(update);
    return;
  }
  status_.time_ns = monitor_time(sample.receive_time_ns);
  sensors_.tick(sample.receive_time_ns, sensor);
  if (statue_present()) {  // its timeout, on the ground sensors' clock
    room().sensor.tick(sample.receive_time_ns);
    note_statue_health();
  }
  const monitor::SensorUpdate fed = sensors_.receive(sensor, sample);
  // Each fed sample in turn: the primary's goes on to the estimators at once (the next one's
  // conditioning is told whether they are quiet).
  for (std::size_t i = 0; i < fed.fed_count; ++i) {
    if (sensors_.condition(sensor, fed.fed[i], quiet())) status_.calibrated = true;
    feed_estimators();
    feed_other_reading(sensor);
  }
  // The estimators took every input the primary had; a new primary may have more.
  if (sensors_.update_primary()) feed_estimators();
  sensors_.cross_check();
  evaluate(update);
}

// Another ground sensor's newest conditioned sample to its own ensembles: they start at rest on
// its first sample (its offset known) and again after a seam, a fault, or a turn as the primary.
void Monitor::feed_other_reading(int sensor) {
  if constexpr (kOtherReadings == 0) return;
  if (sensor < 0 || sensor >= kOtherReadings) return;
  OtherReading& other = others_[static_cast<std::size_t>(sensor)];
  if (sensor == status_.primary || sensors_.config(sensor).role != SensorRole::kGround ||
      !sensors_.healthy_ground(sensor)) {
    other.running = false;
    return;
  }
  ConditionedReading c;
  if (!sensors_.newest_reading(sensor, other.seen, c)) return;
  const bool start = !other.running || c.restart;
  for (int i = 0; i < status_.axis_count; ++i) {
    Ensemble& e = other.ensembles[static_cast<std::size_t>(i)];
    const GroundAcceleration g{c.ground_m_s2[i], c.ground_m_s2.z()};
    if (start) {
      e.restart(g);
    } else {
      e.push(g);
    }
  }
  if (start) other.start_ns = c.time_ns - epoch_ns_;
  other.running = true;
}

// While the ground sensors disagree, each axis's risk, forecast and phase follow the most
// dangerous healthy reading: the higher risk, the higher probability, the further phase
// (docs/safety.md). One sensor turned or mis-scaled cannot then lower the alarm.
void Monitor::follow_worst_reading() {
  status_.risk_sensor = -1;
  if (!status_.disagreement) return;
  for (int sensor = 0; sensor < kOtherReadings; ++sensor) {
    const OtherReading& other = others_[static_cast<std::size_t>(sensor)];
    if (!other.running || sensor == status_.primary || !sensors_.healthy_ground(sensor)) continue;
    for (int i = 0; i < status_.axis_count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      AxisStatus& axis = status_.axes[k];
      const Ensemble& e = other.ensembles[k];
      EnsembleRisk r;
      e.risk(r);
      if (r.risk.total > axis.risk.total) {
        static_cast<EnsembleRisk&>(axis) = r;
        status_.risk_sensor = sensor;
      }
      const ForecastOutcome& f = e.forecaster().latest();
      if (kForecastBuiltIn && f.valid && f.probability > axis.forecast.probability) {
        axis.forecast = f;  // its times from the primary's estimators' start, as theirs are
        axis.forecast.start_time_s +=
            static_cast<double>(other.start_ns - status_.estimator_start_ns) * 1e-9;
        status_.risk_sensor = sensor;
      }
      if (phase_severity(e.nominal().mode()) > phase_severity(axis.mode)) {
        axis.mode = e.nominal().mode();
        axis.state = e.nominal().state();
        status_.risk_sensor = sensor;
      }
    }
  }
}

// Each axis's members take the sample; with the statue sensor's newest rate fresh, the axis's
// filter weighs them on it, and tests sliding on the newest specific force when that is fresh
// too (a restart of the statue's stream loses the tilt: the filters start again).
void Monitor::push_ensembles(const Vector3r& g, std::int64_t receive_time_ns) {
  const bool measuring = statue_present() && room().sensor.usable(receive_time_ns);
  const bool accelerating = measuring && room().sensor.acceleration_usable(receive_time_ns);
  if (measuring && room().sensor.restarts() != room().restarts) {
    room().restarts = room().sensor.restarts();
    for (StatueFilter& f : room().filters) f.reset();
  }
  for (int i = 0; i < status_.axis_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ensembles_[k].push({g[i], g.z()});
    if (statue_present()) room().measured[k] = measuring;
    if (measuring) {
      room().filters[k].on_sample(
          ensembles_[k], {g[i], g.z()},
          {room().sensor.axis_rate(i), accelerating,
           accelerating ? room().sensor.axis_specific_force(i) : Real(0)});
    }
  }
  if (monitor::PWaveStage* stage = pwave_stage()) (void)stage->update(g);
}

void Monitor::feed_estimators() {
  EstimatorInput in;
  while (sensors_.next_input(in)) {
    const Vector3r& g = in.ground_m_s2;
    if (in.start) {
      for (int i = 0; i < status_.axis_count; ++i) {
        ensembles_[static_cast<std::size_t>(i)].restart({g[i], g.z()});
        if (statue_present()) {
          room().filters[static_cast<std::size_t>(i)].reset();
          room().measured[static_cast<std::size_t>(i)] = false;
        }
      }
      // The P-wave stage's filters do not connect across the seam either.
      if (monitor::PWaveStage* stage = pwave_stage()) {
        stage->restart();
        (void)stage->update(g);
      }
      ++status_.estimator_restarts;
      status_.estimator_start_ns = in.time_ns - epoch_ns_;
      status_.calibrated = in.calibrated;
    } else {
      // A failover's seam: the samples missed, linearly between the newest taken and this one.
      const long n = in.bridged + 1;
      for (long j = 1; j < n; ++j) {
        const auto w = static_cast<Real>(static_cast<double>(j) / static_cast<double>(n));
        push_ensembles(last_ground_ + w * (g - last_ground_), in.time_ns);
      }
      push_ensembles(g, in.time_ns);
    }
    status_.estimating = true;
    status_.newest_sample_time_ns = in.time_ns - epoch_ns_;
    last_ground_ = g;
    if (sensors_.has_plate()) {
      Vector3r base = Vector3r::Zero();
      for (int i = 0; i < status_.axis_count; ++i) base[i] = ensemble(i).base_acceleration();
      sensors_.add_model_sample(in.time_ns, base);
    }
  }
}

// One axis: the nominal statue's mode and state, the worst member's risk, the forecast (the box
// without the statue sensor). With the statue sensor measuring and corroborated, the measured
// phase, tilt and rate, the filter's risk (weighted once informative, else the worst member's)
// and, while it measures motion, the forecast's probability weighted alike; uncorroborated, the
// sensor only raises: the higher risk and probability, the further phase (docs/safety.md).
void Monitor::update_axis(int axis_index, AxisStatus& axis) const {
  const auto k = static_cast<std::size_t>(axis_index);
  const Ensemble& statues = ensemble(axis_index);
  axis.mode = statues.nominal().mode();
  axis.state = statues.nominal().state();
  statues.risk(axis);
  axis.forecast = statues.forecaster().latest();
  StatueAxisStatus* statue = monitor::built_part<StatueAxisStatus>(axis.statue);
  if (statue == nullptr || !statue_present()) return;
  *statue = StatueAxisStatus{};
  statue->risk_without = axis.risk.total;
  if (!room().measured[k]) return;
  const StatueEstimate& e = room().filters[k].estimate();
  const double probability = weighted_collapse_probability(axis.forecast, e);
  *statue = {true,          e.informative,     !e.explained,        e.weighted,
             e.effective_members, e.best_score, e.best_member, e.ruled_out,
             e.acceleration_used, e.corroborated, e.refutation, false,
             axis.risk.total};
  if (e.corroborated) {
    axis.mode = e.mode;
    axis.state[kTheta] = e.tilt;
    axis.state[kThetaDot] = e.rotation_rate;
    axis.risk = e.risk;
    axis.worst_member = e.risk_member;
    // Stillness is no evidence against the forecast: a sensor stuck, come off the statue onto
    // the plinth, or on a neighbour reads what a standing statue reads, and the ground
    // corroborates it. Only measured motion weighs the forecast (docs/safety.md, "What
    // stillness cannot rule out").
    if (e.mode.phase == Phase::kFullContact) return;
    // The collapse named is the first among the members the weighing keeps.
    const std::uint32_t left_out =
        e.weighted ? e.ruled_out_members : e.ruled_out_members | e.disagreeing_members;
    axis.forecast.worst_member = -1;
    axis.forecast.collapse_in_s = first_counted_collapse(axis.forecast, ~left_out,
                                                         axis.forecast.worst_member);
    axis.forecast.probability = probability;
    return;
  }
  statue->lowering_refused = e.risk.total < axis.risk.total ||
                             probability < axis.forecast.probability ||
                             phase_severity(e.mode) < phase_severity(axis.mode);
  if (e.risk.total > axis.risk.total) {
    axis.risk = e.risk;
    axis.worst_member = e.risk_member;
  }
  if (probability > axis.forecast.probability) axis.forecast.probability = probability;
  if (phase_severity(e.mode) > phase_severity(axis.mode)) {
    axis.mode = e.mode;
    axis.state[kTheta] = e.tilt;
    axis.state[kThetaDot] = e.rotation_rate;
  }
}

// The statue sensor's trouble (an input fault: the level stays at least the box's without it):
// unusable while the estimators run calibrated, or not corroborated on a measured axis (a
// custodian hears of a sensor the box no longer trusts, whether or not it would lower the level
// now: docs/safety.md).
void Monitor::note_statue_trouble() {
  status_.statue_sensor_unusable = false;
  if (!statue_present() || !status_.estimating || !status_.calibrated) return;
  bool measured_any = false;
  for (int i = 0; i < status_.axis_count; ++i) {
    measured_any = measured_any || room().measured[static_cast<std::size_t>(i)];
  }
  // Usable since the last ground sample: measured from the next one on.
  if (!measured_any && !room().sensor.usable(status_.time_ns + epoch_ns_)) {
    // Sending, its offset still being estimated: a state of knowledge for a while (as
    // not_calibrated is for the ground's), then trouble. Silent or at fault: trouble at once.
    const StatueSensorSettings* statue =
        monitor::built_part<StatueSensorSettings>(config_.statue_sensor);
    const double waited_s =
        static_cast<double>(status_.time_ns - status_.estimator_start_ns) * 1e-9;
    const bool sending = room().sensor.rate_health().state != monitor::HealthState::kFault;
    if (sending && !room().sensor.ready() && statue != nullptr &&
        waited_s < statue->offset_window_s + kStatueOffsetGraceS) {
      return;
    }
    status_.statue_sensor_unusable = true;
    status_.input_fault = monitor::AlarmCause::kStatueSensorFault;
    return;
  }
  for (int i = 0; i < status_.axis_count; ++i) {
    const auto* statue =
        monitor::built_part<StatueAxisStatus>(status_.axes[static_cast<std::size_t>(i)].statue);
    if (statue == nullptr || !statue->measured || statue->corroborated) continue;
    status_.input_fault = statue->refutation == StatueRefutation::kUnexplained
                              ? monitor::AlarmCause::kStatueUnexplained
                              : monitor::AlarmCause::kStatueSensorFault;
    return;
  }
}

// The axes' part of the status: mode, state, risk, the forecast.
void Monitor::update_axes_status() {
  Real risk = 0;
  if (statue_present()) status_.statue_unexplained = false;
  status_.probability = 0.0;
  status_.forecast_axis = -1;
  status_.collapse_forecast_s = -1.0;
  status_.input_fault = monitor::AlarmCause::kNone;
  for (int i = 0; i < status_.axis_count; ++i) {
    if (status_.estimating) update_axis(i, status_.axes[static_cast<std::size_t>(i)]);
  }
  if (status_.estimating) follow_worst_reading();
  for (int i = 0; i < status_.axis_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    AxisStatus& axis = status_.axes[k];
    if (const StatueAxisStatus* statue = monitor::built_part<StatueAxisStatus>(axis.statue);
        statue != nullptr && statue_present()) {
      status_.statue_unexplained = status_.statue_unexplained || statue->unexplained;
    }
    risk = axis.risk.total > risk ? axis.risk.total : risk;
    const ForecastOutcome& f = axis.forecast;
    axis.collapse_forecast_s = -1.0;
    if (!kForecastBuiltIn || !f.valid) continue;
    if (status_.forecast_axis < 0 || f.probability > status_.probability) {
      status_.probability = f.probability;
      status_.forecast_axis = i;
    }
    // A collapse time is named only beside a probability the frames show above 0.
    if (f.worst_member >= 0 && f.probability >= kSmallestShownProbability) {
      const double at_s = static_cast<double>(status_.estimator_start_ns) * 1e-9 +
                          f.start_time_s + f.collapse_in_s;
      axis.collapse_forecast_s = at_s;
      if (status_.collapse_forecast_s < 0.0 || at_s < status_.collapse_forecast_s) {
        status_.collapse_forecast_s = at_s;
      }
    }
  }
  status_.risk = static_cast<double>(risk);
  note_statue_trouble();
}

void Monitor::evaluate(MonitorUpdate& update) {
  sensors_.update_status();
  update_axes_status();
  auto* regional_state = monitor::built_part<monitor::RegionalAlertState>(regional_);
  if (auto* shown = monitor::built_part<monitor::RegionalAlertStatus>(status_.regional);
      regional_state != nullptr && shown != nullptr) {
    regional_state->tick(status_.time_ns);
    *shown = regional_state->status();
  }
  const monitor::PWaveStage* stage = pwave_stage();
  if (auto* shown = monitor::built_part<monitor::PWaveStatus>(status_.pwave);
      stage != nullptr && shown != nullptr) {
    *shown = stage->status();
  }
  monitor::AlarmInput input = alarm_input(status_, config_, bus_fault_);
  // Not estimating, the axes keep what they last showed (a held collapse among it): no reading
  // says collapse then (a person's statement after a restart on a silent bus is not refused).
  if (!status_.estimating) input.collapse_detected = false;
  if (held_fault_ != monitor::AlarmCause::kNone) {
    input.fault_active = true;
    input.fault_cause = held_fault_;
  }
  input.acknowledged = pending_ack_;
  input.acknowledgement = ack_;
  input.statue_stands = pending_stands_;
  input.statue_stands_sequence = stands_sequence_;
  pending_ack_ = false;
  pending_stands_ = false;
  const monitor::AlarmOutput out = alarm_.update(input);
  for (std::size_t i = 0; i < out.event_count && update.event_count < update.events.size(); ++i) {
    update.events[update.event_count++] = out.events[i];
  }
  if (out.acknowledgement != monitor::AckOutcome::kNone) {
    update.acknowledgement = out.acknowledgement;
  }
  if (out.statue_stands != monitor::StandsOutcome::kNone) {
    update.statue_stands = out.statue_stands;
  }
  status_.alarm = out.level;
  status_.latched = out.latched_level;
  status_.trouble = out.trouble;
  note_collapse(input);
  evaluated_ = true;
  report(update);
}

// The held collapse: recorded when the policy begins to hold one, shown on every axis while it
// holds (no later reading shows the statue standing: docs/safety.md), forgotten when a person
// said the statue stands.
void Monitor::note_collapse(const monitor::AlarmInput& input) {
  CollapseRecord& c = status_.collapse;
  if (!alarm_.collapse_held()) {
    c = CollapseRecord{};
    return;
  }
  if (!c.held && input.collapse_detected) {
    c.held = true;
    c.restored = false;
    c.time_ns = status_.time_ns;
    for (int i = 0; i < status_.axis_count; ++i) {
      const Mode& mode = status_.axes[static_cast<std::size_t>(i)].mode;
      if (!mode.collapsed()) continue;
      c.axis = i;
      c.mode = mode;
      break;
    }
  }
  for (int i = 0; i < status_.axis_count; ++i) {
    Mode& shown = status_.axes[static_cast<std::size_t>(i)].mode;
    if (shown.collapsed()) continue;
    if (i == c.axis) {
      shown = c.mode;
    } else {
      shown.phase = c.mode.phase;  // the other plane: the corner it shows is its own
    }
  }
}

// A status without new input: evaluated once first, so that no status says the alarm policy's
// initial `normal` (found by fuzz_monitor: a heartbeat frame before any sample).
void Monitor::report_state(MonitorUpdate& update) {
  if (evaluated_) {
    report(update);
  } else {
    evaluate(update);
  }
}

// A frame the update cannot carry is counted in the status and in the update, never dropped
// silently (the update is sized for the most it has: a full one is a defect).
template <typename Message>
void Monitor::add_frame(MonitorUpdate& update, const Message& message) {
  if (update.frame_count >= update.frames.size() ||
      !can::encode(message, update.frames[update.frame_count]).ok()) {
    ++frames_not_encoded_;
    ++update.frames_lost;
    status_.frames_not_encoded = frames_not_encoded_;
    return;
  }
  ++update.frame_count;
}

// The update's alarm events, then the status when it is due (a MonitorStatus per axis, then,
// while forecasting, a CollapseForecast per axis that has a completed forecast, with the same
// sequence): at every alarm change, at the alarm policy's heartbeat, and at status_interval_s.
void Monitor::report(MonitorUpdate& update) {
  update.status_due = update.event_count > 0 || alarm_.heartbeat_due(status_.time_ns) ||
                      status_.time_ns >= next_status_ns_;
  for (std::size_t i = 0; i < update.event_count; ++i) {
    add_frame(update, alarm_event_message(update.events[i]));
  }
  if (!update.status_due) return;
  for (int i = 0; i < status_.axis_count; ++i) {
    add_frame(update, status_message(status_, i, status_sequence_));
  }
  // A build without the forecast (PLINTH_FORECAST=OFF) never has one to send.
  for (int i = 0; kForecastBuiltIn && config_.forecast.enabled && i < status_.axis_count; ++i) {
    if (!status_.axes[static_cast<std::size_t>(i)].forecast.valid) continue;
    add_frame(update, forecast_message(status_, i, config_.forecast.horizon_s, status_sequence_));
  }
  ++status_sequence_;
  alarm_.heartbeat_sent(status_.time_ns);
  if (next_status_ns_ <= status_.time_ns) {  // the first interval boundary after now
    next_status_ns_ +=
        ((status_.time_ns - next_status_ns_) / status_interval_ns_ + 1) * status_interval_ns_;
  }
}

void Monitor::note_statue_health() {
  if (StatueSensorStatus* s = monitor::built_part<StatueSensorStatus>(status_.statue_sensor)) {
    *s = {room().sensor.rate_health(), room().sensor.acceleration_health(), room().sensor.ready()};
  }
}

MonitorUpdate Monitor::on_statue_sample(const StatueSample& sample) {
  MonitorUpdate update = new_update();
  if (!statue_present()) {
    report_state(update);
    return update;
  }
  status_.time_ns = monitor_time(sample.receive_time_ns);
  room().sensor.on_sample(sample, !status_.estimating || quiet());
  note_statue_health();
  evaluate(update);
  return update;
}

MonitorUpdate Monitor::on_statue_acceleration(const monitor::SensorSample& sample) {
  MonitorUpdate update = new_update();
  if (!statue_present()) {
    report_state(update);
    return update;
  }
  status_.time_ns = monitor_time(sample.receive_time_ns);
  room().sensor.on_acceleration(sample, !status_.estimating || quiet(), last_ground_);
  note_statue_health();
  evaluate(update);
  return update;
}

MonitorUpdate Monitor::on_tick(std::int64_t receive_time_ns) {
  MonitorUpdate update = new_update();
  if (have_epoch_ && statue_present()) {
    room().sensor.tick(receive_time_ns);
    note_statue_health();
  }
  if (have_epoch_) {
    sensors_.tick(receive_time_ns);
    status_.time_ns = monitor_time(receive_time_ns);
    if (sensors_.update_primary()) feed_estimators();
    sensors_.cross_check();
  }
  evaluate(update);
  return update;
}

MonitorUpdate Monitor::acknowledge(const monitor::Acknowledgement& acknowledgement) {
  MonitorUpdate update = new_update();
  pending_ack_ = true;
  ack_ = acknowledgement;
  evaluate(update);
  return update;
}

MonitorUpdate Monitor::statue_stands(std::uint8_t event_sequence) {
  MonitorUpdate update = new_update();
  bool measured_collapse = false;
  for (int i = 0; statue_present() && i < status_.axis_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const StatueEstimate& e = room().filters[k].estimate();
    measured_collapse = measured_collapse ||
                        (room().measured[k] && e.corroborated && e.mode.collapsed());
  }
  // The estimators' own collapse is their simulation's, and an uncorroborated statue sensor's
  // proves nothing: a person's word outranks them, and they start again (the filters too). A
  // corroborated sensor's measured collapse is not overruled (kStillCollapsed).
  if (alarm_.collapse_held() && !measured_collapse &&
      alarm_.sequence_is_latest(event_sequence)) {
    restart_estimators();
  }
  pending_stands_ = true;
  stands_sequence_ = event_sequence;
  evaluate(update);
  return update;
}

// The estimators again at rest on the newest input, untrusted until the primary's conditioner
// passes a quiet window (the start-up rule).
void Monitor::restart_estimators() {
  for (int i = 0; i < status_.axis_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ensembles_[k].restart({last_ground_[i], last_ground_.z()});
    if (statue_present()) {
      room().filters[k].reset();
      room().measured[k] = false;
    }
  }
  for (OtherReading& other : others_) other.running = false;  // again on their next samples
  if (monitor::PWaveStage* stage = pwave_stage()) stage->restart();
  ++status_.estimator_restarts;
  status_.estimator_start_ns = status_.time_ns;
  status_.calibrated = false;
  sensors_.verify_primary();
}

BoxMemory Monitor::memory() const { return {alarm_.memory(), status_.collapse}; }

void Monitor::restore(const BoxMemory& memory) {
  alarm_.restore(memory.alarm);
  status_.collapse = memory.alarm.collapse_held ? memory.collapse : CollapseRecord{};
  status_.collapse.held = memory.alarm.collapse_held;
  status_.collapse.restored = memory.alarm.collapse_held;
  if (memory.collapse.axis < 0 || memory.collapse.axis >= status_.axis_count) {
    status_.collapse.axis = 0;
  }
  if (status_.collapse.held && !status_.collapse.mode.collapsed()) {
    status_.collapse.mode.phase = Phase::kOverturned;  // a record without its phase
  }
}

MonitorUpdate Monitor::on_regional_alert(const monitor::RegionalAlert& alert,
                                         std::int64_t receive_time_ns) {
  status_.time_ns = monitor_time(receive_time_ns);
  return on_regional_alert(alert);
}

MonitorUpdate Monitor::on_regional_alert(const monitor::RegionalAlert& alert) {
  MonitorUpdate update = new_update();
  update.regional_received = true;
  auto* regional_state = monitor::built_part<monitor::RegionalAlertState>(regional_);
  update.regional =
      regional_state != nullptr
          ? regional_state->receive(alert, status_.time_ns)
          : monitor::RegionalOutcome{monitor::RegionalRefusal::kMalformed,
                                     monitor::kRegionalAlertNotBuilt};
  evaluate(update);
  return update;
}

MonitorUpdate Monitor::regional_alert_malformed(const char* field) {
  return regional_alert_refused(monitor::RegionalRefusal::kMalformed, field);
}

MonitorUpdate Monitor::regional_alert_refused(monitor::RegionalRefusal refusal,
                                              const char* field) {
  MonitorUpdate update = new_update();
  if (auto* regional_state = monitor::built_part<monitor::RegionalAlertState>(regional_)) {
    regional_state->refuse_unread(refusal, field);
  }
  update.regional_received = true;
  update.regional = {refusal, field};
  evaluate(update);
  return update;
}

MonitorUpdate Monitor::poll() {
  MonitorUpdate update = new_update();
  report_state(update);
  return update;
}

}  // namespace plinth::firmware

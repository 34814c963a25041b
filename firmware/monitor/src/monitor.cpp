#include "plinth/firmware/monitor.h"

#include <cmath>

#include "plinth/firmware/can_frames.h"

namespace plinth::firmware {

namespace {

#define PLINTH_TEXT_OF(x) #x
#define PLINTH_TEXT(x) PLINTH_TEXT_OF(x)

// The settings of a cross-check window: window_s at the sample rate in [2, max] samples, and a
// finite positive tolerance.
Error validate_check(double window_s, double tolerance_m_s2, double rate_hz,
                     const char* window_field, const char* tolerance_field) {
  const double samples = window_s * rate_hz;
  if (!std::isfinite(window_s) || samples < 2.0 ||
      samples > static_cast<double>(kMaxCheckWindowSamples)) {
    return {ErrorCode::kOutOfRange, window_field,
            "must span 2 to " PLINTH_TEXT(PLINTH_MONITOR_MAX_CHECK_WINDOW_SAMPLES)
            " sample periods at the sample rate"};
  }
  if (!std::isfinite(tolerance_m_s2) || tolerance_m_s2 <= 0.0) {
    return {ErrorCode::kOutOfRange, tolerance_field, "must be a positive acceleration, m/s2"};
  }
  return ok_error();
}

int window_length(double window_s, double rate_hz) {
  const long n = std::lround(window_s * rate_hz);
  return n < 2 ? 2 : (n > kMaxCheckWindowSamples ? kMaxCheckWindowSamples : static_cast<int>(n));
}

}  // namespace

int resolved_sensors(const MonitorConfig& c, std::array<SensorConfig, kMaxSensors>& out) {
  if (c.sensor_count <= 0) {
    out[0].node = c.ground_node;
    out[0].role = SensorRole::kGround;
    out[0].conditioning = c.conditioning;
    out[0].sensor_health = c.sensor_health;
    return 1;
  }
  const int count = c.sensor_count > kMaxSensors ? kMaxSensors : c.sensor_count;
  for (int i = 0; i < count; ++i) {
    out[static_cast<std::size_t>(i)] = c.sensors[static_cast<std::size_t>(i)];
  }
  return count;
}

namespace {

// The [monitor] fields.
Error validate_monitor_fields(const MonitorConfig& c) {
  if (c.axis_count < 1 || c.axis_count > kMaxAxes) {
    return {ErrorCode::kOutOfRange, "monitor.axis_count", "must be 1 or 2"};
  }
  if (c.sensor_count < 0 || c.sensor_count > kMaxSensors) {
    return {ErrorCode::kOutOfRange, "monitor.sensor_count",
            "must lie in [0, " PLINTH_TEXT(PLINTH_MONITOR_MAX_SENSORS) "]"};
  }
  if (c.sensor_count == 0 &&
      (c.ground_node < can::kFirstSensorNode || c.ground_node > can::kLastSensorNode)) {
    return {ErrorCode::kOutOfRange, "monitor.ground_node", "must lie in [1, 15]"};
  }
  if (!std::isfinite(c.quiet_risk) || c.quiet_risk < 0.0 || c.quiet_risk > 1.0) {
    return {ErrorCode::kOutOfRange, "monitor.quiet_risk", "must lie in [0, 1]"};
  }
  // At least 1 ns, and room for hours of monitor time (int64 ns).
  if (!std::isfinite(c.status_interval_s) || c.status_interval_s < 1e-9 ||
      c.status_interval_s > 1e6) {
    return {ErrorCode::kOutOfRange, "monitor.status_interval_s", "must lie in [1e-9, 1e6] s"};
  }
  return ok_error();
}

// Every sensor: node, role, its conditioning and health at the estimator's sample period; at
// least one ground sensor. `sensor_index` receives the index of the sensor at fault.
Error validate_sensors(const MonitorConfig& c, int* sensor_index) {
  std::array<SensorConfig, kMaxSensors> sensors{};
  const int count = resolved_sensors(c, sensors);
  int grounds = 0;
  int plates = 0;
  for (int i = 0; i < count; ++i) {
    const SensorConfig& s = sensors[static_cast<std::size_t>(i)];
    if (sensor_index != nullptr) *sensor_index = c.sensor_count == 0 ? -1 : i;
    if (s.node < can::kFirstSensorNode || s.node > can::kLastSensorNode) {
      return {ErrorCode::kOutOfRange, "sensor.node", "must lie in [1, 15]"};
    }
    for (int j = 0; j < i; ++j) {
      if (sensors[static_cast<std::size_t>(j)].node == s.node) {
        return {ErrorCode::kInconsistent, "sensor.node", "is another sensor's node"};
      }
    }
    if (s.role == SensorRole::kGround) {
      ++grounds;
    } else if (s.role == SensorRole::kPlate) {
      if (++plates > 1) {
        return {ErrorCode::kInconsistent, "sensor.role", "a second plate sensor: at most one"};
      }
    } else {
      return {ErrorCode::kOutOfRange, "sensor.role", "must be ground or plate"};
    }
    monitor::ConditioningSettings conditioning = s.conditioning;
    conditioning.sample_period_s = c.estimator.sample_period();
    PLINTH_TRY(monitor::validate(conditioning));
    monitor::SensorHealthSettings health = s.sensor_health;
    health.sample_period_s = c.estimator.sample_period();
    PLINTH_TRY(monitor::validate(health));
  }
  if (grounds == 0) {
    if (sensor_index != nullptr) *sensor_index = 0;
    return {ErrorCode::kInconsistent, "sensor.role",
            "no ground sensor: at least one must drive the estimators"};
  }
  if (sensor_index != nullptr) *sensor_index = -1;
  return ok_error();
}

}  // namespace

Error validate(const MonitorConfig& c, int* sensor_index) {
  if (sensor_index != nullptr) *sensor_index = -1;
  PLINTH_TRY(validate_monitor_fields(c));
  PLINTH_TRY(validate(c.risk));
  PLINTH_TRY(monitor::validate(c.alarm));
  // The sensor's period is the estimator's sample period: checked with the values start() uses.
  if (!std::isfinite(c.estimator.sample_rate_hz) || c.estimator.sample_rate_hz < 100.0 ||
      c.estimator.sample_rate_hz > 1000.0) {
    return {ErrorCode::kOutOfRange, "estimator.sample_rate_hz", "must lie in [100, 1000] Hz"};
  }
  PLINTH_TRY(validate(c.forecast, c.estimator.sample_rate_hz));
  PLINTH_TRY(validate_check(c.redundancy.window_s, c.redundancy.tolerance_m_s2,
                            c.estimator.sample_rate_hz, "redundancy.window_s",
                            "redundancy.tolerance_m_s2"));
  PLINTH_TRY(validate_check(c.plate.window_s, c.plate.threshold_m_s2, c.estimator.sample_rate_hz,
                            "plate.window_s", "plate.threshold_m_s2"));
  return validate_sensors(c, sensor_index);
}

void Monitor::RmsWindow::add(Real square) {
  const auto slot = static_cast<std::size_t>(next);
  if (count >= length) {
    sum -= squares[slot];
  } else {
    ++count;
  }
  squares[slot] = square;
  sum += square;
  next = next + 1 >= length ? 0 : next + 1;
  if (next == 0) {  // once per window: the sum afresh, no drift of the running sum over hours
    sum = 0;
    for (int i = 0; i < count; ++i) sum += squares[static_cast<std::size_t>(i)];
  }
}

Real Monitor::RmsWindow::rms() const {
  if (count == 0) return 0;
  const Real mean = sum / static_cast<Real>(count);
  return mean > 0 ? std::sqrt(mean) : 0;
}

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
    if (members.size() > static_cast<std::size_t>(kMaxEnsembleMembers)) {
      return {ErrorCode::kOutOfRange, "uncertainty",
              "gives more ensemble members than this build holds (kMaxEnsembleMembers)",
              static_cast<double>(kMaxEnsembleMembers)};
    }
    for (const Scene& scene : members) PLINTH_TRY(validate(config.estimator, scene));
    PLINTH_TRY(forecasters_[static_cast<std::size_t>(i)].start(config.forecast,
                                                               config.estimator.sample_rate_hz));
  }
  config_ = config;
  config_.conditioning.sample_period_s = config.estimator.sample_period();
  config_.sensor_health.sample_period_s = config.estimator.sample_period();
  sensor_count_ = resolved_sensors(config_, sensor_configs_);
  status_ = MonitorStatus{};
  status_.axis_count = config.axis_count;
  status_.sensor_count = sensor_count_;
  for (int i = 0; i < sensor_count_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    SensorConfig& sc = sensor_configs_[k];
    sc.conditioning.sample_period_s = config.estimator.sample_period();
    sc.sensor_health.sample_period_s = config.estimator.sample_period();
    Sensor& s = sensors_[k];
    PLINTH_TRY(monitor::SensorHealthTracker::create(sc.sensor_health, s.health));
    PLINTH_TRY(monitor::Conditioner::create(sc.conditioning, s.conditioner));
    s.history = History{};
    s.window.reset();
    s.window.length = sc.role == SensorRole::kPlate
                          ? window_length(config.plate.window_s, config.estimator.sample_rate_hz)
                          : window_length(config.redundancy.window_s,
                                          config.estimator.sample_rate_hz);
    s.checked = 0;
    SensorStatus& st = status_.sensors[k];
    st = SensorStatus{};
    st.node = sc.node;
    st.role = sc.role;
    st.health = s.health.health();
    if (sc.role == SensorRole::kPlate) status_.plate = i;
  }
  PLINTH_TRY(monitor::AlarmPolicy::create(config_.alarm, alarm_));
  scenes_ = ensembles;
  for (int i = 0; i < config.axis_count; ++i) {
    status_.axes[static_cast<std::size_t>(i)].members = members(i);
  }
  status_.sensor = sensors_[0].health.health();
  estimate_ = History{};
  period_ns_ = std::llround(config.estimator.sample_period() * 1e9);
  consumed_ = 0;
  restart_pending_ = false;
  align_pending_ = false;
  last_fed_ns_ = 0;
  last_ground_.setZero();
  frames_ = FrameCounters{};
  have_epoch_ = false;
  bus_fault_ = false;
  pending_ack_ = false;
  evaluated_ = false;
  status_interval_ns_ = std::llround(config.status_interval_s * 1e9);
  next_status_ns_ = 0;
  status_sequence_ = 0;
  return ok_error();
}

void Monitor::set_event_sink(int axis, EventSink* sink) {
  if (axis < 0 || axis >= kMaxAxes) return;
  const auto i = static_cast<std::size_t>(axis);
  sinks_[i] = sink;
  ensembles_[i][0].set_event_sink(sink);  // the nominal statue's phases and impacts
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
  for (int i = 0; i < status_.axis_count && quiet; ++i) {
    const auto k = static_cast<std::size_t>(i);
    for (std::size_t m = 0; m < scenes_[k].size(); ++m) {
      quiet = quiet && ensembles_[k][m].mode().phase == Phase::kFullContact;
    }
  }
  return quiet;
}

bool Monitor::usable(int sensor) const {
  const Sensor& s = sensors_[static_cast<std::size_t>(sensor)];
  return sensor_configs_[static_cast<std::size_t>(sensor)].role == SensorRole::kGround &&
         s.health.health().state != monitor::HealthState::kFault && s.conditioner.status().ready &&
         !s.history.empty();
}

MonitorUpdate Monitor::on_sensor_sample(int sensor, const monitor::SensorSample& sample) {
  MonitorUpdate update;
  take_sample(sensor, sample, update);
  return update;
}

void Monitor::take_sample(int sensor, const monitor::SensorSample& sample, MonitorUpdate& update) {
  if (sensor < 0 || sensor >= sensor_count_) {
    report_state(update);
    return;
  }
  status_.time_ns = monitor_time(sample.receive_time_ns);
  // The other sensors' silence shows on this one's clock (a silent primary fails over without
  // waiting for a tick).
  for (int j = 0; j < sensor_count_; ++j) {
    if (j != sensor) (void)sensors_[static_cast<std::size_t>(j)].health.tick(sample.receive_time_ns);
  }
  const monitor::SensorUpdate fed = sensors_[static_cast<std::size_t>(sensor)].health.on_sample(sample);
  for (std::size_t i = 0; i < fed.fed_count; ++i) process(sensor, fed.fed[i]);
  update_primary();
  drain_primary();
  cross_check();
  evaluate(update);
}

// One fed sample of `sensor`: conditioned, kept in its history; the primary's goes on to the
// estimators at once.
void Monitor::process(int sensor, const monitor::FedSample& sample) {
  Sensor& s = sensors_[static_cast<std::size_t>(sensor)];
  const monitor::ConditionedSample c = s.conditioner.condition(sample.acceleration_g, quiet());
  if (!c.ready) return;  // start-up window, or refused input (counted by the conditioner)
  // A verification window passed on the primary: the running estimators are trusted again.
  if (c.window_passed && sensor == status_.primary && status_.estimating) {
    status_.calibrated = true;
  }
  if (sample.restart) {  // a seam: nothing before it connects, nor compares, to what follows
    s.history.clear();
    s.window.reset();
    s.checked = s.history.pushed;
  }
  s.history.push({sample.time_ns, c.ground_m_s2, sample.restart});
  update_primary();
  drain_primary();
}

// Keeps the primary while it is usable; else the first usable ground sensor in configured
// order takes over (a failover once the estimators have run).
void Monitor::update_primary() {
  if (status_.primary >= 0 && usable(status_.primary)) return;
  int candidate = -1;
  for (int i = 0; i < sensor_count_ && candidate < 0; ++i) {
    if (usable(i)) candidate = i;
  }
  if (candidate < 0 || candidate == status_.primary) return;
  const History& h = sensors_[static_cast<std::size_t>(candidate)].history;
  if (status_.primary >= 0) ++status_.failovers;
  status_.primary = candidate;
  // The reference changed: every cross-check starts afresh.
  for (int i = 0; i < sensor_count_; ++i) {
    Sensor& s = sensors_[static_cast<std::size_t>(i)];
    s.window.reset();
    s.checked = s.history.pushed;
    SensorStatus& st = status_.sensors[static_cast<std::size_t>(i)];
    st.window_full = false;
    st.disagreeing = false;
    st.rms_m_s2 = 0.0;
  }
  // Continue from the estimators' state when the new primary's history holds the stream on
  // from their newest sample within the bridge limit; else start again at rest on its newest.
  const int bridge = sensor_configs_[static_cast<std::size_t>(candidate)].sensor_health.max_bridge_samples;
  std::uint64_t next = h.valid_from();
  while (next < h.pushed && h.at(next).time_ns <= last_fed_ns_ + period_ns_ / 2) ++next;
  const bool continues = status_.estimating && next < h.pushed && !h.at(next).restart &&
                         h.at(next).time_ns - last_fed_ns_ <=
                             static_cast<std::int64_t>(bridge + 1) * period_ns_ + period_ns_ / 2;
  if (continues) {
    consumed_ = next;
    align_pending_ = true;
    restart_pending_ = false;
    if (status_.failovers > 0) ++status_.failovers_continued;
  } else {
    consumed_ = h.pushed - 1;
    restart_pending_ = true;
    align_pending_ = false;
  }
}

void Monitor::drain_primary() {
  if (status_.primary < 0) return;
  const History& h = sensors_[static_cast<std::size_t>(status_.primary)].history;
  if (consumed_ < h.valid_from()) consumed_ = h.valid_from();
  while (consumed_ < h.pushed) drive(h.at(consumed_++));
}

void Monitor::push_estimators(const Vector3r& g) {
  for (int i = 0; i < status_.axis_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const GroundAcceleration ground{g[i], g.z()};
    const std::span<PlanarEstimator> members(ensembles_[k].data(), scenes_[k].size());
    for (PlanarEstimator& e : members) e.push(ground);
    forecasters_[k].on_sample(ground, members[0].time(), members);
  }
}

// One sample of the primary into the estimators.
void Monitor::drive(const HistoryEntry& entry) {
  const bool restart = !status_.estimating || entry.restart || restart_pending_;
  if (restart) {
    for (int i = 0; i < status_.axis_count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const GroundAcceleration ground{entry.value[i], entry.value.z()};
      // validate() in start() checked what start() can refuse but a non-finite sample, which
      // conditioning does not pass on.
      for (std::size_t m = 0; m < scenes_[k].size(); ++m) {
        (void)ensembles_[k][m].start(scenes_[k][m], config_.estimator, ground);
      }
      ensembles_[k][0].set_event_sink(sinks_[k]);
      forecasters_[k].reset();
    }
    ++status_.estimator_restarts;
    status_.estimator_start_ns = entry.time_ns - epoch_ns_;
    // Calibrated only on the sample right after a passing window; else verify a new one.
    monitor::Conditioner& conditioner =
        sensors_[static_cast<std::size_t>(status_.primary)].conditioner;
    status_.calibrated = conditioner.status().samples_since_window <= 1;
    if (!status_.calibrated) conditioner.begin_verification();
    restart_pending_ = false;
    align_pending_ = false;
    estimate_.clear();
  } else if (align_pending_) {
    // The first sample after a failover: as many sample periods as its time says (the new
    // primary's clock), the ones between bridged linearly.
    align_pending_ = false;
    const double periods =
        static_cast<double>(entry.time_ns - last_fed_ns_) / static_cast<double>(period_ns_);
    const long n = std::lround(periods);
    if (n < 1) return;  // at or before the estimators' newest sample: taken already
    for (long j = 1; j < n; ++j) {
      const auto w = static_cast<Real>(static_cast<double>(j) / static_cast<double>(n));
      push_estimators(last_ground_ + w * (entry.value - last_ground_));
    }
    push_estimators(entry.value);
  } else {
    push_estimators(entry.value);
  }
  status_.estimating = true;
  status_.newest_sample_time_ns = entry.time_ns - epoch_ns_;
  last_fed_ns_ = entry.time_ns;
  last_ground_ = entry.value;
  if (status_.plate >= 0) {
    // The model's absolute base acceleration u'' + u_G'' per axis: the plate's reference.
    HistoryEntry e;
    e.time_ns = entry.time_ns;
    for (int i = 0; i < status_.axis_count; ++i) {
      const PlanarEstimator& est = estimator(i);
      e.value[i] = est.simulator().accelerations().u + est.ground().horizontal;
    }
    estimate_.push(e);
  }
}

// The reference's value at `time_ns`: interpolated between its samples around it (at most two
// periods apart), else its nearest within one period. False: none.
bool Monitor::reference_at(const History& reference, std::int64_t time_ns, Vector3r& value) const {
  const std::uint64_t from = reference.valid_from();
  if (from >= reference.pushed) return false;
  std::uint64_t after = reference.pushed;  // the first entry later than time_ns
  while (after > from && reference.at(after - 1).time_ns > time_ns) --after;
  const bool have_before = after > from;
  const bool have_after = after < reference.pushed;
  if (have_before && have_after) {
    const HistoryEntry& a = reference.at(after - 1);
    const HistoryEntry& b = reference.at(after);
    if (b.time_ns - a.time_ns <= 2 * period_ns_ && !b.restart) {
      const auto w = static_cast<Real>(static_cast<double>(time_ns - a.time_ns) /
                                       static_cast<double>(b.time_ns - a.time_ns));
      value = a.value + w * (b.value - a.value);
      return true;
    }
  }
  std::int64_t best = period_ns_ + 1;
  if (have_before && time_ns - reference.at(after - 1).time_ns < best) {
    best = time_ns - reference.at(after - 1).time_ns;
    value = reference.at(after - 1).value;
  }
  if (have_after && reference.at(after).time_ns - time_ns < best) {
    best = reference.at(after).time_ns - time_ns;
    value = reference.at(after).value;
  }
  return best <= period_ns_;
}

void Monitor::check_sensor(int sensor) {
  const auto k = static_cast<std::size_t>(sensor);
  Sensor& s = sensors_[k];
  SensorStatus& st = status_.sensors[k];
  const bool plate = sensor_configs_[k].role == SensorRole::kPlate;
  const History& reference = plate ? estimate_ : sensors_[static_cast<std::size_t>(status_.primary)].history;
  const int components = plate ? status_.axis_count : 3;
  if (s.checked < s.history.valid_from()) {  // pushed out before a reference came: not compared
    st.unpaired += s.history.valid_from() - s.checked;
    s.checked = s.history.valid_from();
  }
  while (s.checked < s.history.pushed) {
    const HistoryEntry& e = s.history.at(s.checked);
    // Wait until the reference has a sample at or after this one (or nothing will come: the
    // entry is then pushed out of the history and counted unpaired).
    if (reference.empty() || reference.newest().time_ns < e.time_ns) break;
    ++s.checked;
    Vector3r r = Vector3r::Zero();
    if (!reference_at(reference, e.time_ns, r)) {
      ++st.unpaired;
      continue;
    }
    ++st.pairs;
    Real square = 0;
    for (int c = 0; c < components; ++c) {
      const Real d = e.value[c] - r[c];
      square += d * d;
    }
    s.window.add(square);
  }
  st.window_full = s.window.full();
  st.rms_m_s2 = static_cast<double>(s.window.rms());
  const double limit = plate ? config_.plate.threshold_m_s2 : config_.redundancy.tolerance_m_s2;
  const bool beyond = st.window_full && st.rms_m_s2 > limit;
  if (st.window_full) st.max_rms_m_s2 = st.rms_m_s2 > st.max_rms_m_s2 ? st.rms_m_s2 : st.max_rms_m_s2;
  if (beyond && !st.disagreeing) ++st.disagreements;
  st.disagreeing = beyond;
}

void Monitor::cross_check() {
  if (sensor_count_ < 2 || status_.primary < 0) return;
  for (int i = 0; i < sensor_count_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (i == status_.primary) continue;
    if (sensors_[k].health.health().state == monitor::HealthState::kFault) {
      // Not compared while in fault: what it said before no longer counts.
      sensors_[k].window.reset();
      sensors_[k].checked = sensors_[k].history.pushed;
      status_.sensors[k].window_full = false;
      status_.sensors[k].disagreeing = false;
      continue;
    }
    check_sensor(i);
  }
}

// The sensors' part of the status: each sensor's health, the primary's, the sensors' state.
void Monitor::update_sensors_status() {
  const int reported = status_.primary >= 0 ? status_.primary : 0;
  status_.sensor = sensors_[static_cast<std::size_t>(reported)].health.health();
  bool others_degraded = false;
  bool disagreement = false;
  for (int i = 0; i < sensor_count_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    SensorStatus& st = status_.sensors[k];
    st.health = sensors_[k].health.health();
    st.ready = sensors_[k].conditioner.status().ready;
    st.primary = i == status_.primary;
    if (i == reported) continue;
    others_degraded = others_degraded || st.health.state != monitor::HealthState::kOk;
    disagreement = disagreement || (st.role == SensorRole::kGround && st.disagreeing);
  }
  status_.disagreement = disagreement;
  if (status_.plate >= 0) {
    const SensorStatus& plate = status_.sensors[static_cast<std::size_t>(status_.plate)];
    status_.plate_residual_m_s2 = plate.rms_m_s2;
    status_.plate_mismatch = plate.disagreeing;
  }
  if (status_.sensor.state == monitor::HealthState::kFault) {
    status_.sensors_state = monitor::HealthState::kFault;
  } else if (status_.sensor.state != monitor::HealthState::kOk || others_degraded || disagreement ||
             status_.plate_mismatch) {
    status_.sensors_state = monitor::HealthState::kDegraded;
  } else {
    status_.sensors_state = monitor::HealthState::kOk;
  }
}

// One axis: the nominal statue's mode and state, the worst member's risk, the forecast.
void Monitor::update_axis(int axis_index, AxisStatus& axis) const {
  const auto k = static_cast<std::size_t>(axis_index);
  const PlanarEstimator& nominal = ensembles_[k][0];
  axis.mode = nominal.mode();
  axis.state = nominal.state();
  axis.risk = Risk{};
  axis.worst_member = 0;
  axis.outside_model = false;
  for (std::size_t m = 0; m < scenes_[k].size(); ++m) {
    const PlanarEstimator& e = ensembles_[k][m];
    axis.outside_model = axis.outside_model || e.mode().phase == Phase::kLiftedOff;
    const Risk r = overturning_risk(scenes_[k][m], e.mode(), e.state(), config_.risk);
    if (m == 0) axis.nominal_risk = r;
    if (m == 0 || r.total > axis.risk.total) {
      axis.risk = r;
      axis.worst_member = static_cast<int>(m);
    }
  }
  axis.forecast = forecasters_[k].latest();
}

// The axes' part of the status (mode, state, risk), and the alarm policy's input from them.
void Monitor::update_axes_status(monitor::AlarmInput& input) {
  Real risk = 0;
  bool moving = false;
  bool collapse = false;
  bool outside_model = false;
  status_.probability = 0.0;
  status_.forecast_axis = -1;
  status_.collapse_forecast_s = -1.0;
  for (int i = 0; i < status_.axis_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    AxisStatus& axis = status_.axes[k];
    if (status_.estimating) update_axis(i, axis);
    risk = axis.risk.total > risk ? axis.risk.total : risk;
    moving = moving || axis.mode.phase != Phase::kFullContact;
    collapse = collapse || axis.mode.collapsed();
    outside_model = outside_model || axis.outside_model;
    const ForecastOutcome& f = axis.forecast;
    axis.collapse_forecast_s = -1.0;
    if (!kForecastBuiltIn || !f.valid) continue;
    if (status_.forecast_axis < 0 || f.probability > status_.probability) {
      status_.probability = f.probability;
      status_.forecast_axis = i;
    }
    if (f.worst_member >= 0) {
      const double at_s = static_cast<double>(status_.estimator_start_ns) * 1e-9 +
                          f.start_time_s + f.collapse_in_s;
      axis.collapse_forecast_s = at_s;
      if (status_.collapse_forecast_s < 0.0 || at_s < status_.collapse_forecast_s) {
        status_.collapse_forecast_s = at_s;
      }
    }
  }
  status_.risk = static_cast<double>(risk);
  input.risk = risk;
  input.probability = static_cast<Real>(status_.probability);
  input.out_of_full_contact = moving;
  input.collapse_detected = collapse;
  input.outside_model = outside_model;
}

void Monitor::evaluate(MonitorUpdate& update) {
  update_sensors_status();
  monitor::AlarmInput input;
  input.time_ns = status_.time_ns;
  update_axes_status(input);
  const bool sensor_fault = status_.sensor.state == monitor::HealthState::kFault;
  const bool disagreement = status_.disagreement;
  const bool mismatch_fault = status_.plate_mismatch && config_.plate.raises_fault;
  input.fault_active = sensor_fault || disagreement || mismatch_fault || bus_fault_;
  input.fault_cause = sensor_fault ? monitor::to_alarm_cause(status_.sensor.cause)
                      : (disagreement || mismatch_fault) ? monitor::AlarmCause::kSensorDisagreement
                                                         : monitor::AlarmCause::kBusError;
  // Never normal while no estimator runs, or runs on an untrusted start (the start-up rule).
  input.not_calibrated = !status_.estimating || !status_.calibrated;
  input.acknowledged = pending_ack_;
  input.acknowledgement = ack_;
  pending_ack_ = false;
  const monitor::AlarmOutput out = alarm_.update(input);
  for (std::size_t i = 0; i < out.event_count && update.event_count < update.events.size(); ++i) {
    update.events[update.event_count++] = out.events[i];
  }
  if (out.acknowledgement != monitor::AckOutcome::kNone) {
    update.acknowledgement = out.acknowledgement;
  }
  status_.alarm = out.level;
  status_.latched = out.latched_level;
  evaluated_ = true;
  report(update);
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

template <typename Message>
void Monitor::add_frame(MonitorUpdate& update, const Message& message) {
  if (update.frame_count >= update.frames.size()) return;  // sized for the most an update has
  if (!can::encode(message, update.frames[update.frame_count]).ok()) {
    ++frames_.not_encoded;
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

MonitorUpdate Monitor::on_tick(std::int64_t receive_time_ns) {
  MonitorUpdate update;
  if (have_epoch_) {
    for (int i = 0; i < sensor_count_; ++i) {
      (void)sensors_[static_cast<std::size_t>(i)].health.tick(receive_time_ns);
    }
    status_.time_ns = monitor_time(receive_time_ns);
    update_primary();
    drain_primary();
    cross_check();
  }
  evaluate(update);
  return update;
}

template <typename Message>
bool Monitor::decoded(const can::CanFrame& frame, Message& message) {
  const can::DecodeResult r = can::decode(frame, message);
  if (r.ok()) return true;
  ++frames_.rejected;
  frames_.last_error = r.error;
  frames_.last_error_signal = r.signal;
  return false;
}

int Monitor::sensor_of_node(std::uint8_t node) const {
  for (int i = 0; i < sensor_count_; ++i) {
    if (sensor_configs_[static_cast<std::size_t>(i)].node == node) return i;
  }
  return -1;
}

MonitorUpdate Monitor::on_frame(const hal::TimedFrame& timed) {
  ++frames_.received;
  MonitorUpdate update;
  if (!take_frame(timed, update)) report_state(update);  // nothing evaluated: a status may be due
  return update;
}

bool Monitor::take_frame(const hal::TimedFrame& timed, MonitorUpdate& update) {
  const can::CanFrame& frame = timed.frame;
  switch (can::classify(frame.id)) {
    case can::MessageKind::kSensorAcceleration: {
      can::SensorAcceleration message;
      if (!decoded(frame, message)) return false;
      const int sensor = sensor_of_node(message.node);
      if (sensor < 0) {
        ++frames_.other_nodes;
        return false;
      }
      ++frames_.sensor_samples;
      take_sample(sensor, sample_of(message, timed.timestamp_ns), update);
      return true;
    }
    case can::MessageKind::kSensorHeartbeat: {
      can::SensorHeartbeat message;
      if (decoded(frame, message)) ++frames_.heartbeats;
      return false;
    }
    case can::MessageKind::kAcknowledge: {
      can::Acknowledge message;
      if (!decoded(frame, message)) return false;
      ++frames_.acknowledgements;
      pending_ack_ = true;
      ack_ = acknowledgement_of(message);
      evaluate(update);  // at once, at the current monitor time
      return true;
    }
    case can::MessageKind::kMonitorStatus: {
      can::MonitorStatus message;
      if (decoded(frame, message)) ++frames_.monitor_frames;
      return false;
    }
    case can::MessageKind::kAlarmEvent: {
      can::AlarmEvent message;
      if (decoded(frame, message)) ++frames_.monitor_frames;
      return false;
    }
    case can::MessageKind::kCollapseForecast: {
      can::CollapseForecast message;
      if (decoded(frame, message)) ++frames_.monitor_frames;
      return false;
    }
    case can::MessageKind::kUnknown:
      ++frames_.unknown_identifiers;
      return false;
  }
  return false;
}

}  // namespace plinth::firmware

#include "plinth/firmware/sensor_set.h"

#include <cmath>

namespace plinth::firmware {

namespace {

int window_length(double window_s, double rate_hz) {
  const long n = std::lround(window_s * rate_hz);
  return n < 2 ? 2 : (n > kMaxCheckWindowSamples ? kMaxCheckWindowSamples : static_cast<int>(n));
}

}  // namespace

void SensorSet::RmsWindow::add(Real square) {
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

Real SensorSet::RmsWindow::rms() const {
  if (count == 0) return 0;
  const Real mean = sum / static_cast<Real>(count);
  return mean > 0 ? std::sqrt(mean) : 0;
}

Error SensorSet::start(const MonitorConfig& config, SensorSetStatus& status) {
  status_ = &status;
  count_ = resolved_sensors(config, configs_);
  status.sensor_count = count_;
  for (int i = 0; i < count_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    SensorConfig& sc = configs_[k];
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
    SensorStatus& st = status.sensors[k];
    st = SensorStatus{};
    st.node = sc.node;
    st.role = sc.role;
    st.health = s.health.health();
    if (sc.role == SensorRole::kPlate) status.plate = i;
  }
  status.sensor = sensors_[0].health.health();
  axis_count_ = config.axis_count;
  redundancy_ = config.redundancy;
  plate_ = config.plate;
  model_ = History{};
  period_ns_ = std::llround(config.estimator.sample_period() * 1e9);
  consumed_ = 0;
  fed_ = false;
  restart_pending_ = false;
  align_pending_ = false;
  last_fed_ns_ = 0;
  return ok_error();
}

void SensorSet::tick(std::int64_t receive_time_ns, int except) {
  for (int j = 0; j < count_; ++j) {
    if (j != except) (void)sensors_[static_cast<std::size_t>(j)].health.tick(receive_time_ns);
  }
}

monitor::SensorUpdate SensorSet::receive(int sensor, const monitor::SensorSample& sample) {
  return sensors_[static_cast<std::size_t>(sensor)].health.on_sample(sample);
}

bool SensorSet::usable(int sensor) const {
  const Sensor& s = sensors_[static_cast<std::size_t>(sensor)];
  return configs_[static_cast<std::size_t>(sensor)].role == SensorRole::kGround &&
         s.health.health().state != monitor::HealthState::kFault && s.conditioner.status().ready &&
         !s.history.empty();
}

void SensorSet::restart_check(int sensor) {
  Sensor& s = sensors_[static_cast<std::size_t>(sensor)];
  s.window.reset();
  s.checked = s.history.pushed;
}

bool SensorSet::condition(int sensor, const monitor::FedSample& sample, bool quiet) {
  Sensor& s = sensors_[static_cast<std::size_t>(sensor)];
  const monitor::ConditionedSample c = s.conditioner.condition(sample.acceleration_g, quiet);
  if (!c.ready) return false;  // start-up window, or refused input (counted by the conditioner)
  const bool trusted_again = c.window_passed && sensor == status_->primary && fed_;
  if (sample.restart) {  // a seam: nothing before it connects, nor compares, to what follows
    s.history.clear();
    restart_check(sensor);
  }
  s.history.push({sample.time_ns, c.ground_m_s2, sample.restart});
  (void)update_primary();
  return trusted_again;
}

bool SensorSet::update_primary() {
  SensorSetStatus& status = *status_;
  if (status.primary >= 0 && usable(status.primary)) return false;
  int candidate = -1;
  for (int i = 0; i < count_ && candidate < 0; ++i) {
    if (usable(i)) candidate = i;
  }
  if (candidate < 0 || candidate == status.primary) return false;
  const History& h = sensors_[static_cast<std::size_t>(candidate)].history;
  if (status.primary >= 0) ++status.failovers;
  status.primary = candidate;
  // The reference changed: every cross-check starts afresh.
  for (int i = 0; i < count_; ++i) {
    restart_check(i);
    SensorStatus& st = status.sensors[static_cast<std::size_t>(i)];
    st.window_full = false;
    st.disagreeing = false;
    st.rms_m_s2 = 0.0;
  }
  // Continue from the estimators' state when the new primary's history holds the stream on
  // from their newest sample within the bridge limit; else start again at rest on its newest.
  const int bridge = configs_[static_cast<std::size_t>(candidate)].sensor_health.max_bridge_samples;
  std::uint64_t next = h.valid_from();
  while (next < h.pushed && h.at(next).time_ns <= last_fed_ns_ + period_ns_ / 2) ++next;
  const bool continues = fed_ && next < h.pushed && !h.at(next).restart &&
                         h.at(next).time_ns - last_fed_ns_ <=
                             static_cast<std::int64_t>(bridge + 1) * period_ns_ + period_ns_ / 2;
  if (continues) {
    consumed_ = next;
    align_pending_ = true;
    restart_pending_ = false;
    if (status.failovers > 0) ++status.failovers_continued;
  } else {
    consumed_ = h.pushed - 1;
    restart_pending_ = true;
    align_pending_ = false;
  }
  return true;
}

bool SensorSet::newest_reading(int sensor, std::uint64_t& seen, ConditionedReading& out) const {
  const History& h = sensors_[static_cast<std::size_t>(sensor)].history;
  if (h.pushed <= seen || h.empty()) return false;
  seen = h.pushed;
  const HistoryEntry& e = h.newest();
  out = {e.time_ns, e.value, e.restart};
  return true;
}

void SensorSet::verify_primary() {
  if (status_->primary < 0) return;
  sensors_[static_cast<std::size_t>(status_->primary)].conditioner.begin_verification();
}

bool SensorSet::next_input(EstimatorInput& input) {
  if (status_->primary < 0) return false;
  Sensor& primary = sensors_[static_cast<std::size_t>(status_->primary)];
  const History& h = primary.history;
  if (consumed_ < h.valid_from()) consumed_ = h.valid_from();
  while (consumed_ < h.pushed) {
    const HistoryEntry& entry = h.at(consumed_++);
    input.time_ns = entry.time_ns;
    input.ground_m_s2 = entry.value;
    input.start = !fed_ || entry.restart || restart_pending_;
    input.calibrated = false;
    input.bridged = 0;
    if (input.start) {
      // Calibrated only on the sample right after a passing window; else verify a new one.
      input.calibrated = primary.conditioner.status().samples_since_window <= 1;
      if (!input.calibrated) primary.conditioner.begin_verification();
      restart_pending_ = false;
      align_pending_ = false;
      model_.clear();
    } else if (align_pending_) {
      // The first sample after a failover: as many sample periods as its time says (the new
      // primary's clock), the ones between bridged.
      align_pending_ = false;
      const double periods =
          static_cast<double>(entry.time_ns - last_fed_ns_) / static_cast<double>(period_ns_);
      const long n = std::lround(periods);
      if (n < 1) continue;  // at or before the estimators' newest sample: taken already
      input.bridged = static_cast<int>(n - 1);
    }
    fed_ = true;
    last_fed_ns_ = entry.time_ns;
    return true;
  }
  return false;
}

void SensorSet::add_model_sample(std::int64_t time_ns, const Vector3r& base_m_s2) {
  model_.push({time_ns, base_m_s2, false});
}

// The reference's value at `time_ns`: interpolated between its samples around it (at most two
// periods apart), else its nearest within one period. False: none.
bool SensorSet::reference_at(const History& reference, std::int64_t time_ns,
                             Vector3r& value) const {
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

void SensorSet::check_sensor(int sensor) {
  const auto k = static_cast<std::size_t>(sensor);
  Sensor& s = sensors_[k];
  SensorStatus& st = status_->sensors[k];
  const bool plate = configs_[k].role == SensorRole::kPlate;
  const History& reference =
      plate ? model_ : sensors_[static_cast<std::size_t>(status_->primary)].history;
  const int components = plate ? axis_count_ : 3;
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
  const double limit = plate ? plate_.threshold_m_s2 : redundancy_.tolerance_m_s2;
  const bool beyond = st.window_full && st.rms_m_s2 > limit;
  if (st.window_full && st.rms_m_s2 > st.max_rms_m_s2) st.max_rms_m_s2 = st.rms_m_s2;
  if (beyond && !st.disagreeing) ++st.disagreements;
  st.disagreeing = beyond;
}

void SensorSet::cross_check() {
  if (count_ < 2 || status_->primary < 0) return;
  for (int i = 0; i < count_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (i == status_->primary) continue;
    if (sensors_[k].health.health().state == monitor::HealthState::kFault) {
      // Not compared while in fault: what it said before no longer counts.
      restart_check(i);
      status_->sensors[k].window_full = false;
      status_->sensors[k].disagreeing = false;
      continue;
    }
    check_sensor(i);
  }
}

void SensorSet::update_status() {
  SensorSetStatus& status = *status_;
  const int reported = status.primary >= 0 ? status.primary : 0;
  status.sensor = sensors_[static_cast<std::size_t>(reported)].health.health();
  bool others_degraded = false;
  bool disagreement = false;
  for (int i = 0; i < count_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    SensorStatus& st = status.sensors[k];
    st.health = sensors_[k].health.health();
    st.ready = sensors_[k].conditioner.status().ready;
    st.primary = i == status.primary;
    if (i == reported) continue;
    others_degraded = others_degraded || st.health.state != monitor::HealthState::kOk;
    disagreement = disagreement || (st.role == SensorRole::kGround && st.disagreeing);
  }
  status.disagreement = disagreement;
  if (status.plate >= 0) {
    const SensorStatus& plate = status.sensors[static_cast<std::size_t>(status.plate)];
    status.plate_residual_m_s2 = plate.rms_m_s2;
    status.plate_mismatch = plate.disagreeing;
  }
  if (status.sensor.state == monitor::HealthState::kFault) {
    status.sensors_state = monitor::HealthState::kFault;
  } else if (status.sensor.state != monitor::HealthState::kOk || others_degraded || disagreement ||
             status.plate_mismatch) {
    status.sensors_state = monitor::HealthState::kDegraded;
  } else {
    status.sensors_state = monitor::HealthState::kOk;
  }
}

}  // namespace plinth::firmware

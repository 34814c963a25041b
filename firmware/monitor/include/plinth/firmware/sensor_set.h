// The box's accelerometers (docs/monitor.md, Sensors): each with its health tracker,
// conditioner and history; the primary ground sensor, whose samples drive the estimators, and
// its failover; the other ground sensors cross-checked against it; the plate sensor checked
// against the model. Freestanding: sized by kMaxSensors, kSensorHistory and
// kMaxCheckWindowSamples (config.h).
#pragma once

#include <array>
#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/real.h"
#include "plinth/firmware/box_status.h"
#include "plinth/firmware/config.h"
#include "plinth/monitor/conditioning.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// One input for the estimators from the primary's history, in order (SensorSet::next_input).
struct EstimatorInput {
  std::int64_t time_ns = 0;  // receive clock
  Vector3r ground_m_s2 = Vector3r::Zero();  // statue frame
  // The estimators start again at rest on it: the first sample, a seam (a sensor fault ended),
  // a failover that cannot continue the stream. Else they take it as their next sample.
  bool start = false;
  // start: their offset and initial state are trusted (a window that passed conditioning's
  // quietness test ends at this sample: the start-up rule, docs/monitor.md); else the primary's
  // conditioner verifies a new window.
  bool calibrated = false;
  // Not start: the sample periods before it that the estimators missed (the first sample of a
  // new primary after a failover, on its own clock), to bridge linearly from their newest one.
  int bridged = 0;
};

// A conditioned sample of one sensor (SensorSet::newest_reading): statue frame, m/s2.
struct ConditionedReading {
  std::int64_t time_ns = 0;  // receive clock
  Vector3r ground_m_s2 = Vector3r::Zero();
  bool restart = false;  // a seam: nothing before it connects to it
};

class SensorSet {
 public:
  SensorSet() = default;
  SensorSet(const SensorSet&) = delete;
  SensorSet& operator=(const SensorSet&) = delete;

  // The sensors of `config` (validate()d; resolved_sensors(): its list or the single-sensor
  // form), at the estimator's sample period. `status` is the box's part this set keeps up to
  // date; it must outlive the set.
  [[nodiscard]] Error start(const MonitorConfig& config, SensorSetStatus& status);

  [[nodiscard]] int count() const { return count_; }
  [[nodiscard]] const SensorConfig& config(int sensor) const {
    return configs_[static_cast<std::size_t>(sensor)];
  }
  [[nodiscard]] const monitor::ConditioningStatus& conditioning(int sensor) const {
    return sensors_[static_cast<std::size_t>(sensor)].conditioner.status();
  }
  [[nodiscard]] bool has_plate() const { return status_->plate >= 0; }

  // Every sensor's timeout at `receive_time_ns` but `except`'s (-1: none): a silent sensor's
  // silence shows on the others' clock, so a silent primary fails over without a tick.
  void tick(std::int64_t receive_time_ns, int except = -1);
  // One sample of `sensor` (its index in configured order): its health tracker's verdict and
  // the samples to feed, which go to condition() in order.
  [[nodiscard]] monitor::SensorUpdate receive(int sensor, const monitor::SensorSample& sample);
  // One fed sample of `sensor`: conditioned (`quiet`: offset tracking allowed) and kept in its
  // history; the primary is then kept or replaced (update_primary). True when it ends a
  // verification window of the primary that passed while the estimators run: they are
  // trusted again.
  [[nodiscard]] bool condition(int sensor, const monitor::FedSample& sample, bool quiet);
  // Keeps the primary while it is usable (a ground sensor, health not fault, offset estimated);
  // else the first usable ground sensor in configured order takes over. After the estimators
  // ran (a failover) they continue on its history when it holds the stream on from their
  // newest sample within the bridge limit ((max_bridge_samples + 1) periods); else they start
  // again at rest on its newest sample. True when the primary changed (the estimators have
  // inputs from the new one).
  bool update_primary();
  // The estimators were started again by the monitor (not on a seam): the primary's conditioner
  // verifies a new quiet window before they are trusted (condition() says when).
  void verify_primary();
  // The newest conditioned sample of `sensor` when there is one newer than `seen` (the
  // caller's count of its samples taken, updated); false otherwise.
  [[nodiscard]] bool newest_reading(int sensor, std::uint64_t& seen,
                                    ConditionedReading& out) const;
  // A ground sensor's reading can be trusted to raise the alarm: not in fault, its offset known.
  [[nodiscard]] bool healthy_ground(int sensor) const { return usable(sensor); }
  // The estimators' next input from the primary's history; false when they have taken all.
  [[nodiscard]] bool next_input(EstimatorInput& input);
  // The model's absolute base acceleration u'' + u_G'' (m/s2, per modelled axis in x, y) at
  // receive time `time_ns`, after the estimators took the input of that time: the plate's
  // reference.
  void add_model_sample(std::int64_t time_ns, const Vector3r& base_m_s2);
  // Pairs the samples each other sensor received since the last call with the reference at
  // the same time (ground: the primary's samples, interpolated; plate: the model's) and
  // updates its RMS window: beyond the tolerance (plate: the threshold) it disagrees.
  void cross_check();
  // The status part: each sensor's health and readiness, the primary's health, disagreement,
  // plate mismatch, and the sensors' state (ok; degraded: a sensor but the primary not ok, a
  // disagreement or a mismatch; fault: the primary's fault).
  void update_status();

 private:
  // A conditioned sample, statue frame, m/s2, at its receive time.
  struct HistoryEntry {
    std::int64_t time_ns = 0;  // receive clock
    Vector3r value = Vector3r::Zero();
    bool restart = false;  // the health tracker's restart mark
  };
  // The last kSensorHistory entries of a stream; entries [valid_from(), pushed) are kept.
  struct History {
    std::array<HistoryEntry, kSensorHistory> entries{};
    std::uint64_t pushed = 0;      // entries ever pushed; the newest is pushed - 1
    std::uint64_t first_kept = 0;  // entries before this were cleared (a seam in the stream)
    [[nodiscard]] std::uint64_t valid_from() const {
      const std::uint64_t held = pushed < kSensorHistory ? 0 : pushed - kSensorHistory;
      return first_kept > held ? first_kept : held;
    }
    [[nodiscard]] bool empty() const { return valid_from() >= pushed; }
    [[nodiscard]] const HistoryEntry& at(std::uint64_t n) const {
      return entries[static_cast<std::size_t>(n % kSensorHistory)];
    }
    [[nodiscard]] const HistoryEntry& newest() const { return at(pushed - 1); }
    void push(const HistoryEntry& e) {
      entries[static_cast<std::size_t>(pushed++ % kSensorHistory)] = e;
    }
    void clear() { first_kept = pushed; }
  };
  // The RMS of a sliding window of squared differences, m/s2, in Real (the sum is taken afresh
  // once per window, so a float build does not drift).
  struct RmsWindow {
    std::array<Real, kMaxCheckWindowSamples> squares{};
    int length = 2;   // samples
    int count = 0;    // samples held, up to length
    int next = 0;     // slot of the next one
    Real sum = 0;
    void reset() { count = 0; next = 0; sum = 0; }
    void add(Real square);
    [[nodiscard]] bool full() const { return count >= length; }
    [[nodiscard]] Real rms() const;
  };
  struct Sensor {
    monitor::SensorHealthTracker health;
    monitor::Conditioner conditioner;
    History history;
    RmsWindow window;
    std::uint64_t checked = 0;  // history entries cross-checked (or found unpairable)
  };

  void check_sensor(int sensor);
  // Forgets `sensor`'s comparison so far: its window, and its history as checked.
  void restart_check(int sensor);
  [[nodiscard]] bool reference_at(const History& reference, std::int64_t time_ns,
                                  Vector3r& value) const;
  [[nodiscard]] bool usable(int sensor) const;

  std::array<SensorConfig, kMaxSensors> configs_{};
  int count_ = 1;
  std::array<Sensor, kMaxSensors> sensors_{};
  SensorSetStatus* status_ = nullptr;
  int axis_count_ = 1;
  RedundancySettings redundancy_;
  PlateCheckSettings plate_;
  History model_;  // the model's base acceleration u'' + u_G'' per axis (the plate's reference)
  std::int64_t period_ns_ = 5'000'000;
  std::uint64_t consumed_ = 0;    // the primary's history entries the estimators took
  bool fed_ = false;              // the estimators took an input since start()
  bool restart_pending_ = false;  // the next entry starts the estimators at rest
  bool align_pending_ = false;    // the next entry continues after a failover: align by time
  std::int64_t last_fed_ns_ = 0;  // receive time of the estimators' newest input
};

}  // namespace plinth::firmware

#include "plinth/monitor/sensor_health.h"

#include <bit>
#include <cmath>
#include <type_traits>

#include "settings_checks.h"

namespace plinth::monitor {

namespace {

// Serial-number arithmetic on the 8-bit counter: how far `to` is ahead of `from`, 0..255.
std::uint8_t sequence_delta(std::uint8_t to, std::uint8_t from) {
  return static_cast<std::uint8_t>(to - from);
}

// Half the counter's range: a delta at or above it reads as behind, not ahead.
constexpr std::uint8_t kSequenceHalfRange = 128;

bool bit_identical(const Vector3r& a, const Vector3r& b) {
  using Bits = std::conditional_t<sizeof(Real) == 8, std::uint64_t, std::uint32_t>;
  for (Eigen::Index i = 0; i < 3; ++i) {
    if (std::bit_cast<Bits>(a[i]) != std::bit_cast<Bits>(b[i])) return false;
  }
  return true;
}

}  // namespace

Error validate(const SensorHealthSettings& s) {
  PLINTH_TRY(detail::first_error({
      detail::check_duration(s.sample_period_s, "sensor_health.sample_period_s", false),
      detail::check_duration(s.timeout_s, "sensor_health.timeout_s", false),
      check_positive(s.full_scale_g, "sensor_health.full_scale_g"),
      check_positive(s.max_valid_g, "sensor_health.max_valid_g"),
  }));
  if (s.max_bridge_samples < 0 || s.max_bridge_samples > kMaxBridgeSamples) {
    return {ErrorCode::kOutOfRange, "sensor_health.max_bridge_samples", "must lie in 0..15",
            static_cast<Real>(kMaxBridgeSamples)};
  }
  const Time longest_bridge_s = (s.max_bridge_samples + 1) * s.sample_period_s;
  if (s.timeout_s <= longest_bridge_s) {
    return {ErrorCode::kInconsistent, "sensor_health.timeout_s",
            "must exceed the longest bridgeable gap, (max_bridge_samples + 1) sample periods",
            longest_bridge_s};
  }
  const Time wrap_s = kSequenceHalfRange * s.sample_period_s;
  if (s.timeout_s >= wrap_s) {
    return {ErrorCode::kInconsistent, "sensor_health.timeout_s",
            "must be shorter than 128 sample periods (the sequence counter's half range)", wrap_s};
  }
  if (s.recovery_samples < 1) {
    return {ErrorCode::kOutOfRange, "sensor_health.recovery_samples", "must be at least 1",
            Real(1)};
  }
  if (s.stuck_samples < 0 || s.stuck_samples == 1) {
    return {ErrorCode::kOutOfRange, "sensor_health.stuck_samples",
            "must be 0 (check off) or at least 2", Real(2)};
  }
  if (s.max_valid_g < s.full_scale_g) {
    return {ErrorCode::kInconsistent, "sensor_health.max_valid_g",
            "must not be below full_scale_g", s.full_scale_g};
  }
  return ok_error();
}

AlarmCause to_alarm_cause(HealthCause cause) {
  switch (cause) {
    case HealthCause::kNone: return AlarmCause::kNone;
    case HealthCause::kNoData:
    case HealthCause::kTimeout: return AlarmCause::kSensorTimeout;
    default: return AlarmCause::kSensorFault;
  }
}

Error SensorHealthTracker::create(const SensorHealthSettings& settings, SensorHealthTracker& out) {
  PLINTH_TRY(validate(settings));
  out = SensorHealthTracker{};
  out.settings_ = settings;
  out.timeout_ns_ = detail::to_ns(settings.timeout_s);
  return ok_error();
}

// Raises the state to `severity` (never lowers it) and restarts the recovery run.
void SensorHealthTracker::note(HealthState severity, HealthCause cause) {
  sample_clean_ = false;
  clean_run_ = 0;
  if (severity > health_.state) {
    if (severity == HealthState::kFault) ++health_.counters.faults;
    health_.state = severity;
    health_.cause = cause;
  } else if (severity == health_.state) {
    health_.cause = cause;
  }
}

// The silence is the fault; the stream re-synchronises on the next sample.
void SensorHealthTracker::declare_timeout() {
  ++health_.counters.timeouts;
  note(HealthState::kFault, HealthCause::kTimeout);
  have_reference_ = false;
  rejected_in_gap_ = 0;
  out_of_order_run_ = 0;
}

const SensorHealth& SensorHealthTracker::tick(std::int64_t now_ns) {
  if (have_reference_ && now_ns - last_accepted_time_ns_ >= timeout_ns_) declare_timeout();
  return health_;
}

// False when the sample is dropped (duplicate, out of order); counts missed numbers otherwise.
bool SensorHealthTracker::check_sequence(std::uint8_t sequence, SampleVerdict& verdict) {
  if (have_reference_) {
    const std::uint8_t delta = sequence_delta(sequence, last_received_sequence_);
    if (delta == 0) {
      ++health_.counters.duplicates;
      note(HealthState::kDegraded, HealthCause::kDuplicate);
      verdict = SampleVerdict::kDuplicate;
      return false;
    }
    if (delta >= kSequenceHalfRange) {
      ++health_.counters.out_of_order;
      verdict = SampleVerdict::kOutOfOrder;
      // A run longer than any gap we would bridge: the node restarted its counter.
      if (++out_of_order_run_ > settings_.max_bridge_samples) {
        note(HealthState::kFault, HealthCause::kOutOfOrder);
        have_reference_ = false;
        out_of_order_run_ = 0;
      } else {
        note(HealthState::kDegraded, HealthCause::kOutOfOrder);
      }
      return false;
    }
    health_.counters.missing += static_cast<std::uint64_t>(delta - 1);
  }
  out_of_order_run_ = 0;
  last_received_sequence_ = sequence;
  return true;
}

HealthCause SensorHealthTracker::value_problem(const SensorSample& sample) const {
  if (!sample.acceleration_g.allFinite()) return HealthCause::kNonFinite;
  if (sample.acceleration_g.cwiseAbs().maxCoeff() > settings_.max_valid_g) {
    return HealthCause::kOutOfRange;
  }
  if ((sample.status & ~sensor_flags::kDefinedMask) != 0) {
    return HealthCause::kUndefinedStatus;
  }
  return HealthCause::kNone;
}

void SensorHealthTracker::check_flags_and_stuck(const SensorSample& sample, bool& saturated) {
  namespace flag = sensor_flags;
  SensorCounters& c = health_.counters;
  saturated = (sample.status & flag::kSaturated) != 0 ||
              sample.acceleration_g.cwiseAbs().maxCoeff() >= settings_.full_scale_g;
  if (saturated) {
    ++c.saturated;
    note(HealthState::kDegraded, HealthCause::kSaturated);
  }
  if ((sample.status & flag::kOverTemperature) != 0) {
    ++c.over_temperature;
    note(HealthState::kDegraded, HealthCause::kOverTemperature);
  }
  if ((sample.status & flag::kSelfTestFailed) != 0) {
    ++c.self_test_failed;
    note(HealthState::kFault, HealthCause::kSelfTestFailed);
  }
  if ((sample.status & flag::kCalibrationInvalid) != 0) {
    ++c.calibration_invalid;
    note(HealthState::kFault, HealthCause::kCalibrationInvalid);
  }
  const bool same = have_reference_ && bit_identical(sample.acceleration_g, last_accepted_g_);
  identical_run_ = same ? identical_run_ + 1 : 1;
  if (settings_.stuck_samples > 0 && identical_run_ >= settings_.stuck_samples) {
    if (identical_run_ == settings_.stuck_samples) ++c.stuck_detections;
    note(HealthState::kFault, HealthCause::kStuck);
  }
}

// Appends the bridged samples (when `bridge_first`) and then the sample itself.
void SensorHealthTracker::feed(SensorUpdate& update, const SensorSample& sample,
                               bool bridge_first, bool restart, bool saturated) {
  if (bridge_first) {
    const int slots = sequence_delta(sample.sequence, last_accepted_sequence_) - 1;
    const std::int64_t elapsed_ns = sample.receive_time_ns - last_accepted_time_ns_;
    const std::int64_t span_ns = elapsed_ns > 0 ? elapsed_ns : 0;  // a clock step back: no time
    for (int k = 1; k <= slots; ++k) {
      FedSample& b = update.fed[update.fed_count++];
      const Real fraction = static_cast<Real>(k) / static_cast<Real>(slots + 1);
      b.time_ns = last_accepted_time_ns_ + span_ns * k / (slots + 1);
      b.sequence = static_cast<std::uint8_t>(last_accepted_sequence_ + k);
      b.acceleration_g = last_accepted_g_ + fraction * (sample.acceleration_g - last_accepted_g_);
      b.bridged = true;
    }
    health_.counters.bridged += static_cast<std::uint64_t>(slots);
  }
  FedSample& f = update.fed[update.fed_count++];
  f.time_ns = sample.receive_time_ns;
  f.sequence = sample.sequence;
  f.acceleration_g = sample.acceleration_g;
  f.restart = restart;
  f.saturated = saturated;
  health_.counters.fed += update.fed_count;
}

SensorUpdate SensorHealthTracker::on_sample(const SensorSample& sample) {
  SensorUpdate update;
  ++health_.counters.received;
  sample_clean_ = true;
  if (have_reference_ && sample.receive_time_ns - last_accepted_time_ns_ >= timeout_ns_) {
    declare_timeout();
    sample_clean_ = true;  // the silence was the fault, not this sample: it may start recovery
  }

  if (!check_sequence(sample.sequence, update.verdict)) {
    update.health = health_;
    return update;
  }

  // Slots between the last accepted sample and this one: missed and rejected numbers.
  const int slots =
      have_reference_ ? sequence_delta(sample.sequence, last_accepted_sequence_) - 1 : 0;

  if (const HealthCause problem = value_problem(sample); problem != HealthCause::kNone) {
    SensorCounters& c = health_.counters;
    if (problem == HealthCause::kNonFinite) ++c.non_finite;
    if (problem == HealthCause::kOutOfRange) ++c.out_of_range;
    if (problem == HealthCause::kUndefinedStatus) ++c.undefined_status;
    ++rejected_in_gap_;
    last_rejection_ = problem;
    // This sample's slot joins the gap: past the bridge limit (or with no stream to bridge
    // from) it is a fault now, not when the next good sample arrives.
    const bool beyond_bridge = !have_reference_ || slots + 1 > settings_.max_bridge_samples;
    note(beyond_bridge ? HealthState::kFault : HealthState::kDegraded, problem);
    update.verdict = SampleVerdict::kRejected;
    update.health = health_;
    return update;
  }

  // The gap closed by this sample belongs to the time before it: it restarts the recovery
  // run, and this sample may be the run's first.
  const bool long_gap = slots > settings_.max_bridge_samples;
  if (long_gap) {
    ++health_.counters.long_gaps;
    note(HealthState::kFault, HealthCause::kSequenceGap);
  } else if (slots > 0) {
    // All the slots rejected samples: keep their cause; else numbers were missed.
    note(HealthState::kDegraded,
         rejected_in_gap_ >= slots ? last_rejection_ : HealthCause::kSequenceGap);
  }
  sample_clean_ = true;

  bool saturated = false;
  check_flags_and_stuck(sample, saturated);

  if (sample_clean_) ++clean_run_;
  const bool was_fault = health_.state == HealthState::kFault;
  if (health_.state != HealthState::kOk && clean_run_ >= settings_.recovery_samples) {
    health_.state = HealthState::kOk;
    health_.cause = HealthCause::kNone;
  }

  if (health_.state == HealthState::kFault) {
    ++health_.counters.held_in_fault;
    update.verdict = SampleVerdict::kHeldInFault;
  } else {
    const bool restart = was_fault;
    feed(update, sample, !restart && slots > 0, restart, saturated);
    update.verdict = SampleVerdict::kFed;
  }

  have_reference_ = true;
  last_accepted_sequence_ = sample.sequence;
  last_accepted_time_ns_ = sample.receive_time_ns;
  last_accepted_g_ = sample.acceleration_g;
  rejected_in_gap_ = 0;
  update.health = health_;
  return update;
}

}  // namespace plinth::monitor

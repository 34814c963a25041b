#include "plinth/monitor/conditioning.h"

#include <cmath>
#include <Eigen/LU>

#include "plinth/core/scene.h"
#include "settings_checks.h"

namespace plinth::monitor {

namespace {

// What a sensor at rest reads in the statue frame, m/s2 (the support pushes up).
Vector3r gravity_up() { return {Real(0), Real(0), kStandardGravity}; }

// A sample count as Real, through double (exact below 2^53): a float build then needs no
// int64-to-float routine (libgcc's comes with its software float addition, about 700 bytes).
Real count_as_real(std::int64_t n) { return static_cast<Real>(static_cast<double>(n)); }

// Samples in the start-up window; validate() checks it is at least 2.
std::int64_t window_length(const ConditioningSettings& s) {
  return static_cast<std::int64_t>(std::llround(s.startup_window_s / s.sample_period_s));
}

Error validate_rotation(const ConditioningSettings& s) {
  const Real tol = s.rotation_tolerance;
  if (!std::isfinite(tol) || tol <= Real(0) || tol > Real(0.1)) {
    return {ErrorCode::kOutOfRange, "conditioning.rotation_tolerance", "must lie in (0, 0.1]",
            Real(0.1)};
  }
  const Matrix3r& r = s.sensor_to_statue;
  if (!r.allFinite()) {
    return {ErrorCode::kNotFinite, "conditioning.sensor_to_statue", "must be finite"};
  }
  const Real orthonormality = (r.transpose() * r - Matrix3r::Identity()).cwiseAbs().maxCoeff();
  if (orthonormality > tol) {
    return {ErrorCode::kInconsistent, "conditioning.sensor_to_statue",
            "is not orthonormal (R^T R - I exceeds rotation_tolerance)", tol};
  }
  const Real det = r.determinant();
  if (std::abs(det - Real(1)) > tol) {
    return {ErrorCode::kInconsistent, "conditioning.sensor_to_statue",
            det < Real(0) ? "has determinant -1: a reflection (an axis reversed), not a rotation"
                          : "has a determinant other than +1",
            Real(1)};
  }
  return ok_error();
}

}  // namespace

Error validate(const ConditioningSettings& s) {
  if (s.unit != AccelerationUnit::kStandardGravity &&
      s.unit != AccelerationUnit::kMetresPerSecondSquared) {
    return {ErrorCode::kOutOfRange, "conditioning.unit", "must be g or m/s2"};
  }
  PLINTH_TRY(detail::first_error({
      validate_rotation(s),
      detail::check_duration(s.sample_period_s, "conditioning.sample_period_s", false),
      detail::check_duration(s.startup_window_s, "conditioning.startup_window_s", false),
      check_positive(s.startup_max_std_m_s2, "conditioning.startup_max_std_m_s2"),
      check_positive(s.startup_max_offset_m_s2, "conditioning.startup_max_offset_m_s2"),
      check_positive(s.startup_max_drift_m_s2, "conditioning.startup_max_drift_m_s2"),
      check_positive(s.startup_gravity_tolerance_m_s2,
                             "conditioning.startup_gravity_tolerance_m_s2"),
      detail::check_duration(s.tracking_time_constant_s, "conditioning.tracking_time_constant_s",
                             false),
      check_positive(s.tracking_gate_m_s2, "conditioning.tracking_gate_m_s2"),
  }));
  // Needs a valid period and window.
  if (window_length(s) < 2) {
    return {ErrorCode::kInconsistent, "conditioning.startup_window_s",
            "must span at least 2 sample periods", 2.0 * s.sample_period_s};
  }
  return ok_error();
}

Error Conditioner::create(const ConditioningSettings& settings, Conditioner& out) {
  PLINTH_TRY(validate(settings));
  out = Conditioner{};
  out.settings_ = settings;
  out.unit_scale_ =
      settings.unit == AccelerationUnit::kStandardGravity ? kStandardGravity : Real(1);
  // The ratio of the settings' doubles, its expm1 in Real (a float build: expm1f, not double's).
  out.tracking_gain_ =
      -std::expm1(static_cast<Real>(-settings.sample_period_s / settings.tracking_time_constant_s));
  out.status_.window_length = window_length(settings);
  return ok_error();
}

void Conditioner::clear_window() {
  status_.window_samples = 0;
  window_mean_.setZero();
  window_m2_.setZero();
  first_half_sum_.setZero();
}

void Conditioner::restart_startup() {
  status_.ready = false;
  status_.verifying = false;
  status_.offset_m_s2.setZero();
  status_.consecutive_gated = 0;
  clear_window();
}

void Conditioner::begin_verification() {
  if (!status_.ready) return;  // the start-up window is the test already
  status_.verifying = true;
  clear_window();
}

Vector3r Conditioner::to_statue_m_s2(const Vector3r& sensor_sample) const {
  return settings_.sensor_to_statue * (unit_scale_ * sensor_sample);
}

// The quietness test of a full window (conditioning.h), its first failed check.
StartupRejection Conditioner::quietness(const Vector3r& offset) const {
  if (status_.window_std_m_s2.maxCoeff() > settings_.startup_max_std_m_s2) {
    return StartupRejection::kTooNoisy;
  }
  if (status_.window_drift_m_s2.cwiseAbs().maxCoeff() > settings_.startup_max_drift_m_s2) {
    return StartupRejection::kDrifting;
  }
  if (std::abs(window_mean_.norm() - kStandardGravity) > settings_.startup_gravity_tolerance_m_s2) {
    return StartupRejection::kNotGravity;
  }
  if (offset.cwiseAbs().maxCoeff() > settings_.startup_max_offset_m_s2) {
    return StartupRejection::kOffsetTooLarge;
  }
  return StartupRejection::kNone;
}

bool Conditioner::add_to_window(const Vector3r& statue_m_s2) {
  const std::int64_t n = ++status_.window_samples;
  const std::int64_t half = status_.window_length / 2;
  if (n <= half) first_half_sum_ += statue_m_s2;
  const Vector3r before = statue_m_s2 - window_mean_;
  window_mean_ += before / count_as_real(n);
  window_m2_ += before.cwiseProduct(statue_m_s2 - window_mean_);
  if (n < status_.window_length) return false;

  status_.window_std_m_s2 = (window_m2_ / count_as_real(n - 1)).cwiseSqrt();
  const Vector3r second_half_sum = window_mean_ * count_as_real(n) - first_half_sum_;
  status_.window_drift_m_s2 =
      second_half_sum / count_as_real(n - half) - first_half_sum_ / count_as_real(half);
  const Vector3r offset = window_mean_ - gravity_up();
  status_.last_rejection = quietness(offset);
  switch (status_.last_rejection) {
    case StartupRejection::kNone:
      ++status_.windows_passed;
      status_.samples_since_window = 0;
      if (!status_.ready) status_.offset_m_s2 = offset;  // a verification keeps the offset
      status_.ready = true;
      status_.verifying = false;
      return true;
    case StartupRejection::kTooNoisy:
      ++status_.rejected_noisy;
      break;
    case StartupRejection::kDrifting:
      ++status_.rejected_drift;
      break;
    case StartupRejection::kNotGravity:
      ++status_.rejected_gravity;
      break;
    case StartupRejection::kOffsetTooLarge:
      ++status_.rejected_offset;
      break;
  }
  clear_window();  // a new window begins (the output stays as it was: ready while verifying)
  return true;
}

ConditionedSample Conditioner::condition(const Vector3r& sensor_sample, bool quiet) {
  ConditionedSample out;
  if (!sensor_sample.allFinite()) {
    ++status_.invalid_inputs;
    out.tracking = OffsetTracking::kInvalidInput;
    return out;
  }
  const Vector3r statue = to_statue_m_s2(sensor_sample);
  if (!status_.ready) {
    (void)add_to_window(statue);
    out.tracking = OffsetTracking::kStartup;
    return out;
  }
  if (status_.verifying) {
    out.window_passed = add_to_window(statue) && status_.last_rejection == StartupRejection::kNone;
  }
  out.ready = true;
  ++status_.samples_since_window;
  out.ground_m_s2 = statue - gravity_up() - status_.offset_m_s2;
  if (!quiet) {
    out.tracking = OffsetTracking::kNotQuiet;
  } else if (out.ground_m_s2.cwiseAbs().maxCoeff() > settings_.tracking_gate_m_s2) {
    ++status_.gated;
    ++status_.consecutive_gated;
    out.tracking = OffsetTracking::kGated;
  } else {
    // The residual is what the offset misses: move toward it by the low-pass gain.
    status_.offset_m_s2 += tracking_gain_ * out.ground_m_s2;
    ++status_.tracked;
    status_.consecutive_gated = 0;
    out.tracking = OffsetTracking::kTracked;
  }
  return out;
}

}  // namespace plinth::monitor

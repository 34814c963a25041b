// Conditioning: one per sensor, between sensor health and the estimators. Turns the sensor's
// samples (its unit, its mounting) into the ground acceleration in the statue frame, m/s2, with
// its offset from a quiet start-up window (docs/monitor-components.md, Conditioning).
// Freestanding: no heap, no exceptions; Eigen fixed-size types.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/name_table.h"
#include "plinth/core/real.h"

namespace plinth::monitor {

// The unit of the sensor's samples. g is standard gravity, 9.80665 m/s2.
enum class AccelerationUnit : std::uint8_t { kStandardGravity = 0, kMetresPerSecondSquared = 1 };

// The units' names in the configuration file.
inline constexpr NameTable<AccelerationUnit, 2> kAccelerationUnitNames{{{
    {AccelerationUnit::kStandardGravity, "g"},
    {AccelerationUnit::kMetresPerSecondSquared, "m/s2"},
}}};

struct ConditioningSettings {
  AccelerationUnit unit = AccelerationUnit::kStandardGravity;
  // Rotation from the sensor frame to the statue frame (statue = R * sensor). Must be
  // orthonormal (every element of R^T R - I within rotation_tolerance) with det R = +1
  // (within rotation_tolerance): a reflection means an axis is wired or declared backwards.
  Matrix3r sensor_to_statue = Matrix3r::Identity();
  Real rotation_tolerance = Real(1e-3);       // dimensionless, in (0, 0.1]
  Time sample_period_s = Real(0.001);         // the stream's sample period, s
  Time startup_window_s = 10.0;               // s, at least 2 samples long
  Real startup_max_std_m_s2 = Real(0.05);     // m/s2, per axis, over the start-up window
  Real startup_max_offset_m_s2 = 1.0;         // m/s2, per axis of the estimated offset
  Real startup_max_drift_m_s2 = Real(0.02);   // m/s2, per axis: second half's mean - first half's
  Real startup_gravity_tolerance_m_s2 = 0.5;  // m/s2: | |window mean| - g0 | at most this
  Time tracking_time_constant_s = 600.0;      // s, of the offset's low-pass while quiet
  Real tracking_gate_m_s2 =
      Real(0.1);  // m/s2: a quiet sample beyond this on an axis is not tracked
};

// Checks the settings; the Error names the field at fault ("conditioning.sensor_to_statue", ...).
[[nodiscard]] Error validate(const ConditioningSettings& settings);

enum class StartupRejection : std::uint8_t {
  kNone = 0,
  kTooNoisy,        // an axis's standard deviation exceeded startup_max_std_m_s2
  kOffsetTooLarge,  // an offset component exceeded startup_max_offset_m_s2
  kDrifting,        // an axis's mean moved more than startup_max_drift_m_s2 across the window
  kNotGravity,      // the mean's norm is not g0 within startup_gravity_tolerance_m_s2
};

// What conditioning did with the offset on one sample.
enum class OffsetTracking : std::uint8_t {
  kStartup,       // the start-up window is still collecting (the sample went into it)
  kNotQuiet,      // the caller said not quiet: offset held
  kGated,         // quiet, but the sample exceeded tracking_gate_m_s2: offset held
  kTracked,       // the offset moved toward this sample
  kInvalidInput,  // non-finite input: refused
};

inline constexpr NameTable<StartupRejection, 5> kStartupRejectionNames{{{
    {StartupRejection::kNone, "none"},
    {StartupRejection::kTooNoisy, "start-up window too noisy"},
    {StartupRejection::kOffsetTooLarge, "offset too large (mounting or unit?)"},
    {StartupRejection::kDrifting, "start-up window drifting"},
    {StartupRejection::kNotGravity, "mean is not 1 g (unit or gain?)"},
}}};

inline constexpr NameTable<OffsetTracking, 5> kOffsetTrackingNames{{{
    {OffsetTracking::kStartup, "start-up"},
    {OffsetTracking::kNotQuiet, "not quiet"},
    {OffsetTracking::kGated, "gated"},
    {OffsetTracking::kTracked, "tracked"},
    {OffsetTracking::kInvalidInput, "invalid input"},
}}};

[[nodiscard]] constexpr const char* startup_rejection_name(StartupRejection rejection) {
  return kStartupRejectionNames.name(rejection);
}
[[nodiscard]] constexpr const char* offset_tracking_name(OffsetTracking tracking) {
  return kOffsetTrackingNames.name(tracking);
}

struct ConditionedSample {
  bool ready = false;  // ground_m_s2 holds a conditioned sample (start-up done, input finite)
  Vector3r ground_m_s2 = Vector3r::Zero();  // statue frame; z is v_G''
  OffsetTracking tracking = OffsetTracking::kStartup;
  bool window_passed = false;  // this sample completed a verification window that passed
};

struct ConditioningStatus {
  bool ready = false;
  std::int64_t window_samples = 0;  // samples in the current start-up window
  std::int64_t window_length = 0;   // samples the window needs
  StartupRejection last_rejection = StartupRejection::kNone;
  std::uint64_t rejected_noisy = 0;   // windows rejected as too noisy
  std::uint64_t rejected_offset = 0;  // windows rejected for too large an offset
  std::uint64_t rejected_drift = 0;   // windows rejected as drifting
  std::uint64_t rejected_gravity = 0;  // windows rejected for a mean that is not 1 g
  std::uint64_t windows_passed = 0;    // windows accepted (start-up and verification)
  bool verifying = false;              // a verification window is collecting (output ready)
  // Ready samples output since the latest passing window ended (1: the sample right after the
  // start-up window, or the one completing a verification window).
  std::uint64_t samples_since_window = 0;
  std::uint64_t invalid_inputs = 0;   // non-finite samples refused
  std::uint64_t tracked = 0;          // samples that moved the offset
  std::uint64_t gated = 0;            // quiet samples the gate kept out
  std::uint64_t consecutive_gated = 0;  // quiet samples gated since the last tracked one
  Vector3r offset_m_s2 = Vector3r::Zero();        // statue frame (valid when ready)
  Vector3r window_std_m_s2 = Vector3r::Zero();    // of the last completed window
  Vector3r window_drift_m_s2 = Vector3r::Zero();  // of the last completed window
};

// The output: x, y the statue's first and second principal horizontal axes, z up and relative
// to gravity (the vertical channel is v_G'' = a_z - g, so g + v_G'' is the model's normal-force
// term):
//   statue = R * (unit_scale * sensor)             R = sensor_to_statue, unit_scale 1 or g0
//   ground = statue - (0, 0, g0) - offset          g0 = 9.80665 m/s2 (kStandardGravity)
//
// Offset: the sensor's bias in the statue frame, the mean of statue - (0, 0, g0) over a
// start-up window of startup_window_s; not ready until a window passes the quietness test (in
// this order, the first failed check the rejection's reason):
//   spread   the standard deviation of every axis <= startup_max_std_m_s2
//   drift    the mean of the window's second half minus its first half's, every axis, within
//            startup_max_drift_m_s2 (a slow onset, a warming sensor)
//   gravity  the mean's norm within startup_gravity_tolerance_m_s2 of g0 (a wrong unit or gain)
//   offset   every offset component within startup_max_offset_m_s2 (a wrong mounting rotation)
// A rejected window is counted with its reason and a new one begins: while the ground shakes
// the output stays not ready, however long that lasts.
//
// Slow tracking: once ready, a first-order low-pass (tracking_time_constant_s) follows the
// offset, on a sample only when the caller says the block is at rest and the ground quiet and
// every component of the sample's output stays within tracking_gate_m_s2: an earthquake, even
// one not noticed yet, is never averaged into the offset; nor is a lasting jump beyond the
// gate (status().consecutive_gated counts the quiet samples it refused).
class Conditioner {
 public:
  Conditioner() = default;

  // Fails on invalid settings (the Error names the field); `out` is then left untouched.
  [[nodiscard]] static Error create(const ConditioningSettings& settings, Conditioner& out);

  // One sample in the sensor frame and the declared unit. `quiet`: the caller's estimate that
  // the block is at rest in full contact and the ground quiet (allows offset tracking).
  // Non-finite input is refused (not ready for that sample, counted); the state is unchanged.
  [[nodiscard]] ConditionedSample condition(const Vector3r& sensor_sample, bool quiet);

  // Forgets the offset and starts a new start-up window (for example after a sensor fault).
  void restart_startup();
  // Once ready: tests a new window for quietness while the output stays ready on the current
  // offset (the monitor's estimators started again without a quiet window just before); the
  // sample completing a passing one is marked window_passed, the offset left as it is.
  void begin_verification();

  // Unit and rotation alone, m/s2 in the statue frame (gravity and offset still in).
  [[nodiscard]] Vector3r to_statue_m_s2(const Vector3r& sensor_sample) const;

  [[nodiscard]] const ConditioningStatus& status() const { return status_; }
  [[nodiscard]] const ConditioningSettings& settings() const { return settings_; }

 private:
  // Adds a sample; true when it completed the window (status_.last_rejection says how).
  [[nodiscard]] bool add_to_window(const Vector3r& statue_m_s2);
  [[nodiscard]] StartupRejection quietness(const Vector3r& offset) const;
  void clear_window();

  ConditioningSettings settings_;
  Real unit_scale_ = 1.0;     // sensor unit to m/s2
  Real tracking_gain_ = 0.0;  // the low-pass's per-sample gain, 1 - exp(-period / tau)
  ConditioningStatus status_;
  // Running mean and sum of squared deviations of the window (Welford), statue frame, m/s2.
  Vector3r window_mean_ = Vector3r::Zero();
  Vector3r window_m2_ = Vector3r::Zero();
  Vector3r first_half_sum_ = Vector3r::Zero();  // statue frame, m/s2
};

}  // namespace plinth::monitor

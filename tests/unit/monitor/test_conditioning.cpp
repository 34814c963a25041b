// Conditioning: units, mounting rotation, the start-up offset window, and slow offset tracking
// (an hour of drifting quiet is followed; an earthquake is not swallowed).
#include "plinth/monitor/conditioning.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>

#include "plinth/core/scene.h"
#include "settings_support.h"

namespace plinth::monitor {
namespace {

constexpr double kG0 = kStandardGravity;  // m/s2

Conditioner make(const ConditioningSettings& s) {
  Conditioner c;
  const Error e = Conditioner::create(s, c);
  EXPECT_TRUE(e.ok()) << e.field << ": " << e.reason;
  return c;
}

// A tilted mounting: the sensor turned 0.3 rad about an oblique axis.
Eigen::Matrix3d tilted() {
  return Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
}

// What a sensor mounted with `r` reads, in g, for a ground acceleration (statue frame, m/s2,
// z relative to gravity) and a sensor bias (sensor frame, g).
Eigen::Vector3d reading_g(const Eigen::Matrix3d& r, const Eigen::Vector3d& ground_m_s2,
                          const Eigen::Vector3d& bias_g) {
  const Eigen::Vector3d statue = ground_m_s2 + Eigen::Vector3d(0.0, 0.0, kG0);
  return r.transpose() * statue / kG0 + bias_g;
}

// ---------------------------------------------------------------------------------------------
// Settings

// create() validates: the Error names the field and says what is wrong.
void expect_refused(const ConditioningSettings& s, const char* field, ErrorCode code,
                    const char* reason_part = "") {
  plinth::testing::expect_create_refused<Conditioner>(s, field, code, reason_part);
}

TEST(ConditioningSettings, DefaultsAreValidAndEveryFieldIsChecked) {
  EXPECT_TRUE(validate(ConditioningSettings{}).ok());
  ConditioningSettings s;
  s.unit = static_cast<AccelerationUnit>(7);
  expect_refused(s, "conditioning.unit", ErrorCode::kOutOfRange);
  s = {};
  s.rotation_tolerance = 0.0;
  expect_refused(s, "conditioning.rotation_tolerance", ErrorCode::kOutOfRange);
  s = {};
  s.sample_period_s = -0.001;
  expect_refused(s, "conditioning.sample_period_s", ErrorCode::kOutOfRange);
  s = {};
  s.sample_period_s = 0.01;
  s.startup_window_s = 0.014;  // 1.4 periods: rounds to 1 sample
  expect_refused(s, "conditioning.startup_window_s", ErrorCode::kInconsistent);
  s.startup_window_s = 0.015;  // rounds to 2
  EXPECT_TRUE(validate(s).ok());
  s = {};
  s.startup_max_std_m_s2 = 0.0;
  expect_refused(s, "conditioning.startup_max_std_m_s2", ErrorCode::kOutOfRange);
  s = {};
  s.startup_max_offset_m_s2 = std::numeric_limits<double>::infinity();
  expect_refused(s, "conditioning.startup_max_offset_m_s2", ErrorCode::kNotFinite);
  s = {};
  s.startup_max_drift_m_s2 = -0.1;
  expect_refused(s, "conditioning.startup_max_drift_m_s2", ErrorCode::kOutOfRange);
  s = {};
  s.startup_gravity_tolerance_m_s2 = std::numeric_limits<double>::quiet_NaN();
  expect_refused(s, "conditioning.startup_gravity_tolerance_m_s2", ErrorCode::kNotFinite);
  s = {};
  s.tracking_time_constant_s = 0.0;
  expect_refused(s, "conditioning.tracking_time_constant_s", ErrorCode::kOutOfRange);
  s = {};
  s.tracking_gate_m_s2 = -0.1;
  expect_refused(s, "conditioning.tracking_gate_m_s2", ErrorCode::kOutOfRange);
}

TEST(ConditioningSettings, RotationMustBeOrthonormalWithDeterminantPlusOne) {
  ConditioningSettings s;  // tolerance 1e-3
  s.sensor_to_statue = tilted();
  EXPECT_TRUE(validate(s).ok());
  s.sensor_to_statue(0, 1) += 4e-4;  // a survey's rounding: within tolerance
  EXPECT_TRUE(validate(s).ok());

  s.sensor_to_statue = 1.001 * Eigen::Matrix3d::Identity();  // R^T R - I = 0.002 on the diagonal
  expect_refused(s, "conditioning.sensor_to_statue", ErrorCode::kInconsistent, "orthonormal");
  s.sensor_to_statue = 1.0003 * Eigen::Matrix3d::Identity();  // 0.0006, det 1.0009: within
  EXPECT_TRUE(validate(s).ok());

  s.sensor_to_statue = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();  // z wired backwards
  expect_refused(s, "conditioning.sensor_to_statue", ErrorCode::kInconsistent, "determinant -1");
  s.sensor_to_statue = tilted();
  s.sensor_to_statue.col(0).swap(s.sensor_to_statue.col(1));  // x and y swapped: a reflection
  expect_refused(s, "conditioning.sensor_to_statue", ErrorCode::kInconsistent, "determinant -1");

  s.sensor_to_statue = Eigen::Matrix3d::Identity();
  s.sensor_to_statue(2, 0) = std::numeric_limits<double>::quiet_NaN();
  expect_refused(s, "conditioning.sensor_to_statue", ErrorCode::kNotFinite);
}

// ---------------------------------------------------------------------------------------------
// Units and rotation

TEST(Conditioning, UnitsAndRotationToTheStatueFrame) {
  ConditioningSettings s;
  s.sensor_to_statue << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // +90 degrees about z: sensor x is statue y
  const Conditioner in_g = make(s);
  const Eigen::Vector3d statue = in_g.to_statue_m_s2({1.0, 0.0, 0.5});
  EXPECT_NEAR(statue.x(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(statue.y(), 9.80665);
  EXPECT_DOUBLE_EQ(statue.z(), 0.5 * 9.80665);
  s.unit = AccelerationUnit::kMetresPerSecondSquared;
  const Conditioner in_si = make(s);
  EXPECT_TRUE(in_si.to_statue_m_s2({0.0, -2.0, 3.0}).isApprox(Eigen::Vector3d(2.0, 0.0, 3.0)));
}

// ---------------------------------------------------------------------------------------------
// Start-up window

ConditioningSettings ten_sample_window() {
  ConditioningSettings s;
  s.sample_period_s = 0.01;
  s.startup_window_s = 0.1;  // 10 samples
  return s;
}

TEST(Conditioning, NotReadyUntilTheWindowIsFullThenTheOffsetIsItsMean) {
  Conditioner c = make(ten_sample_window());
  EXPECT_EQ(c.status().window_length, 10);
  const Eigen::Vector3d bias_g(0.002, -0.003, 0.004);
  for (int i = 0; i < 10; ++i) {
    const double wobble = i % 2 == 0 ? 0.001 : -0.001;  // the window's mean keeps the bias
    const ConditionedSample out =
        c.condition(bias_g + Eigen::Vector3d(0.0, 0.0, 1.0 + wobble), true);
    EXPECT_FALSE(out.ready) << i;
    EXPECT_EQ(out.tracking, OffsetTracking::kStartup);
    EXPECT_EQ(c.status().ready, i == 9) << i;
  }
  EXPECT_TRUE(c.status().offset_m_s2.isApprox(kG0 * bias_g, 1e-12));
  EXPECT_NEAR(c.status().window_std_m_s2.z(), 0.001 * kG0 * std::sqrt(10.0 / 9.0), 1e-12);
  EXPECT_NEAR(c.status().window_std_m_s2.x(), 0.0, 1e-15);

  // The vertical channel is relative to gravity: v_G'' = a_z - g.
  const ConditionedSample out = c.condition(bias_g + Eigen::Vector3d(0.1, 0.0, 1.05), false);
  ASSERT_TRUE(out.ready);
  EXPECT_NEAR(out.ground_m_s2.x(), 0.1 * kG0, 1e-12);
  EXPECT_NEAR(out.ground_m_s2.y(), 0.0, 1e-12);
  EXPECT_NEAR(out.ground_m_s2.z(), 0.05 * kG0, 1e-12);
}

TEST(Conditioning, TiltedMountingRecoversTheGroundAcceleration) {
  ConditioningSettings s = ten_sample_window();
  s.sensor_to_statue = tilted();
  Conditioner c = make(s);
  const Eigen::Vector3d bias_g(0.003, 0.001, -0.002);
  const Eigen::Vector3d at_rest = reading_g(s.sensor_to_statue, {0, 0, 0}, bias_g);
  for (int i = 0; i < 10; ++i) (void)c.condition(at_rest, true);
  ASSERT_TRUE(c.status().ready);
  // The offset is the bias seen in the statue frame.
  EXPECT_TRUE(c.status().offset_m_s2.isApprox(kG0 * (s.sensor_to_statue * bias_g), 1e-10));
  const Eigen::Vector3d ground(0.7, -0.4, 0.25);
  const ConditionedSample out = c.condition(reading_g(s.sensor_to_statue, ground, bias_g), false);
  EXPECT_LT((out.ground_m_s2 - ground).cwiseAbs().maxCoeff(), 1e-12);
}

// Alternating +-a: the sample standard deviation of 10 samples is a sqrt(10/9).
void fill_window_alternating(Conditioner& c, double a_m_s2) {
  for (int i = 0; i < 10; ++i) {
    (void)c.condition({0.0, 0.0, kG0 + (i % 2 == 0 ? a_m_s2 : -a_m_s2)}, true);
  }
}

TEST(Conditioning, WindowStandardDeviationBoundary) {
  ConditioningSettings s = ten_sample_window();
  s.unit = AccelerationUnit::kMetresPerSecondSquared;
  s.startup_max_std_m_s2 = 0.05;
  const double at_limit = 0.05 / std::sqrt(10.0 / 9.0);
  {
    Conditioner c = make(s);
    fill_window_alternating(c, at_limit * (1.0 - 1e-6));
    EXPECT_TRUE(c.status().ready);
    EXPECT_EQ(c.status().rejected_noisy, 0U);
  }
  Conditioner c = make(s);
  fill_window_alternating(c, at_limit * (1.0 + 1e-6));
  EXPECT_FALSE(c.status().ready);
  EXPECT_EQ(c.status().rejected_noisy, 1U);
  EXPECT_EQ(c.status().last_rejection, StartupRejection::kTooNoisy);
  EXPECT_EQ(c.status().window_samples, 0);  // restarted
  fill_window_alternating(c, 0.01);          // the ground calmed down
  EXPECT_TRUE(c.status().ready);
  EXPECT_EQ(c.status().rejected_noisy, 1U);
}

TEST(Conditioning, WindowWithGravityInTheWrongPlaceIsRejected) {
  // Declared m/s2, sent in g: gravity reads 1 instead of 9.8 (the mean's norm is not g0).
  ConditioningSettings s = ten_sample_window();
  s.unit = AccelerationUnit::kMetresPerSecondSquared;
  Conditioner wrong_unit = make(s);
  for (int i = 0; i < 10; ++i) (void)wrong_unit.condition({0.0, 0.0, 1.0}, true);
  EXPECT_FALSE(wrong_unit.status().ready);
  EXPECT_EQ(wrong_unit.status().last_rejection, StartupRejection::kNotGravity);
  EXPECT_EQ(wrong_unit.status().rejected_gravity, 1U);

  // A gain 6 % high: every offset component within its limit (z: 0.59 m/s2 < 1), the norm not.
  s = ten_sample_window();
  Conditioner wrong_gain = make(s);
  for (int i = 0; i < 10; ++i) (void)wrong_gain.condition({0.0, 0.0, 1.06}, true);
  EXPECT_FALSE(wrong_gain.status().ready);
  EXPECT_EQ(wrong_gain.status().last_rejection, StartupRejection::kNotGravity);
  s.startup_gravity_tolerance_m_s2 = 0.6;  // named threshold: 0.59 m/s2 is then within it
  Conditioner tolerant = make(s);
  for (int i = 0; i < 10; ++i) (void)tolerant.condition({0.0, 0.0, 1.06}, true);
  EXPECT_TRUE(tolerant.status().ready);

  // A mounting rotation that puts the sensor's z (up) on the statue's y.
  s = ten_sample_window();
  s.sensor_to_statue = Eigen::AngleAxisd(-std::numbers::pi / 2.0, Eigen::Vector3d::UnitX());
  Conditioner wrong_rotation = make(s);
  for (int i = 0; i < 10; ++i) (void)wrong_rotation.condition({0.0, 0.0, 1.0}, true);
  EXPECT_FALSE(wrong_rotation.status().ready);
  EXPECT_EQ(wrong_rotation.status().last_rejection, StartupRejection::kOffsetTooLarge);
}

// A slow onset: x ramps by 0.1 m/s2 across the window. Its spread (0.03 m/s2) passes, its
// drift (the halves' means 0.05 m/s2 apart) does not; the same window flat passes.
TEST(Conditioning, DriftingWindowIsRejected) {
  ConditioningSettings s = ten_sample_window();
  s.unit = AccelerationUnit::kMetresPerSecondSquared;
  Conditioner c = make(s);
  for (int i = 0; i < 10; ++i) (void)c.condition({0.1 * i / 9.0, 0.0, kG0}, true);
  EXPECT_FALSE(c.status().ready);
  EXPECT_EQ(c.status().last_rejection, StartupRejection::kDrifting);
  EXPECT_EQ(c.status().rejected_drift, 1U);
  EXPECT_LT(c.status().window_std_m_s2.x(), s.startup_max_std_m_s2);
  EXPECT_NEAR(c.status().window_drift_m_s2.x(), 0.1 * 5.0 / 9.0, 1e-12);
  for (int i = 0; i < 10; ++i) (void)c.condition({0.05, 0.0, kG0}, true);
  EXPECT_TRUE(c.status().ready);
  EXPECT_EQ(c.status().windows_passed, 1U);
  EXPECT_NEAR(c.status().offset_m_s2.x(), 0.05, 1e-12);
}

// Verification: the output stays ready on the offset while a new window is tested; a noisy
// window is rejected (counted), a quiet one marks the sample that completes it and keeps the
// offset.
TEST(Conditioning, VerificationWindowKeepsTheOutputAndTheOffset) {
  ConditioningSettings s = ten_sample_window();
  s.unit = AccelerationUnit::kMetresPerSecondSquared;
  Conditioner c = make(s);
  c.begin_verification();  // not ready: the start-up window is the test already
  EXPECT_FALSE(c.status().verifying);
  for (int i = 0; i < 10; ++i) (void)c.condition({0.02, 0.0, kG0}, false);
  ASSERT_TRUE(c.status().ready);
  EXPECT_EQ(c.status().samples_since_window, 0U);
  EXPECT_EQ(c.condition({0.02, 0.0, kG0}, false).ground_m_s2.x(), 0.0);
  EXPECT_EQ(c.status().samples_since_window, 1U);
  c.begin_verification();
  EXPECT_TRUE(c.status().verifying);
  for (int i = 0; i < 10; ++i) {
    const ConditionedSample out = c.condition({i % 2 == 0 ? 1.0 : -1.0, 0.0, kG0}, false);
    EXPECT_TRUE(out.ready);
    EXPECT_FALSE(out.window_passed);
  }
  EXPECT_EQ(c.status().rejected_noisy, 1U);
  EXPECT_TRUE(c.status().verifying);
  for (int i = 0; i < 10; ++i) {
    const ConditionedSample out = c.condition({0.03, 0.0, kG0}, false);
    EXPECT_TRUE(out.ready);
    EXPECT_EQ(out.window_passed, i == 9);
  }
  EXPECT_FALSE(c.status().verifying);
  EXPECT_EQ(c.status().windows_passed, 2U);
  EXPECT_EQ(c.status().samples_since_window, 1U);
  EXPECT_NEAR(c.status().offset_m_s2.x(), 0.02, 1e-15);  // kept: tracking follows it, if quiet
}

TEST(Conditioning, NonFiniteInputIsRefusedAndChangesNothing) {
  Conditioner c = make(ten_sample_window());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const ConditionedSample out = c.condition({0.0, nan, 1.0}, true);
  EXPECT_FALSE(out.ready);
  EXPECT_EQ(out.tracking, OffsetTracking::kInvalidInput);
  EXPECT_EQ(c.status().window_samples, 0);
  EXPECT_EQ(c.status().invalid_inputs, 1U);
  for (int i = 0; i < 10; ++i) (void)c.condition({0.0, 0.0, 1.0}, true);
  ASSERT_TRUE(c.status().ready);
  const Eigen::Vector3d offset = c.status().offset_m_s2;
  EXPECT_EQ(c.condition({nan, 0.0, 1.0}, true).tracking, OffsetTracking::kInvalidInput);
  EXPECT_EQ(c.status().offset_m_s2, offset);
  c.restart_startup();
  EXPECT_FALSE(c.status().ready);
  EXPECT_FALSE(c.condition({0.0, 0.0, 1.0}, true).ready);
}

// ---------------------------------------------------------------------------------------------
// Offset tracking

// One hour at 100 Hz of quiet ground (sensor noise only) while the sensor's bias drifts
// linearly; returns the largest error of the offset estimate (statue frame, m/s2) after the
// first 5 time constants, and the final error vector.
struct DriftRun {
  double max_error_m_s2 = 0.0;
  Eigen::Vector3d final_error_m_s2 = Eigen::Vector3d::Zero();
};

DriftRun run_drifting_hour(bool quiet) {
  ConditioningSettings s;
  s.sensor_to_statue = tilted();
  s.sample_period_s = 0.01;
  s.startup_window_s = 10.0;
  s.tracking_time_constant_s = 60.0;
  Conditioner c = make(s);
  const Eigen::Vector3d bias0_g(0.002, -0.001, 0.003);
  const Eigen::Vector3d drift_g_per_h(0.005, -0.003, 0.004);  // temperature drift
  std::mt19937 rng(4);
  std::normal_distribution<double> noise_g(0.0, 0.0005);  // about 5 mm/s2
  DriftRun run;
  const int samples = 10 * 100 + 3600 * 100;
  for (int i = 0; i < samples; ++i) {
    const double t_h = static_cast<double>(i) * 0.01 / 3600.0;
    const Eigen::Vector3d bias_g = bias0_g + t_h * drift_g_per_h;
    const Eigen::Vector3d noise(noise_g(rng), noise_g(rng), noise_g(rng));
    (void)c.condition(reading_g(s.sensor_to_statue, {0, 0, 0}, bias_g) + noise, quiet);
    if (i < 1000 + 5 * 6000) continue;  // start-up, then 5 time constants to settle
    const Eigen::Vector3d error = c.status().offset_m_s2 - kG0 * (s.sensor_to_statue * bias_g);
    run.max_error_m_s2 = std::max(run.max_error_m_s2, error.cwiseAbs().maxCoeff());
    run.final_error_m_s2 = error;
  }
  EXPECT_TRUE(c.status().ready);
  return run;
}

TEST(Conditioning, SlowDriftOverAnHourOfQuietIsFollowed) {
  const DriftRun tracked = run_drifting_hour(true);
  // A first-order low-pass lags a ramp by rate * tau: the drift seen in the statue frame is at
  // most 0.0062 g/h on an axis, so 0.0062 g/h * 60 s = 1.0e-3 m/s2; the noise adds about 5e-5.
  const Eigen::Vector3d lag =
      -kG0 * (tilted() * Eigen::Vector3d(0.005, -0.003, 0.004)) * 60.0 / 3600.0;
  EXPECT_NEAR(lag.cwiseAbs().maxCoeff(), 1.006e-3, 1e-6);
  EXPECT_LT(tracked.max_error_m_s2, 1.3e-3);
  EXPECT_LT((tracked.final_error_m_s2 - lag).cwiseAbs().maxCoeff(), 2e-4);

  // Without tracking the start-up offset is an hour stale: errors of several cm/s2.
  const DriftRun stale = run_drifting_hour(false);
  EXPECT_GT(stale.max_error_m_s2, 0.04);
}

// Settles a conditioner on exact quiet input (no noise, no bias).
Conditioner settled(double gate_m_s2) {
  ConditioningSettings s;
  s.unit = AccelerationUnit::kMetresPerSecondSquared;
  s.sample_period_s = 0.01;
  s.startup_window_s = 1.0;
  s.tracking_time_constant_s = 600.0;
  s.tracking_gate_m_s2 = gate_m_s2;
  Conditioner c = make(s);
  for (int i = 0; i < 100; ++i) (void)c.condition({0.0, 0.0, kG0}, true);
  EXPECT_TRUE(c.status().ready);
  return c;
}

TEST(Conditioning, EarthquakeBurstIsNotSwallowedEvenWhenTheCallerSaysQuiet) {
  for (const bool quiet : {false, true}) {
    Conditioner c = settled(0.1);
    double peak_x = 0.0;
    double worst_error = 0.0;
    for (int i = 0; i < 2000; ++i) {  // 20 s
      const double t = static_cast<double>(i) * 0.01;
      const Eigen::Vector3d ground(2.0 * std::sin(2.0 * std::numbers::pi * 1.5 * t),
                                   1.0 * std::sin(2.0 * std::numbers::pi * 0.8 * t),
                                   0.5 * std::sin(2.0 * std::numbers::pi * 3.0 * t));
      const ConditionedSample out = c.condition(ground + Eigen::Vector3d(0.0, 0.0, kG0), quiet);
      peak_x = std::max(peak_x, out.ground_m_s2.x());
      worst_error = std::max(worst_error, (out.ground_m_s2 - ground).cwiseAbs().maxCoeff());
    }
    EXPECT_NEAR(peak_x, 2.0, 1e-3) << quiet;
    EXPECT_LT(worst_error, 1e-6) << quiet;
    EXPECT_LT(c.status().offset_m_s2.cwiseAbs().maxCoeff(), 1e-6) << quiet;
    if (quiet) {
      EXPECT_GT(c.status().gated, 1900U);
    }
  }
}

TEST(Conditioning, LongOneSidedPushIsGatedNotAbsorbed) {
  // 0.5 m/s2 on x for one time constant (600 s), the caller wrongly saying quiet throughout.
  Conditioner gated = settled(0.1);
  Conditioner ungated = settled(10.0);
  ConditionedSample last_gated;
  ConditionedSample last_ungated;
  for (int i = 0; i < 60000; ++i) {
    last_gated = gated.condition({0.5, 0.0, kG0}, true);
    last_ungated = ungated.condition({0.5, 0.0, kG0}, true);
  }
  EXPECT_DOUBLE_EQ(last_gated.ground_m_s2.x(), 0.5);
  EXPECT_EQ(last_gated.tracking, OffsetTracking::kGated);
  EXPECT_EQ(gated.status().consecutive_gated, 60000U);  // for the caller to notice
  // Without the gate a time constant of tracking takes 1 - 1/e of the push away.
  EXPECT_NEAR(last_ungated.ground_m_s2.x(), 0.5 * std::exp(-1.0), 1e-3);
  EXPECT_EQ(last_ungated.tracking, OffsetTracking::kTracked);
}

TEST(Conditioning, NoTrackingWhenNotQuiet) {
  Conditioner c = settled(0.1);
  const ConditionedSample out = c.condition({0.05, 0.0, kG0}, false);
  EXPECT_EQ(out.tracking, OffsetTracking::kNotQuiet);
  EXPECT_EQ(c.status().offset_m_s2, Eigen::Vector3d::Zero());
  const ConditionedSample tracked = c.condition({0.05, 0.0, kG0}, true);
  EXPECT_EQ(tracked.tracking, OffsetTracking::kTracked);
  EXPECT_NEAR(c.status().offset_m_s2.x(), 0.05 * -std::expm1(-0.01 / 600.0), 1e-18);
  EXPECT_STREQ(offset_tracking_name(OffsetTracking::kGated), "gated");
  EXPECT_STREQ(startup_rejection_name(StartupRejection::kTooNoisy), "start-up window too noisy");
}

}  // namespace
}  // namespace plinth::monitor

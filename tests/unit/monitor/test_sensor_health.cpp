// Sensor health: sequence gaps and their bridging, duplicates, out-of-order samples, timeouts,
// bad values, status flags, stuck sensors, and what the solver is fed across a fault.
#include "plinth/monitor/sensor_health.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "settings_support.h"

namespace plinth::monitor {
namespace {

constexpr std::int64_t kPeriodNs = 1'000'000;   // 1 ms, the default sample_period_s
constexpr std::int64_t kTimeoutNs = 50'000'000;  // the default timeout_s
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Sample n of a noisy node at rest: time n ms, sequence n mod 256, never two alike.
SensorSample nth_sample(std::int64_t n, std::uint8_t status = 0) {
  SensorSample s;
  s.receive_time_ns = n * kPeriodNs;
  s.sequence = static_cast<std::uint8_t>(n % 256);
  s.status = status;
  const double x = static_cast<double>(n);
  s.acceleration_g = {0.01 * std::sin(0.7 * x), 0.01 * std::cos(1.3 * x),
                      1.0 + 0.01 * std::sin(2.1 * x)};
  return s;
}

// A tracker fed sample after sample of nth_sample, from `first`.
class Stream {
 public:
  explicit Stream(const SensorHealthSettings& settings = {}, std::int64_t first = 0) : n(first) {
    const Error e = SensorHealthTracker::create(settings, tracker);
    EXPECT_TRUE(e.ok()) << e.field << ": " << e.reason;
  }

  SensorUpdate next(std::uint8_t status = 0) { return tracker.on_sample(nth_sample(n++, status)); }
  SensorUpdate next_with(const Eigen::Vector3d& g, std::uint8_t status = 0) {
    SensorSample s = nth_sample(n++, status);
    s.acceleration_g = g;
    return tracker.on_sample(s);
  }
  // Drops `count` samples (never sent), then sends the next.
  SensorUpdate skip(int count) {
    n += count;
    return next();
  }
  // Clears the initial no-data fault.
  void warm_up() {
    for (int i = 0; i < tracker.settings().recovery_samples; ++i) (void)next();
    ASSERT_EQ(tracker.health().state, HealthState::kOk);
  }
  [[nodiscard]] const SensorCounters& counters() const { return tracker.health().counters; }

  SensorHealthTracker tracker;
  std::int64_t n;
};

SensorHealthSettings with_recovery(int samples) {
  SensorHealthSettings s;
  s.recovery_samples = samples;
  return s;
}

// ---------------------------------------------------------------------------------------------
// Settings

// create() validates: the Error names the field.
void expect_refused(const SensorHealthSettings& s, const char* field, ErrorCode code) {
  plinth::testing::expect_create_refused<SensorHealthTracker>(s, field, code);
}

TEST(SensorHealthSettings, DefaultsAreValidAndEveryFieldIsChecked) {
  EXPECT_TRUE(validate(SensorHealthSettings{}).ok());
  SensorHealthSettings s;
  s.sample_period_s = 0.0;
  expect_refused(s, "sensor_health.sample_period_s", ErrorCode::kOutOfRange);
  s = {};
  s.timeout_s = kNaN;
  expect_refused(s, "sensor_health.timeout_s", ErrorCode::kNotFinite);
  s = {};
  s.max_bridge_samples = 16;
  expect_refused(s, "sensor_health.max_bridge_samples", ErrorCode::kOutOfRange);
  s = {};
  s.max_bridge_samples = -1;
  expect_refused(s, "sensor_health.max_bridge_samples", ErrorCode::kOutOfRange);
  s = {};
  s.recovery_samples = 0;
  expect_refused(s, "sensor_health.recovery_samples", ErrorCode::kOutOfRange);
  s = {};
  s.stuck_samples = 1;
  expect_refused(s, "sensor_health.stuck_samples", ErrorCode::kOutOfRange);
  s = {};
  s.full_scale_g = -2.0;
  expect_refused(s, "sensor_health.full_scale_g", ErrorCode::kOutOfRange);
  s = {};
  s.max_valid_g = 7.9;  // below full scale 8
  expect_refused(s, "sensor_health.max_valid_g", ErrorCode::kInconsistent);
  s = {};
  s.stuck_samples = 0;  // off
  EXPECT_TRUE(validate(s).ok());
}

TEST(SensorHealthSettings, TimeoutMustExceedTheLongestBridgeAndStayBelowTheCounterWrap) {
  SensorHealthSettings s;  // 1 ms period, bridge 3: the longest bridged gap spans 4 ms
  s.timeout_s = 0.004;
  expect_refused(s, "sensor_health.timeout_s", ErrorCode::kInconsistent);
  s.timeout_s = 0.0041;
  EXPECT_TRUE(validate(s).ok());
  s.timeout_s = 0.128;  // 128 periods: a silence could hide behind the 8-bit wrap
  expect_refused(s, "sensor_health.timeout_s", ErrorCode::kInconsistent);
  EXPECT_DOUBLE_EQ(validate(s).limit, 0.128);
  s.timeout_s = 0.127;
  EXPECT_TRUE(validate(s).ok());
}

// ---------------------------------------------------------------------------------------------
// Start-up and the plain stream

TEST(SensorHealth, StartsInFaultAndTheFirstFedSampleIsARestart) {
  Stream st(with_recovery(3));
  EXPECT_EQ(st.tracker.health().state, HealthState::kFault);
  EXPECT_EQ(st.tracker.health().cause, HealthCause::kNoData);
  EXPECT_EQ(st.next().verdict, SampleVerdict::kHeldInFault);
  EXPECT_EQ(st.next().verdict, SampleVerdict::kHeldInFault);
  const SensorUpdate third = st.next();
  ASSERT_EQ(third.verdict, SampleVerdict::kFed);
  ASSERT_EQ(third.fed_count, 1U);
  EXPECT_TRUE(third.fed[0].restart);
  EXPECT_EQ(third.fed[0].sequence, 2);
  EXPECT_EQ(third.health.state, HealthState::kOk);
  EXPECT_EQ(third.health.cause, HealthCause::kNone);
  const SensorUpdate fourth = st.next();
  ASSERT_EQ(fourth.fed_count, 1U);
  EXPECT_FALSE(fourth.fed[0].restart);
  EXPECT_FALSE(fourth.fed[0].bridged);
  EXPECT_EQ(st.counters().held_in_fault, 2U);
  EXPECT_EQ(st.counters().fed, 2U);
  EXPECT_EQ(st.counters().faults, 0U);  // it started in fault
}

TEST(SensorHealth, SequenceWrapFrom255To0IsInSequence) {
  Stream st({}, 240);
  st.warm_up();  // samples 240..249
  for (int i = 0; i < 20; ++i) {  // 250..255, 0..13
    const SensorUpdate u = st.next();
    ASSERT_EQ(u.fed_count, 1U) << i;
    EXPECT_EQ(u.health.state, HealthState::kOk) << i;
  }
  EXPECT_EQ(st.counters().missing, 0U);
  EXPECT_EQ(st.counters().out_of_order, 0U);
  EXPECT_EQ(st.counters().fed, 21U);  // the last warm-up sample and these 20
}

// ---------------------------------------------------------------------------------------------
// Gaps

TEST(SensorHealth, GapAtTheBridgeLimitAcrossTheWrapIsBridgedLinearly) {
  Stream st({}, 245);
  st.warm_up();  // 245..254
  const SensorSample before = nth_sample(254);
  const SensorSample after = nth_sample(258);  // sequence 2: 255, 0, 1 missing
  const SensorUpdate u = st.skip(3);
  ASSERT_EQ(u.verdict, SampleVerdict::kFed);
  ASSERT_EQ(u.fed_count, 4U);
  const std::uint8_t expected_sequence[4] = {255, 0, 1, 2};
  for (std::size_t k = 0; k < 4; ++k) {
    const FedSample& f = u.fed[k];
    EXPECT_EQ(f.sequence, expected_sequence[k]);
    EXPECT_EQ(f.bridged, k < 3) << k;
    EXPECT_FALSE(f.restart);
    const double w = static_cast<double>(k + 1) / 4.0;
    EXPECT_EQ(f.time_ns, (254 + static_cast<std::int64_t>(k) + 1) * kPeriodNs) << k;
    const Eigen::Vector3d expected =
        before.acceleration_g + w * (after.acceleration_g - before.acceleration_g);
    EXPECT_LT((f.acceleration_g - expected).cwiseAbs().maxCoeff(), 1e-15) << k;
  }
  EXPECT_EQ(u.fed[3].acceleration_g, after.acceleration_g);
  EXPECT_EQ(u.health.state, HealthState::kDegraded);
  EXPECT_EQ(u.health.cause, HealthCause::kSequenceGap);
  EXPECT_EQ(st.counters().missing, 3U);
  EXPECT_EQ(st.counters().bridged, 3U);
  EXPECT_EQ(st.counters().long_gaps, 0U);
}

TEST(SensorHealth, GapOneBeyondTheBridgeLimitIsAFaultAndFeedingRestartsAfterRecovery) {
  Stream st;  // bridge 3, recovery 10
  st.warm_up();
  const std::uint64_t fed_before = st.counters().fed;
  const SensorUpdate u = st.skip(4);
  EXPECT_EQ(u.verdict, SampleVerdict::kHeldInFault);
  EXPECT_EQ(u.fed_count, 0U);
  EXPECT_EQ(u.health.state, HealthState::kFault);
  EXPECT_EQ(u.health.cause, HealthCause::kSequenceGap);
  EXPECT_EQ(st.counters().long_gaps, 1U);
  EXPECT_EQ(st.counters().missing, 4U);
  EXPECT_EQ(st.counters().faults, 1U);
  // The sample that ends the gap is the first of the 10 clean ones recovery needs.
  for (int i = 0; i < 8; ++i) EXPECT_EQ(st.next().verdict, SampleVerdict::kHeldInFault) << i;
  const SensorUpdate back = st.next();
  ASSERT_EQ(back.fed_count, 1U);
  EXPECT_TRUE(back.fed[0].restart);
  EXPECT_FALSE(back.fed[0].bridged);
  EXPECT_EQ(back.health.state, HealthState::kOk);
  EXPECT_EQ(st.counters().fed, fed_before + 1);
  EXPECT_EQ(st.counters().held_in_fault, 9U + 9U);  // 9 at start-up, 9 here
}

TEST(SensorHealth, WithOneRecoverySampleFeedingRestartsAtTheSampleAfterTheGap) {
  Stream st(with_recovery(1));
  st.warm_up();
  const SensorUpdate u = st.skip(20);
  ASSERT_EQ(u.fed_count, 1U);
  EXPECT_TRUE(u.fed[0].restart);
  EXPECT_EQ(u.fed[0].sequence, nth_sample(st.n - 1).sequence);
  EXPECT_EQ(st.counters().long_gaps, 1U);
  EXPECT_EQ(st.counters().faults, 1U);
  EXPECT_EQ(u.health.state, HealthState::kOk);
}

TEST(SensorHealth, DegradedClearsAfterExactlyRecoverySamples) {
  Stream st;  // recovery 10
  st.warm_up();
  ASSERT_EQ(st.skip(1).health.state, HealthState::kDegraded);  // run 1: the closing sample
  for (int i = 2; i < 10; ++i) {
    EXPECT_EQ(st.next().health.state, HealthState::kDegraded) << "clean run " << i;
  }
  const SensorUpdate tenth = st.next();
  EXPECT_EQ(tenth.health.state, HealthState::kOk);
  EXPECT_FALSE(tenth.fed[0].restart);  // degraded samples were fed: no discontinuity
}

// ---------------------------------------------------------------------------------------------
// Duplicates and order

TEST(SensorHealth, DuplicateIsDroppedCountedAndTheStreamGoesOn) {
  Stream st;
  st.warm_up();
  SensorSample again = nth_sample(st.n - 1);
  const SensorUpdate dup = st.tracker.on_sample(again);
  EXPECT_EQ(dup.verdict, SampleVerdict::kDuplicate);
  EXPECT_EQ(dup.fed_count, 0U);
  EXPECT_EQ(dup.health.state, HealthState::kDegraded);
  EXPECT_EQ(dup.health.cause, HealthCause::kDuplicate);
  EXPECT_EQ(st.counters().duplicates, 1U);
  const SensorUpdate next = st.next();
  ASSERT_EQ(next.fed_count, 1U);
  EXPECT_FALSE(next.fed[0].bridged);
  EXPECT_EQ(st.counters().missing, 0U);
}

TEST(SensorHealth, OutOfOrderSampleIsDroppedWithoutAGap) {
  Stream st;
  st.warm_up();
  const SensorSample late = nth_sample(st.n - 2);
  const SensorUpdate u = st.tracker.on_sample(late);
  EXPECT_EQ(u.verdict, SampleVerdict::kOutOfOrder);
  EXPECT_EQ(u.fed_count, 0U);
  EXPECT_EQ(u.health.cause, HealthCause::kOutOfOrder);
  EXPECT_EQ(st.counters().out_of_order, 1U);
  const SensorUpdate next = st.next();
  EXPECT_EQ(next.fed_count, 1U);
  EXPECT_EQ(st.counters().missing, 0U);
}

TEST(SensorHealth, ACounterRestartIsAFaultThenTheStreamResynchronises) {
  Stream st(with_recovery(2), 100);
  st.warm_up();  // sequences 100, 101
  st.n = 0;      // the node rebooted: 0, 1, 2, ... all read as behind 101
  for (int i = 0; i < 3; ++i) {
    const SensorUpdate u = st.next();
    EXPECT_EQ(u.verdict, SampleVerdict::kOutOfOrder);
    EXPECT_EQ(u.health.state, HealthState::kDegraded) << i;
  }
  const SensorUpdate fourth = st.next();  // more than max_bridge_samples (3) in a row
  EXPECT_EQ(fourth.verdict, SampleVerdict::kOutOfOrder);
  EXPECT_EQ(fourth.health.state, HealthState::kFault);
  EXPECT_EQ(fourth.health.cause, HealthCause::kOutOfOrder);
  EXPECT_EQ(st.next().verdict, SampleVerdict::kHeldInFault);  // sequence 4: a fresh start
  const SensorUpdate fed = st.next();
  ASSERT_EQ(fed.fed_count, 1U);
  EXPECT_TRUE(fed.fed[0].restart);
  EXPECT_EQ(fed.fed[0].sequence, 5);
  EXPECT_EQ(st.counters().out_of_order, 4U);
  EXPECT_EQ(st.counters().missing, 0U);
}

// ---------------------------------------------------------------------------------------------
// Timeout

TEST(SensorHealth, TimeoutBoundaryOnTick) {
  Stream st;
  st.warm_up();
  const std::int64_t last = nth_sample(st.n - 1).receive_time_ns;
  EXPECT_EQ(st.tracker.tick(last + kTimeoutNs - 1).state, HealthState::kOk);
  const SensorHealth& h = st.tracker.tick(last + kTimeoutNs);
  EXPECT_EQ(h.state, HealthState::kFault);
  EXPECT_EQ(h.cause, HealthCause::kTimeout);
  EXPECT_EQ(h.counters.timeouts, 1U);
  (void)st.tracker.tick(last + 3 * kTimeoutNs);  // one silence, one timeout
  EXPECT_EQ(st.counters().timeouts, 1U);
  EXPECT_EQ(st.counters().faults, 1U);
}

TEST(SensorHealth, ResumingAfterATimeoutResynchronisesWithoutCountingAGap) {
  Stream st(with_recovery(1));
  st.warm_up();
  (void)st.tracker.tick(nth_sample(st.n - 1).receive_time_ns + kTimeoutNs);
  ASSERT_EQ(st.tracker.health().cause, HealthCause::kTimeout);
  const SensorUpdate u = st.skip(77);  // any sequence: the counter may have wrapped meanwhile
  ASSERT_EQ(u.fed_count, 1U);
  EXPECT_TRUE(u.fed[0].restart);
  EXPECT_EQ(u.health.state, HealthState::kOk);
  EXPECT_EQ(st.counters().missing, 0U);
  EXPECT_EQ(st.counters().long_gaps, 0U);
}

TEST(SensorHealth, TimeoutIsDetectedByTheLateSampleItselfWithoutATick) {
  // One sample period short of the timeout: an ordinary long gap.
  {
    Stream st(with_recovery(1));
    st.warm_up();
    SensorSample s = nth_sample(st.n);
    s.receive_time_ns = nth_sample(st.n - 1).receive_time_ns + kTimeoutNs - 1;
    (void)st.tracker.on_sample(s);
    EXPECT_EQ(st.counters().timeouts, 0U);
  }
  {
    Stream st(with_recovery(3));
    st.warm_up();
    SensorSample s = nth_sample(st.n);
    s.receive_time_ns = nth_sample(st.n - 1).receive_time_ns + kTimeoutNs;
    const SensorUpdate u = st.tracker.on_sample(s);
    EXPECT_EQ(st.counters().timeouts, 1U);
    EXPECT_EQ(u.verdict, SampleVerdict::kHeldInFault);
    EXPECT_EQ(u.health.cause, HealthCause::kTimeout);
  }
}

TEST(SensorHealth, DuplicatesAloneDoNotKeepTheStreamAlive) {
  Stream st;
  st.warm_up();
  SensorSample again = nth_sample(st.n - 1);
  for (int i = 1; i <= 60; ++i) {
    again.receive_time_ns += kPeriodNs;
    (void)st.tracker.on_sample(again);
    (void)st.tracker.tick(again.receive_time_ns);
  }
  // The 50th arrives a timeout after the last accepted sample: the silence is a timeout, and
  // that copy starts the stream afresh; the 10 after it are duplicates of it.
  EXPECT_EQ(st.tracker.health().state, HealthState::kFault);
  EXPECT_EQ(st.tracker.health().cause, HealthCause::kTimeout);
  EXPECT_EQ(st.counters().timeouts, 1U);
  EXPECT_EQ(st.counters().duplicates, 59U);
}

// ---------------------------------------------------------------------------------------------
// Values

TEST(SensorHealth, NaNSampleIsRejectedAndBridgedFromItsNeighbours) {
  Stream st;
  st.warm_up();
  const SensorSample before = nth_sample(st.n - 1);
  const SensorUpdate bad = st.next_with({0.0, kNaN, 1.0});
  EXPECT_EQ(bad.verdict, SampleVerdict::kRejected);
  EXPECT_EQ(bad.fed_count, 0U);
  EXPECT_EQ(bad.health.state, HealthState::kDegraded);
  EXPECT_EQ(bad.health.cause, HealthCause::kNonFinite);
  const SensorSample after = nth_sample(st.n);
  const SensorUpdate good = st.next();
  ASSERT_EQ(good.fed_count, 2U);
  EXPECT_TRUE(good.fed[0].bridged);
  EXPECT_TRUE(good.fed[0].acceleration_g.allFinite());
  EXPECT_NEAR(good.fed[0].acceleration_g.y(),
              0.5 * (before.acceleration_g.y() + after.acceleration_g.y()), 1e-15);
  EXPECT_EQ(good.health.cause, HealthCause::kNonFinite);
  EXPECT_EQ(st.counters().non_finite, 1U);
  EXPECT_EQ(st.counters().missing, 0U);  // received, only bad
  EXPECT_EQ(st.counters().bridged, 1U);
}

TEST(SensorHealth, RejectedSamplesPastTheBridgeLimitAreAFaultAtOnce) {
  Stream st;  // bridge 3
  st.warm_up();
  const double inf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(st.next_with({inf, 0.0, 1.0}).health.state, HealthState::kDegraded) << i;
  }
  const SensorUpdate fourth = st.next_with({inf, 0.0, 1.0});
  EXPECT_EQ(fourth.health.state, HealthState::kFault);
  EXPECT_EQ(fourth.health.cause, HealthCause::kNonFinite);
  EXPECT_EQ(st.counters().non_finite, 4U);
  EXPECT_EQ(st.next().verdict, SampleVerdict::kHeldInFault);  // nothing bridged across a fault
  EXPECT_EQ(st.counters().bridged, 0U);
}

TEST(SensorHealth, OutOfRangeIsRejectedAndFullScaleIsSaturated) {
  Stream st;  // full scale 8 g, valid up to 8.192 g
  st.warm_up();
  const SensorUpdate over = st.next_with({0.0, -8.1921, 1.0});
  EXPECT_EQ(over.verdict, SampleVerdict::kRejected);
  EXPECT_EQ(over.health.cause, HealthCause::kOutOfRange);
  EXPECT_EQ(st.counters().out_of_range, 1U);

  const SensorUpdate at_limit = st.next_with({0.0, -8.192, 1.0});
  ASSERT_EQ(at_limit.verdict, SampleVerdict::kFed);
  ASSERT_EQ(at_limit.fed_count, 2U);  // the rejected one bridged first
  EXPECT_TRUE(at_limit.fed[1].saturated);
  EXPECT_EQ(at_limit.health.cause, HealthCause::kSaturated);

  const SensorUpdate at_full_scale = st.next_with({8.0, 0.0, 1.0});
  ASSERT_EQ(at_full_scale.fed_count, 1U);
  EXPECT_TRUE(at_full_scale.fed[0].saturated);
  const SensorUpdate below = st.next_with({7.9999, 0.0, 1.0});
  ASSERT_EQ(below.fed_count, 1U);
  EXPECT_FALSE(below.fed[0].saturated);
  const SensorUpdate flagged = st.next(sensor_flags::kSaturated);
  ASSERT_EQ(flagged.fed_count, 1U);
  EXPECT_TRUE(flagged.fed[0].saturated);
  EXPECT_EQ(st.counters().saturated, 3U);
  EXPECT_EQ(flagged.health.state, HealthState::kDegraded);
}

TEST(SensorHealth, UndefinedStatusBitsAreRejected) {
  Stream st;
  st.warm_up();
  const SensorUpdate u = st.next(0x10);
  EXPECT_EQ(u.verdict, SampleVerdict::kRejected);
  EXPECT_EQ(u.health.cause, HealthCause::kUndefinedStatus);
  EXPECT_EQ(st.counters().undefined_status, 1U);
}

TEST(SensorHealth, SelfTestAndCalibrationFlagsAreFaultsOverTemperatureDegrades) {
  Stream st(with_recovery(2));
  st.warm_up();
  const SensorUpdate hot = st.next(sensor_flags::kOverTemperature);
  EXPECT_EQ(hot.verdict, SampleVerdict::kFed);
  EXPECT_EQ(hot.health.state, HealthState::kDegraded);
  EXPECT_EQ(hot.health.cause, HealthCause::kOverTemperature);

  const SensorUpdate self_test = st.next(sensor_flags::kSelfTestFailed);
  EXPECT_EQ(self_test.verdict, SampleVerdict::kHeldInFault);
  EXPECT_EQ(self_test.health.cause, HealthCause::kSelfTestFailed);
  const SensorUpdate calibration = st.next(sensor_flags::kCalibrationInvalid);
  EXPECT_EQ(calibration.verdict, SampleVerdict::kHeldInFault);
  EXPECT_EQ(calibration.health.cause, HealthCause::kCalibrationInvalid);
  EXPECT_EQ(st.next().verdict, SampleVerdict::kHeldInFault);  // clean run 1 of 2
  const SensorUpdate back = st.next();
  ASSERT_EQ(back.fed_count, 1U);
  EXPECT_TRUE(back.fed[0].restart);
  EXPECT_EQ(st.counters().over_temperature, 1U);
  EXPECT_EQ(st.counters().self_test_failed, 1U);
  EXPECT_EQ(st.counters().calibration_invalid, 1U);
  EXPECT_EQ(st.counters().faults, 1U);
}

TEST(SensorHealth, StuckBoundary) {
  SensorHealthSettings s;
  s.stuck_samples = 5;
  s.recovery_samples = 2;
  Stream st(s);
  st.warm_up();
  const Eigen::Vector3d frozen(0.0125, -0.0025, 1.0);
  for (int i = 1; i <= 4; ++i) {  // four alike: could still be quantised noise
    const SensorUpdate u = st.next_with(frozen);
    EXPECT_EQ(u.verdict, SampleVerdict::kFed) << i;
    EXPECT_EQ(u.health.state, HealthState::kOk) << i;
  }
  const SensorUpdate fifth = st.next_with(frozen);
  EXPECT_EQ(fifth.verdict, SampleVerdict::kHeldInFault);
  EXPECT_EQ(fifth.health.cause, HealthCause::kStuck);
  EXPECT_EQ(st.next_with(frozen).verdict, SampleVerdict::kHeldInFault);
  EXPECT_EQ(st.counters().stuck_detections, 1U);
  (void)st.next();
  EXPECT_EQ(st.next().fed_count, 1U);  // values move again: recovered after 2 clean samples

  // Two axes frozen, one moving: not stuck.
  for (int i = 0; i < 20; ++i) {
    const SensorUpdate u =
        st.next_with({frozen.x(), frozen.y(), 1.0 + 1e-4 * static_cast<double>(i)});
    EXPECT_EQ(u.verdict, SampleVerdict::kFed) << i;
  }
  EXPECT_EQ(st.counters().stuck_detections, 1U);
}

TEST(SensorHealth, StuckCheckOffForSyntheticInput) {
  SensorHealthSettings s;
  s.stuck_samples = 0;
  Stream st(s);
  st.warm_up();
  for (int i = 0; i < 500; ++i) ASSERT_EQ(st.next_with({0.0, 0.0, 1.0}).fed_count, 1U) << i;
  EXPECT_EQ(st.counters().stuck_detections, 0U);
}

// ---------------------------------------------------------------------------------------------
// Names

TEST(SensorHealth, NamesAndAlarmCauses) {
  EXPECT_STREQ(health_state_name(HealthState::kDegraded), "degraded");
  EXPECT_STREQ(health_cause_name(HealthCause::kSequenceGap), "sequence gap");
  EXPECT_STREQ(health_cause_name(HealthCause::kStuck), "stuck values");
  EXPECT_STREQ(health_cause_name(static_cast<HealthCause>(99)), "invalid");
  EXPECT_EQ(to_alarm_cause(HealthCause::kTimeout), AlarmCause::kSensorTimeout);
  EXPECT_EQ(to_alarm_cause(HealthCause::kNoData), AlarmCause::kSensorTimeout);
  EXPECT_EQ(to_alarm_cause(HealthCause::kStuck), AlarmCause::kSensorFault);
  EXPECT_EQ(to_alarm_cause(HealthCause::kNone), AlarmCause::kNone);
}

}  // namespace
}  // namespace plinth::monitor

// The statue sensor in the monitor (statue_sensor.h): its offset, its rate to each axis's
// StatueFilter, the measured phase and the weighted risk in the status, the fallback to the
// worst member when it is silent, and the statue_unexplained fault when no member explains it;
// its accelerometer's specific force to the filters' sliding test, and its fallback.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "plinth/firmware/alarm_inputs.h"
#include "plinth/firmware/monitor.h"
#include "test_support.h"

namespace plinth::firmware {
namespace {

using testing::make;
using testing::paper_block;
using testing::wide_block;
using testing::with_friction;

constexpr double kRate = 200.0;
constexpr long kQuiet = 400;  // 2 s of quiet: both sensors' start-up windows (1 s)

MonitorConfig statue_config() {
  MonitorConfig c;
  c.estimator.sample_rate_hz = kRate;
  c.forecast.enabled = false;
  c.conditioning.startup_window_s = 1.0;
  c.sensor_health.stuck_samples = 0;  // the synthetic ground is noise-free
  c.statue_sensor.present = true;
  c.statue_sensor.node = 2;
  c.statue_sensor.offset_window_s = 1.0;
  return c;
}

// The monitor on {paper's block, wide block}: 2 s quiet, then a 1 Hz sine of `amplitude_g`.
// The statue's gyroscope reads `statue_rate(n)` about -y (axis 0) plus an offset of 0.01 rad/s
// and noise; its accelerometer what a statue standing on the ground reads (the ground's
// acceleration and gravity, a small offset and noise: the ground sensor corroborates it);
// `statue` false: no statue sample at all.
struct StatueRun {
  StatueRun() : scenes{make(paper_block()), wide_block()}, monitor(std::make_unique<Monitor>()) {}
  Error start(const MonitorConfig& c) {
    return monitor->start(c, {std::span<const Scene>(scenes), {}});
  }
  template <typename Rate>
  const BoxStatus& step(long n, double amplitude_g, Rate statue_rate, bool statue = true) {
    const double t = static_cast<double>(n - kQuiet) / kRate;
    const double a = n < kQuiet ? 0.0 : amplitude_g * std::sin(2.0 * std::numbers::pi * t);
    monitor::SensorSample ground;
    ground.receive_time_ns = std::llround(static_cast<double>(n) / kRate * 1e9);
    ground.sequence = static_cast<std::uint8_t>(n & 0xFF);
    ground.acceleration_g = Vector3r(static_cast<Real>(a), 0, 1);
    if (statue) {
      StatueSample s;
      s.receive_time_ns = ground.receive_time_ns;
      s.sequence = ground.sequence;
      const double rate = n < kQuiet ? 0.0 : statue_rate(n);
      s.rotation_rate_rad_s = Vector3r(static_cast<Real>(0.003 * gauss(random)),
                                       static_cast<Real>(-rate + 0.01 + 0.003 * gauss(random)),
                                       static_cast<Real>(0.003 * gauss(random)));
      (void)monitor->on_statue_sample(s);
      monitor::SensorSample f = ground;
      if (!accelerometer_follows_ground) f.acceleration_g = Vector3r(0, 0, 1);
      f.acceleration_g += Vector3r(static_cast<Real>(0.01 + 0.003 * gauss(random)),
                                   static_cast<Real>(0.003 * gauss(random)),
                                   static_cast<Real>(0.003 * gauss(random)));
      if (feed_accelerometer) (void)monitor->on_statue_acceleration(f);
    }
    return *monitor->on_sample(ground).status;
  }
  std::vector<Scene> scenes;
  std::unique_ptr<Monitor> monitor;
  bool accelerometer_follows_ground = true;  // false: it reads gravity alone (rest)
  bool feed_accelerometer = true;            // false: its accelerometer sends nothing
  std::mt19937 random{24};
  std::normal_distribution<double> gauss;
};

// The wide block is the statue: it stands at 0.5 g, where the paper's block (member 0, the
// nominal) rocks and overturns. The sensor sees it stand: the phase is full contact, the weights
// go to the wide member, and the risk is its (low), not the worst member's.
TEST(MonitorStatue, AStandingStatueTakesTheFragileMembersRiskAway) {
  StatueRun run;
  ASSERT_TRUE(run.start(statue_config()).ok());
  const auto still = [](long) { return 0.0; };
  double worst_simulated = 0.0;
  for (long n = 0; n < kQuiet + 1200; ++n) {
    (void)run.step(n, 0.5, still);
    EnsembleRisk r;
    run.monitor->ensemble(0).risk(r);
    worst_simulated = std::fmax(worst_simulated, r.risk.total);
  }
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_TRUE(s.has_statue_sensor);
  EXPECT_TRUE(s.statue_sensor.ready);
  const AxisStatus& axis = s.axes[0];
  EXPECT_TRUE(axis.statue.measured);
  EXPECT_TRUE(axis.statue.weighted);
  EXPECT_FALSE(axis.statue.unexplained);
  EXPECT_EQ(axis.mode.phase, Phase::kFullContact);
  EXPECT_GT(worst_simulated, 0.9);
  EXPECT_LT(s.risk, 0.05);
  EXPECT_GT(run.monitor->statue_filter(0).estimate().weights[1], Real(0.9));
  EXPECT_FALSE(s.statue_unexplained);
  EXPECT_TRUE(axis.statue.corroborated);
  EXPECT_EQ(s.trouble, monitor::AlarmCause::kNone);
  EXPECT_NE(s.alarm, monitor::AlarmLevel::kAlarm);
}

// The same run with the forecast on. Still, the sensor takes the rocking member's present risk
// away but not its forecast collapse: a sensor on the plinth or stuck reads what a standing
// statue reads (docs/safety.md, "What stillness cannot rule out"). The status's probability is
// the ensemble's own, and the paper's block forecast to collapse raises the alarm.
TEST(MonitorStatue, StillnessDoesNotRuleOutTheForecastCollapse) {
  StatueRun run;
  MonitorConfig c = statue_config();
  c.forecast.enabled = true;
  ASSERT_TRUE(run.start(c).ok());
  const auto still = [](long) { return 0.0; };
  bool forecast_seen = false;
  bool alarmed = false;
  for (long n = 0; n < kQuiet + 1200; ++n) {
    const BoxStatus& s = run.step(n, 0.5, still);
    const ForecastOutcome& raw = run.monitor->ensemble(0).forecaster().latest();
    if (!s.axes[0].statue.measured || !s.axes[0].statue.corroborated) continue;
    ASSERT_EQ(s.axes[0].forecast.probability, raw.probability) << n;
    ASSERT_EQ(s.axes[0].forecast.collapse_in_s, raw.collapse_in_s) << n;
    forecast_seen = forecast_seen || (raw.valid && raw.probability > 0.0);
    alarmed = alarmed || s.alarm == monitor::AlarmLevel::kAlarm;
  }
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_TRUE(s.axes[0].statue.corroborated);
  EXPECT_EQ(s.axes[0].mode.phase, Phase::kFullContact);
  EXPECT_LT(s.axes[0].risk.total, 0.05);  // the present risk: the standing member's
  EXPECT_TRUE(forecast_seen);
  EXPECT_TRUE(alarmed);
}

// The same statue, its sensor reading rest (come off the statue: no rotation, its accelerometer
// gravity alone, not the ground's shaking). The ground sensor does not corroborate it: the box
// keeps the worst member's risk (the box without the sensor's) and names the sensor.
TEST(MonitorStatue, ASensorReadingRestIsRefusedAndNamed) {
  StatueRun run;
  run.accelerometer_follows_ground = false;
  ASSERT_TRUE(run.start(statue_config()).ok());
  const auto still = [](long) { return 0.0; };
  bool alarmed = false;
  for (long n = 0; n < kQuiet + 1200; ++n) {
    const BoxStatus& s = run.step(n, 0.5, still);
    alarmed = alarmed || s.alarm == monitor::AlarmLevel::kAlarm;
  }
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_TRUE(s.axes[0].statue.measured);
  EXPECT_FALSE(s.axes[0].statue.corroborated);
  EXPECT_EQ(s.axes[0].statue.refutation, StatueRefutation::kDoesNotFollowBase);
  EnsembleRisk r;
  run.monitor->ensemble(0).risk(r);
  EXPECT_GE(s.axes[0].risk.total, r.risk.total);
  EXPECT_EQ(s.trouble, monitor::AlarmCause::kStatueSensorFault);
  EXPECT_TRUE(alarmed);  // the paper's block, a member, overturns: the box without it alarms
}

// Without statue samples (a silent or absent node) the axis is not measured: the worst member's
// risk, as the box without the sensor.
TEST(MonitorStatue, ASilentStatueSensorLeavesTheWorstMembersRisk) {
  StatueRun run;
  ASSERT_TRUE(run.start(statue_config()).ok());
  const auto still = [](long) { return 0.0; };
  for (long n = 0; n < kQuiet + 600; ++n) (void)run.step(n, 0.5, still, n < kQuiet + 100);
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_FALSE(s.axes[0].statue.measured);
  EnsembleRisk r;
  run.monitor->ensemble(0).risk(r);
  EXPECT_EQ(s.axes[0].risk.total, r.risk.total);
  EXPECT_EQ(s.statue_sensor.rate.state, monitor::HealthState::kFault);  // timed out
}

// A loose sensor swinging on a quiet ground: its accelerometer does not read what its gyroscope
// says (no block rocks so on a still ground), and no member explains it. The sensor is refused:
// the trouble names it; the level is never below the box's without it (the swing it reads may
// raise it: any input may), the risk never below the worst member's (every member sits).
TEST(MonitorStatue, ASwingingLooseSensorIsRefused) {
  StatueRun run;
  ASSERT_TRUE(run.start(statue_config()).ok());
  const auto swing = [](long n) {
    return 0.3 * std::sin(2.0 * std::numbers::pi * 3.0 * static_cast<double>(n) / kRate);
  };
  bool fault_said = false;
  for (long n = 0; n < kQuiet + 600; ++n) {
    const BoxStatus& s = run.step(n, 0.0, swing);
    fault_said = fault_said || s.trouble == monitor::AlarmCause::kStatueSensorFault ||
                 s.trouble == monitor::AlarmCause::kStatueUnexplained;
  }
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_TRUE(fault_said);
  EXPECT_GE(s.axes[0].risk.total, s.axes[0].statue.risk_without);
  EXPECT_FALSE(s.axes[0].statue.corroborated);
  EXPECT_NE(alarm_input(s, run.monitor->config(), false).input_fault,
            monitor::AlarmCause::kNone);
  EXPECT_FALSE(alarm_input(s, run.monitor->config(), false).fault_active);
}

TEST(MonitorStatue, RefusesAStatueSensorOnAGroundSensorsNode) {
  StatueRun run;
  MonitorConfig c = statue_config();
  c.statue_sensor.node = c.ground_node;
  EXPECT_EQ(std::string(run.start(c).field), "statue_sensor.node");
  c = statue_config();
  c.statue_sensor.sensor_to_statue(0, 0) = -1;  // a reflection
  EXPECT_EQ(std::string(run.start(c).field), "statue_sensor.sensor_to_statue");
  c = statue_config();
  c.statue_sensor.filter.memory_s = -1;
  EXPECT_EQ(std::string(run.start(c).field), "statue_filter.memory_s");
  // The streams' health, named by the statue sensor's keys with their units.
  c = statue_config();
  c.statue_sensor.health.rate_max_valid_rad_s = 10;  // below rate_full_scale_rad_s
  EXPECT_EQ(std::string(run.start(c).field), "statue_sensor.health.rate_max_valid_rad_s");
  c = statue_config();
  c.statue_sensor.health.acceleration_full_scale_g = -1;
  EXPECT_EQ(std::string(run.start(c).field), "statue_sensor.health.acceleration_full_scale_g");
  c = statue_config();
  c.statue_sensor.health.timeout_s = 0.001;  // within a bridgeable gap at 200 Hz
  EXPECT_EQ(std::string(run.start(c).field), "statue_sensor.health.timeout_s");
}

// The accelerometer's stream has its own health: a gyroscope that streams while the
// accelerometer is silent is measured, and the status says which stream is at fault.
TEST(MonitorStatue, EachStreamHasItsOwnHealth) {
  StatueRun run;
  run.feed_accelerometer = false;
  ASSERT_TRUE(run.start(statue_config()).ok());
  const auto still = [](long) { return 0.0; };
  for (long n = 0; n < kQuiet + 100; ++n) {
    (void)run.step(n, 0.05, still);
    if (n < 100) {
      monitor::SensorSample a;
      a.receive_time_ns = std::llround(static_cast<double>(n) / kRate * 1e9);
      a.sequence = static_cast<std::uint8_t>(n & 0xFF);
      a.acceleration_g = Vector3r(Real(0.001) * static_cast<Real>(n % 7), 0, 1);
      if (n == 50) a.acceleration_g.x() = Real(8.1);  // at full scale: saturated, degraded
      (void)run.monitor->on_statue_acceleration(a);
    }
  }
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_EQ(s.statue_sensor.rate.state, monitor::HealthState::kOk);
  EXPECT_EQ(s.statue_sensor.acceleration.state, monitor::HealthState::kFault);
  EXPECT_EQ(s.statue_sensor.acceleration.cause, monitor::HealthCause::kTimeout);
  EXPECT_EQ(s.statue_sensor.acceleration.counters.received, 100U);
  EXPECT_EQ(s.statue_sensor.acceleration.counters.saturated, 1U);
  EXPECT_TRUE(s.axes[0].statue.measured);
  // Without its accelerometer nothing corroborates the gyroscope: refused, named.
  EXPECT_EQ(s.axes[0].statue.refutation, StatueRefutation::kNoAccelerometer);
  EXPECT_EQ(s.trouble, monitor::AlarmCause::kStatueSensorFault);
}

// The statue sensor's trouble is an input fault beside the faults that make the risk stale:
// it never is one of them (the risk it leaves is the box's without the sensor, still valid).
TEST(MonitorStatue, TheStatueSensorsTroubleIsAnInputFault) {
  BoxStatus s;
  s.estimating = true;
  s.calibrated = true;
  s.sensor.state = monitor::HealthState::kOk;
  s.statue_unexplained = true;
  s.input_fault = monitor::AlarmCause::kStatueUnexplained;
  MonitorConfig config;
  EXPECT_FALSE(alarm_input(s, config, false).fault_active);
  EXPECT_EQ(alarm_input(s, config, false).input_fault, monitor::AlarmCause::kStatueUnexplained);
  EXPECT_EQ(alarm_input(s, config, true).fault_cause, monitor::AlarmCause::kBusError);
  s.axes[0].outside_model = true;
  EXPECT_EQ(alarm_input(s, config, false).fault_cause, monitor::AlarmCause::kOutsideModel);
}


// A block that slides (the paper's with mu_s 0.15, mu_k 0.12) under a 1 Hz sine of 0.25 g for
// 4 s after the quiet, then still; the statue sensor turned 90 degrees about z on it (statue =
// R sensor), its accelerometer's y axis (the statue's -x) 0.03 g off, its gyroscope's 0.01 rad/s,
// both with noise. Its readings come from a true statue fed the same ground (lib/core
// simulated_specific_force, 1 m up on the axis). `accelerometer(n)` says whether sample n has an
// accelerometer frame.
struct SlidingStatueRun {
  SlidingStatueRun()
      : scenes{make(with_friction(paper_block(), 0.15, 0.12))},
        monitor(std::make_unique<Monitor>()),
        truth(std::make_unique<PlanarEstimator>()) {
    config = statue_config();
    config.statue_sensor.sensor_to_statue << 0, -1, 0, 1, 0, 0, 0, 0, 1;
    EstimatorSettings e;
    e.sample_rate_hz = kRate;
    e.steps_per_sample = 4;
    EXPECT_TRUE(truth->start(scenes[0], e, {}).ok());
  }
  Error start() { return monitor->start(config, {std::span<const Scene>(scenes), {}}); }
  template <typename Accelerometer>
  const BoxStatus& step(long n, Accelerometer accelerometer) {
    const double t = static_cast<double>(n - kQuiet) / kRate;
    const double a = n < kQuiet || t >= 4.0 ? 0.0 : 0.25 * std::sin(2.0 * std::numbers::pi * t);
    if (n >= kQuiet) truth->push({static_cast<Real>(a * kStandardGravity), 0});
    const Matrix3r to_sensor = config.statue_sensor.sensor_to_statue.transpose();
    const std::int64_t time_ns = std::llround(static_cast<double>(n) / kRate * 1e9);
    const auto sequence = static_cast<std::uint8_t>(n & 0xFF);
    StatueSample gyro;
    gyro.receive_time_ns = time_ns;
    gyro.sequence = sequence;
    const Real rate = n < kQuiet ? Real(0) : truth->state()[kThetaDot];
    gyro.rotation_rate_rad_s =
        to_sensor * Vector3r(static_cast<Real>(0.003 * gauss(random)),
                             -rate + static_cast<Real>(0.003 * gauss(random)),
                             static_cast<Real>(0.003 * gauss(random))) +
        Vector3r(0, Real(0.01), 0);
    (void)monitor->on_statue_sample(gyro);
    if (accelerometer(n)) {
      Vector2r f(0, kStandardGravity);
      if (n >= kQuiet) {
        f = simulated_specific_force(scenes[0], truth->mode(), truth->state(),
                                     truth->simulator().accelerations(), truth->ground(), {});
      }
      monitor::SensorSample s;
      s.receive_time_ns = time_ns;
      s.sequence = sequence;
      s.acceleration_g = to_sensor * Vector3r(f.x(), 0, f.y()) / kStandardGravity +
                         Vector3r(0, Real(0.03), 0) +
                         Vector3r(static_cast<Real>(0.003 * gauss(random)),
                                  static_cast<Real>(0.003 * gauss(random)),
                                  static_cast<Real>(0.003 * gauss(random)));
      (void)monitor->on_statue_acceleration(s);
    }
    monitor::SensorSample ground;
    ground.receive_time_ns = time_ns;
    ground.sequence = sequence;
    ground.acceleration_g = Vector3r(static_cast<Real>(a), 0, 1);
    return *monitor->on_sample(ground).status;
  }
  std::vector<Scene> scenes;
  MonitorConfig config;
  std::unique_ptr<Monitor> monitor;
  std::unique_ptr<PlanarEstimator> truth;
  std::mt19937 random{31};
  std::normal_distribution<double> gauss;
};

// The statue sensor's accelerometer tells sliding: the axis's phase is sliding while the true
// statue slides (through the mounting's rotation, the offset removed over the quiet window),
// never before it, and full contact once it has stuck.
TEST(MonitorStatue, TheAccelerometerMeasuresSliding) {
  SlidingStatueRun run;
  ASSERT_TRUE(run.start().ok());
  const auto always = [](long) { return true; };
  int truth_sliding = 0;
  int both = 0;
  double last_truth = -1.0;
  for (long n = 0; n < kQuiet + 6 * static_cast<long>(kRate); ++n) {
    const BoxStatus& s = run.step(n, always);
    const double t = static_cast<double>(n - kQuiet) / kRate;
    const bool truth_slides = n >= kQuiet && run.truth->mode().sliding();
    if (truth_slides) last_truth = t;
    truth_sliding += truth_slides ? 1 : 0;
    if (n < kQuiet + 10) continue;
    const AxisStatus& axis = s.axes[0];
    ASSERT_TRUE(axis.statue.measured) << n;
    ASSERT_TRUE(axis.statue.acceleration_used) << n;
    if (axis.mode.sliding()) {
      ASSERT_EQ(axis.mode.phase, Phase::kSliding) << n;
      ASSERT_GE(last_truth, 0.0) << "sliding before the truth, t = " << t;
      ASSERT_LT(t - last_truth, 0.4) << t;
    }
    both += truth_slides && axis.mode.sliding() ? 1 : 0;
  }
  EXPECT_GT(truth_sliding, 200);
  EXPECT_GT(both, truth_sliding / 2) << both << " of " << truth_sliding;
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_EQ(s.axes[0].mode.phase, Phase::kFullContact);
  EXPECT_EQ(s.statue_sensor.acceleration.state, monitor::HealthState::kOk);
}

// The accelerometer falls silent while the statue slides: within max_age_s the phase is the
// gyroscope's (full contact) and the status says the accelerometer is not used; its stream then
// times out (fault). Sliding is never said from its last, stale sample; once follow_onset_s
// passes without it, the sensor is refused and the phase is the box's own (its nominal member's).
TEST(MonitorStatue, ASilentAccelerometerFallsBackToTheGyroscope) {
  SlidingStatueRun run;
  ASSERT_TRUE(run.start().ok());
  const auto always = [](long) { return true; };
  long n = 0;
  for (; n < kQuiet + 4 * static_cast<long>(kRate); ++n) {
    if (run.step(n, always).axes[0].mode.sliding()) break;
  }
  ASSERT_TRUE(run.monitor->poll().status->axes[0].mode.sliding());
  const long silent = n + 1;
  const auto until_silent = [silent](long k) { return k < silent; };
  for (++n; n < silent + 100; ++n) {
    const BoxStatus& s = run.step(n, until_silent);
    const long refused = silent + 30;  // follow_onset_s 0.15 s
    if (n >= silent + 2 && n < refused) {  // max_age_s 0.01 s: two samples
      ASSERT_FALSE(s.axes[0].mode.sliding()) << n - silent;
      ASSERT_FALSE(s.axes[0].statue.acceleration_used) << n - silent;
      ASSERT_TRUE(s.axes[0].statue.measured) << n - silent;  // the gyroscope still is
    }
  }
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_EQ(s.statue_sensor.acceleration.state, monitor::HealthState::kFault);
  EXPECT_EQ(s.axes[0].statue.refutation, StatueRefutation::kNoAccelerometer);
  EXPECT_EQ(s.axes[0].mode.phase, run.monitor->ensemble(0).nominal().mode().phase);
}

}  // namespace
}  // namespace plinth::firmware

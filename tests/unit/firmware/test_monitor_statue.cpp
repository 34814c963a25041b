// The statue sensor in the monitor (statue_sensor.h): its offset, its rate to each axis's
// StatueFilter, the measured phase and the weighted risk in the status, the fallback to the
// worst member when it is silent, and the statue_unexplained fault when no member explains it.
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
// and noise; nullptr: no statue sample at all.
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
    }
    return *monitor->on_sample(ground).status;
  }
  std::vector<Scene> scenes;
  std::unique_ptr<Monitor> monitor;
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
  EXPECT_NE(s.alarm, monitor::AlarmLevel::kAlarm);
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

// A loose sensor swinging on a quiet ground: no member explains it; the level is fault with
// cause statue_unexplained, and the risk stays the worst member's (every member sits).
TEST(MonitorStatue, ASwingingLooseSensorIsStatueUnexplained) {
  StatueRun run;
  ASSERT_TRUE(run.start(statue_config()).ok());
  const auto swing = [](long n) {
    return 0.3 * std::sin(2.0 * std::numbers::pi * 3.0 * static_cast<double>(n) / kRate);
  };
  bool fault_said = false;
  for (long n = 0; n < kQuiet + 600; ++n) {
    const BoxStatus& s = run.step(n, 0.0, swing);
    fault_said = fault_said || (s.statue_unexplained && s.alarm == monitor::AlarmLevel::kFault);
  }
  EXPECT_TRUE(fault_said);
  const BoxStatus& s = *run.monitor->poll().status;
  EXPECT_TRUE(s.statue_unexplained);
  EXPECT_EQ(alarm_input(s, run.monitor->config(), false).fault_cause,
            monitor::AlarmCause::kStatueUnexplained);
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
}

// The fault's place: after the sensors', the disagreement's, the bus's and outside_model's.
TEST(MonitorStatue, StatueUnexplainedIsTheLastFault) {
  BoxStatus s;
  s.estimating = true;
  s.calibrated = true;
  s.sensor.state = monitor::HealthState::kOk;
  s.statue_unexplained = true;
  MonitorConfig config;
  EXPECT_TRUE(alarm_input(s, config, false).fault_active);
  EXPECT_EQ(alarm_input(s, config, false).fault_cause, monitor::AlarmCause::kStatueUnexplained);
  EXPECT_EQ(alarm_input(s, config, true).fault_cause, monitor::AlarmCause::kBusError);
  s.axes[0].outside_model = true;
  EXPECT_EQ(alarm_input(s, config, false).fault_cause, monitor::AlarmCause::kOutsideModel);
}

}  // namespace
}  // namespace plinth::firmware

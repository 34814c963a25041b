// The box's loop with several sensors (firmware/monitor): redundant ground sensors cross-checked
// and failing over, the plate sensor checking the model, and their configuration file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "box_file_error.h"
#include "monitor_config.h"
#include "plinth/firmware/frame_decoder.h"
#include "plinth/firmware/monitor.h"
#include "plinth/host/input_error.h"
#include "test_support.h"

namespace plinth {
namespace {

namespace fw = firmware;
namespace can = hal::can;

constexpr double kRate = 200.0;                 // Hz
constexpr std::int64_t kPeriodNs = 5'000'000;  // ns
constexpr double kPi = 3.14159265358979323846;

// Quiet for 1 s (the 0.5 s start-up window and the recovery samples), then a sine of 0.05 g at
// 0.5 Hz (the isolated base's own frequency: its absolute acceleration is large) on x, g.
double ground_g(long n) {
  const double t = static_cast<double>(n) / kRate - 1.0;
  return t < 0.0 ? 0.0 : 0.05 * std::sin(2.0 * kPi * 0.5 * t);
}

monitor::SensorSample sample(long n, double ax_g, std::int64_t delay_ns = 0) {
  monitor::SensorSample s;
  s.receive_time_ns = static_cast<std::int64_t>(n) * kPeriodNs + delay_ns;
  s.sequence = static_cast<std::uint8_t>(n & 0xFF);
  s.acceleration_g = Eigen::Vector3d(ax_g, 0.0, 1.0);
  return s;
}

fw::MonitorConfig single_config() {
  fw::MonitorConfig config;
  config.estimator.sample_rate_hz = kRate;
  config.conditioning.startup_window_s = 0.5;
  config.sensor_health.stuck_samples = 0;  // noise-free input
  config.alarm.lower_hold_s = 0.2;  // the start-up fault ends before the tests' conditions start
  return config;
}

// The single-sensor settings as sensors of the given roles, nodes 1, 2, ...
fw::MonitorConfig sensors_config(std::initializer_list<fw::SensorRole> roles) {
  fw::MonitorConfig config = single_config();
  for (const fw::SensorRole role : roles) {
    fw::SensorConfig& s = config.sensors[static_cast<std::size_t>(config.sensor_count)];
    s.node = static_cast<std::uint8_t>(config.sensor_count + 1);
    s.role = role;
    s.conditioning = config.conditioning;
    s.sensor_health = config.sensor_health;
    ++config.sensor_count;
  }
  return config;
}

// The same estimate: bit for bit (tolerance 0), or within `tolerance` (m, rad, m/s, rad/s).
void expect_same_estimate(const fw::Monitor& a, const fw::Monitor& b, long n,
                          double tolerance = 0.0) {
  ASSERT_EQ(a.status().estimating, b.status().estimating) << n;
  EXPECT_EQ(a.status().axes[0].mode.phase, b.status().axes[0].mode.phase) << n;
  for (Eigen::Index i = 0; i < 6; ++i) {
    ASSERT_NEAR(a.status().axes[0].state[i], b.status().axes[0].state[i], tolerance)
        << n << " " << i;
  }
  EXPECT_NEAR(a.status().risk, b.status().risk, tolerance) << n;
}

const Scene& scene() {
  static const Scene s = testing::make(testing::paper_isolated(0.0));
  return s;
}

// Starts `monitor` on the paper's isolated block, one axis.
bool started(fw::Monitor& monitor, const fw::MonitorConfig& config) {
  return monitor.start(config, {&scene(), nullptr}).ok();
}

fw::MonitorConfig two_grounds() {
  return sensors_config({fw::SensorRole::kGround, fw::SensorRole::kGround});
}

// Two ground sensors reading the same ground, the second 1.3 ms later on the bus (its samples
// are taken then): no disagreement, and the estimate is the single sensor's, sample by sample.
TEST(MonitorSensors, TwoAgreeingGroundSensorsGiveTheSingleSensorResults) {
  fw::Monitor single;
  ASSERT_TRUE(started(single, single_config()));
  fw::Monitor dual;
  ASSERT_TRUE(started(dual, two_grounds()));
  const std::int64_t delay = 1'300'000;
  for (long n = 0; n < 1000; ++n) {
    (void)single.on_sample(sample(n, ground_g(n)));
    (void)dual.on_sensor_sample(0, sample(n, ground_g(n)));
    expect_same_estimate(single, dual, n);
    const double later = static_cast<double>(n) + static_cast<double>(delay) / kPeriodNs;
    const double t = later / kRate - 1.0;
    const double a = t < 0.0 ? 0.0 : 0.05 * std::sin(2.0 * kPi * 0.5 * t);
    (void)dual.on_sensor_sample(1, sample(n, a, delay));
    ASSERT_FALSE(dual.status().disagreement) << n;
  }
  const fw::BoxStatus& s = dual.status();
  EXPECT_EQ(s.primary, 0);
  EXPECT_EQ(s.failovers, 0U);
  EXPECT_EQ(s.sensors_state, monitor::HealthState::kOk);
  EXPECT_GT(std::fabs(s.axes[0].state[kU]), 1e-3);  // the base moved
  EXPECT_TRUE(s.sensors[1].window_full);
  EXPECT_GT(s.sensors[1].pairs, 700U);
  EXPECT_LT(s.sensors[1].max_rms_m_s2, 1e-3);
  EXPECT_EQ(s.sensors[1].disagreements, 0U);
  EXPECT_EQ(s.alarm, single.status().alarm);
  EXPECT_EQ(s.estimator_restarts, 1U);
}

// The second sensor's x drifts away at 2 m/s2 per s from t = 3 s: the RMS difference passes
// the 0.3 m/s2 tolerance within the 0.5 s window; the trouble says kSensorDisagreement, the
// estimators run on, and the alarm follows the more dangerous reading, the drifting one (a
// drift that strong is an earthquake as far as one sensor can tell).
TEST(MonitorSensors, DriftingSensorIsReportedWithinTheWindow) {
  fw::Monitor monitor;
  ASSERT_TRUE(started(monitor, two_grounds()));
  const long drift_from = 800;  // t = 3 s after the start-up second
  long reported = -1;
  bool fault_event = false;
  for (long n = 0; n < 1200; ++n) {
    const double drift_g =
        n < drift_from ? 0.0 : 2.0 * static_cast<double>(n - drift_from) / kRate / kStandardGravity;
    for (const fw::MonitorUpdate& u :
         {monitor.on_sensor_sample(0, sample(n, ground_g(n))),
          monitor.on_sensor_sample(1, sample(n, ground_g(n) + drift_g, 1'000'000))}) {
      for (std::size_t i = 0; i < u.event_count; ++i) {
        if (n > drift_from && u.events[i].trouble == monitor::AlarmCause::kSensorDisagreement) {
          fault_event = true;
        }
      }
    }
    if (n < drift_from) {
      ASSERT_FALSE(monitor.status().disagreement) << n;
    }
    if (reported < 0 && monitor.status().disagreement) reported = n;
  }
  ASSERT_GT(reported, drift_from);
  EXPECT_LT(reported - drift_from, std::lround(0.5 * kRate));
  EXPECT_TRUE(fault_event);
  const fw::BoxStatus& s = monitor.status();
  EXPECT_EQ(s.alarm, monitor::AlarmLevel::kAlarm);
  EXPECT_EQ(s.trouble, monitor::AlarmCause::kSensorDisagreement);
  EXPECT_EQ(s.risk_sensor, 1);
  EXPECT_TRUE(s.sensors[1].disagreeing);
  EXPECT_EQ(s.sensors[1].disagreements, 1U);
  EXPECT_GT(s.sensors[1].rms_m_s2, 0.3);
  EXPECT_EQ(s.sensors_state, monitor::HealthState::kDegraded);
  EXPECT_EQ(s.primary, 0);
  EXPECT_EQ(s.estimator_restarts, 1U);
  // The primary falls silent: the drifting sensor takes over (the one left); the cross-check
  // has no one to compare, so the disagreement ends and its trouble with it (the alarm it raised
  // stays latched).
  for (long n = 1200; n < 1400; ++n) {
    (void)monitor.on_sensor_sample(1, sample(n, ground_g(n) + 0.3, 1'000'000));
  }
  EXPECT_EQ(monitor.status().primary, 1);
  EXPECT_FALSE(monitor.status().disagreement);
  EXPECT_FALSE(monitor.status().sensors[1].disagreeing);
  EXPECT_EQ(monitor.status().sensors_state, monitor::HealthState::kDegraded);
  EXPECT_NE(monitor.status().trouble, monitor::AlarmCause::kSensorDisagreement);
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kAlarm);
}

// Two ground sensors under a slender block on the ground (the paper's, one axis), 1 Hz shaking
// of 0.5 g on x that overturns it. The primary is turned 90 degrees about the vertical (the box
// file says it is not): its x reads the ground's y, still. Alone it would say normal; the
// sensors disagree, and the alarm follows the most dangerous healthy reading, the second
// sensor's: alarm no later than a box with that sensor alone, the disagreement shown beside it.
TEST(MonitorSensors, DisagreeingSensorsAlarmOnTheWorseReading) {
  static const Scene block = testing::make(testing::paper_block());
  const auto shaking_g = [](long n) {
    const double t = static_cast<double>(n) / kRate - 1.0;
    return t < 0.0 ? 0.0 : 0.5 * std::fmin(1.0, t) * std::sin(2.0 * kPi * t);
  };
  const auto turned = [](long n, double ax_g) {
    monitor::SensorSample s = sample(n, 0.0);
    s.acceleration_g = Eigen::Vector3d(0.0, ax_g, 1.0);  // its x is the ground's y
    return s;
  };
  fw::Monitor dual;
  ASSERT_TRUE(dual.start(two_grounds(), {&block, nullptr}).ok());
  fw::Monitor correct_alone;
  ASSERT_TRUE(correct_alone.start(single_config(), {&block, nullptr}).ok());
  fw::Monitor turned_alone;
  ASSERT_TRUE(turned_alone.start(single_config(), {&block, nullptr}).ok());
  long dual_alarm = -1;
  long alone_alarm = -1;
  bool turned_alarmed = false;
  bool followed = false;
  for (long n = 0; n < 12 * static_cast<long>(kRate); ++n) {
    (void)dual.on_sensor_sample(0, turned(n, shaking_g(n)));
    (void)dual.on_sensor_sample(1, sample(n, shaking_g(n), 1'000'000));
    (void)correct_alone.on_sample(sample(n, shaking_g(n)));
    (void)turned_alone.on_sample(turned(n, shaking_g(n)));
    if (dual_alarm < 0 && dual.status().alarm == monitor::AlarmLevel::kAlarm) dual_alarm = n;
    if (alone_alarm < 0 && correct_alone.status().alarm == monitor::AlarmLevel::kAlarm) {
      alone_alarm = n;
    }
    turned_alarmed = turned_alarmed || turned_alone.status().alarm == monitor::AlarmLevel::kAlarm;
    if (dual.status().risk_sensor == 1) {
      followed = true;
      ASSERT_TRUE(dual.status().disagreement) << n;
      ASSERT_EQ(dual.status().trouble, monitor::AlarmCause::kSensorDisagreement) << n;
    }
  }
  EXPECT_FALSE(turned_alarmed);  // what one turned sensor alone says: nothing (docs/safety.md)
  ASSERT_GE(alone_alarm, 0);
  ASSERT_GE(dual_alarm, 0);
  EXPECT_LE(dual_alarm, alone_alarm + 1);
  EXPECT_TRUE(followed);
  EXPECT_EQ(dual.status().primary, 0);  // the turned sensor still drives its own estimators
}

// The primary goes silent at t = 2.5 s: the second sensor (same values, 1 ms later on the bus)
// takes over, the estimators continue from their state (the single-sensor run's estimate, to
// 1e-9), no fault level, a degraded report. Then both are silent: fault (timeout). Then the
// second comes back after 0.5 s: the estimators start again at rest.
TEST(MonitorSensors, PrimarySilentFailsOverAndTheEstimatorContinues) {
  fw::Monitor single;
  ASSERT_TRUE(started(single, single_config()));
  fw::Monitor monitor;
  ASSERT_TRUE(started(monitor, two_grounds()));
  const long silent_from = 700;
  bool fault_after_start = false;
  for (long n = 0; n < 1000; ++n) {
    (void)single.on_sample(sample(n, ground_g(n)));
    fw::MonitorUpdate u;
    if (n < silent_from) u = monitor.on_sensor_sample(0, sample(n, ground_g(n)));
    for (std::size_t i = 0; i < u.event_count; ++i) {
      fault_after_start = fault_after_start || (monitor.status().estimating &&
                                                u.events[i].level == monitor::AlarmLevel::kFault);
    }
    u = monitor.on_sensor_sample(1, sample(n, ground_g(n), 1'000'000));
    for (std::size_t i = 0; i < u.event_count; ++i) {
      fault_after_start = fault_after_start || (monitor.status().estimating &&
                                                u.events[i].level == monitor::AlarmLevel::kFault);
    }
    if (n % 2 == 0) (void)monitor.on_tick(static_cast<std::int64_t>(n) * kPeriodNs + 2'000'000);
  }
  // The estimate went on through the failover: the single sensor's (the second sensor's
  // conditioner tracked its offset on its own: 1e-9).
  expect_same_estimate(single, monitor, 1000, 1e-9);
  fw::BoxStatus s = monitor.status();
  EXPECT_FALSE(fault_after_start);
  EXPECT_EQ(s.primary, 1);
  EXPECT_EQ(s.failovers, 1U);
  EXPECT_EQ(s.failovers_continued, 1U);
  EXPECT_EQ(s.estimator_restarts, 1U);
  EXPECT_EQ(s.alarm, monitor::AlarmLevel::kNormal);
  EXPECT_EQ(s.sensors_state, monitor::HealthState::kDegraded);
  EXPECT_EQ(s.sensors[0].health.state, monitor::HealthState::kFault);
  EXPECT_EQ(s.sensors[0].health.cause, monitor::HealthCause::kTimeout);
  EXPECT_TRUE(s.sensors[1].primary);

  // Both silent: the fault level, cause sensor_timeout.
  std::int64_t t = 999 * kPeriodNs;
  bool timeout_fault = false;
  for (int k = 0; k < 20; ++k) {
    t += 10'000'000;
    const fw::MonitorUpdate u = monitor.on_tick(t);
    for (std::size_t i = 0; i < u.event_count; ++i) {
      if (u.events[i].level == monitor::AlarmLevel::kFault) {
        EXPECT_EQ(u.events[i].cause, monitor::AlarmCause::kSensorTimeout);
        timeout_fault = true;
      }
    }
  }
  EXPECT_TRUE(timeout_fault);
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kFault);
  EXPECT_EQ(monitor.status().sensors_state, monitor::HealthState::kFault);
  // The second sensor back after the gap: beyond the bridge limit, the estimators restart.
  for (long n = 1040; n < 1100; ++n) (void)monitor.on_sensor_sample(1, sample(n, 0.0));
  s = monitor.status();
  EXPECT_EQ(s.estimator_restarts, 2U);
  EXPECT_EQ(s.primary, 1);
  EXPECT_NE(s.sensors_state, monitor::HealthState::kFault);
}

// A plate sensor reading the model's own base acceleration: a small residual, and it does not
// drive the estimators (the estimate is the ground sensor's alone). Mounted backwards (x
// reversed) or with a wrong horizontal gain: the residual passes its threshold, reported; with
// plate.raises_fault also the fault level, cause kSensorDisagreement.
double run_plate(double gain, bool raises_fault, fw::BoxStatus& out, bool& fault_seen) {
  fw::Monitor single;
  EXPECT_TRUE(started(single, single_config()));
  fw::MonitorConfig config = sensors_config({fw::SensorRole::kGround, fw::SensorRole::kPlate});
  config.plate.raises_fault = raises_fault;
  fw::Monitor monitor;
  EXPECT_TRUE(started(monitor, config));
  double max_residual = 0.0;
  fault_seen = false;
  for (long n = 0; n < 1200; ++n) {
    (void)single.on_sample(sample(n, ground_g(n)));
    (void)monitor.on_sensor_sample(0, sample(n, ground_g(n)));
    expect_same_estimate(single, monitor, n);
    double plate_g = ground_g(n);
    if (monitor.status().estimating) {
      const PlanarEstimator& e = monitor.ensemble(0).nominal();
      plate_g = (e.simulator().accelerations().u + e.ground().horizontal) / kStandardGravity;
    }
    const fw::MonitorUpdate u = monitor.on_sensor_sample(1, sample(n, gain * plate_g));
    for (std::size_t i = 0; i < u.event_count; ++i) {
      if (u.events[i].level == monitor::AlarmLevel::kFault && monitor.status().estimating &&
          n > 300) {
        EXPECT_EQ(u.events[i].cause, monitor::AlarmCause::kSensorDisagreement);
        fault_seen = true;
      }
    }
    if (monitor.status().sensors[1].window_full) {
      max_residual = std::fmax(max_residual, monitor.status().plate_residual_m_s2);
    }
  }
  out = monitor.status();
  return max_residual;
}

TEST(MonitorSensors, PlateSensorMatchingTheModelHasASmallResidual) {
  fw::BoxStatus s;
  bool fault = false;
  const double residual = run_plate(1.0, true, s, fault);
  EXPECT_LT(residual, 1e-3);
  EXPECT_FALSE(s.plate_mismatch);
  EXPECT_FALSE(fault);
  EXPECT_EQ(s.plate, 1);
  EXPECT_EQ(s.primary, 0);
  EXPECT_FALSE(s.sensors[1].primary);
  EXPECT_GT(s.sensors[1].pairs, 500U);
  EXPECT_EQ(s.sensors_state, monitor::HealthState::kOk);
  EXPECT_EQ(s.alarm, monitor::AlarmLevel::kNormal);
}

TEST(MonitorSensors, PlateSensorMountedBackwardsOrScaledIsAMismatch) {
  for (const double gain : {-1.0, 2.5}) {
    fw::BoxStatus s;
    bool fault = false;
    const double residual = run_plate(gain, false, s, fault);
    EXPECT_GT(residual, 0.5) << gain;
    EXPECT_TRUE(s.plate_mismatch) << gain;
    EXPECT_GE(s.sensors[1].disagreements, 1U) << gain;
    EXPECT_EQ(s.sensors_state, monitor::HealthState::kDegraded) << gain;
    EXPECT_FALSE(fault) << gain;  // reported, not the fault level
    EXPECT_NE(s.alarm, monitor::AlarmLevel::kFault) << gain;
    EXPECT_FALSE(s.disagreement) << gain;  // the ground sensors' cross-check is another matter
    (void)run_plate(gain, true, s, fault);
    EXPECT_TRUE(fault) << gain;
    EXPECT_EQ(s.alarm, monitor::AlarmLevel::kFault) << gain;
  }
}

// Frames of each configured node go to their sensor; other nodes are counted.
TEST(MonitorSensors, FramesGoToTheirSensor) {
  fw::MonitorConfig config = sensors_config({fw::SensorRole::kGround, fw::SensorRole::kPlate});
  config.sensors[0].node = 4;
  config.sensors[1].node = 9;
  fw::Monitor monitor;
  ASSERT_TRUE(started(monitor, config));
  fw::FrameDecoder decoder;
  decoder.start(config);
  for (const int node : {4, 9, 9, 2}) {
    can::SensorAcceleration m;
    m.node = static_cast<std::uint8_t>(node);
    m.az_g = 1.0;
    can::CanFrame f;
    ASSERT_TRUE(can::encode(m, f).ok());
    (void)fw::on_frame(monitor, decoder, {f, 1000});
  }
  EXPECT_EQ(decoder.counters().sensor_samples, 3U);
  EXPECT_EQ(decoder.counters().other_nodes, 1U);
  EXPECT_EQ(monitor.status().sensors[0].health.counters.received, 1U);
  EXPECT_EQ(monitor.status().sensors[1].health.counters.received, 2U);
}

TEST(MonitorSensors, RefusesBadSensorListsNamingTheSensor) {
  fw::Monitor monitor;
  int index = -2;
  fw::MonitorConfig c = two_grounds();
  c.sensors[1].node = 1;
  EXPECT_STREQ(fw::validate(c, &index).field, "sensor.node");
  EXPECT_EQ(index, 1);
  c = sensors_config({fw::SensorRole::kPlate, fw::SensorRole::kPlate});
  EXPECT_STREQ(fw::validate(c, &index).reason, "a second plate sensor: at most one");
  c = sensors_config({fw::SensorRole::kPlate});
  EXPECT_STREQ(fw::validate(c, &index).field, "sensor.role");
  c = two_grounds();
  c.sensors[1].sensor_health.timeout_s = 1.0;
  EXPECT_STREQ(monitor.start(c, {&scene(), nullptr}).field, "sensor_health.timeout_s");
  (void)fw::validate(c, &index);
  EXPECT_EQ(index, 1);
  c = sensors_config({fw::SensorRole::kGround});
  c.redundancy.window_s = 0.001;
  EXPECT_STREQ(fw::validate(c).field, "redundancy.window_s");
  c = sensors_config({fw::SensorRole::kGround});
  c.plate.threshold_m_s2 = 0.0;
  EXPECT_STREQ(fw::validate(c).field, "plate.threshold_m_s2");
  c.sensor_count = 5;
  EXPECT_STREQ(fw::validate(c).field, "monitor.sensor_count");
}

// ---------------------------------------------------------------------------------------------
// The configuration file's [[sensor]] tables (firmware/linux/monitor_config.h).

using testing::box_file_error;

TEST(MonitorSensorsFile, SensorTablesOverTheDefaults) {
  const fw::MonitorFile f = fw::load_monitor_text(
      "[sensor_health]\ntimeout_s = 0.04\n"
      "[redundancy]\nwindow_s = 0.4\ntolerance_m_s2 = 0.2\n"
      "[plate]\nthreshold_m_s2 = 0.8\nraises_fault = true\n"
      "[[sensor]]\nnode = 1\nrole = \"ground\"\n"
      "[[sensor]]\nnode = 2\nunit = \"m/s2\"\n"
      "sensor_to_statue = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]\n"
      "sensor_health.recovery_samples = 5\n"
      "[[sensor]]\nnode = 5\nrole = \"plate\"\n[sensor.conditioning]\nstartup_window_s = 3.0\n",
      "/etc/plinth/box.toml", fw::MonitorConfig{});
  const fw::MonitorConfig& c = f.config;
  ASSERT_EQ(c.sensor_count, 3);
  EXPECT_EQ(c.sensors[0].node, 1);
  EXPECT_EQ(c.sensors[1].node, 2);
  EXPECT_EQ(c.sensors[2].node, 5);
  EXPECT_EQ(c.sensors[1].role, fw::SensorRole::kGround);
  EXPECT_EQ(c.sensors[2].role, fw::SensorRole::kPlate);
  EXPECT_EQ(c.sensors[0].conditioning.unit, monitor::AccelerationUnit::kStandardGravity);
  EXPECT_EQ(c.sensors[1].conditioning.unit, monitor::AccelerationUnit::kMetresPerSecondSquared);
  EXPECT_EQ(c.sensors[1].conditioning.sensor_to_statue(0, 1), -1.0);
  EXPECT_EQ(c.sensors[0].conditioning.sensor_to_statue(0, 1), 0.0);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(c.sensors[static_cast<std::size_t>(i)].sensor_health.timeout_s, 0.04);
  EXPECT_EQ(c.sensors[1].sensor_health.recovery_samples, 5);
  EXPECT_EQ(c.sensors[0].sensor_health.recovery_samples, 10);
  EXPECT_EQ(c.sensors[2].conditioning.startup_window_s, 3.0);
  EXPECT_EQ(c.sensors[0].conditioning.startup_window_s, 10.0);
  EXPECT_EQ(c.redundancy.window_s, 0.4);
  EXPECT_EQ(c.redundancy.tolerance_m_s2, 0.2);
  EXPECT_EQ(c.plate.threshold_m_s2, 0.8);
  EXPECT_TRUE(c.plate.raises_fault);
}

TEST(MonitorSensorsFile, BadSensorTablesNameFileLineAndKey) {
  EXPECT_EQ(box_file_error("[[sensor]]\nnode = 1\n[[sensor]]\nnode = 1\n"),
            "/etc/plinth/box.toml:4: sensor[1].node: node 1 is already sensor[0]'s");
  EXPECT_EQ(
      box_file_error("[[sensor]]\nnode = 1\n[[sensor]]\nnode = 2\nrole = \"roof\"\n"),
      "/etc/plinth/box.toml:5: sensor[1].role: expected \"ground\" or \"plate\", got \"roof\"");
  EXPECT_EQ(box_file_error("[[sensor]]\nnode = 1\n[[sensor]]\nnode = 2\nrole = \"plate\"\n"
                           "[[sensor]]\nnode = 3\nrole = \"plate\"\n"),
            "/etc/plinth/box.toml:8: sensor[2].role: a second plate sensor: at most one");
  EXPECT_EQ(box_file_error("[[sensor]]\nnode = 1\nrole = \"plate\"\n"),
            "/etc/plinth/box.toml:3: sensor[0].role: no ground sensor: at least one must drive "
            "the estimators");
  EXPECT_EQ(box_file_error("[[sensor]]\nrole = \"ground\"\n"),
            "/etc/plinth/box.toml:1: sensor[0]: no node (each [[sensor]] gives its CAN node)");
  EXPECT_EQ(box_file_error("[[sensor]]\nnode = 16\n"),
            "/etc/plinth/box.toml:2: sensor[0].node: must lie in [1, 15]");
  EXPECT_EQ(box_file_error("[[sensor]]\nnode = 1\nnodes = 2\n"),
            "/etc/plinth/box.toml:3: sensor[0].nodes: unknown key (docs/monitor.md lists them)");
  EXPECT_EQ(box_file_error("[[sensor]]\nnode = 1\nunit = \"gal\"\n"),
            "/etc/plinth/box.toml:3: sensor[0].unit: expected \"g\" or \"m/s2\", got \"gal\"");
  EXPECT_EQ(box_file_error("[monitor]\nground_node = 2\n[[sensor]]\nnode = 1\n"),
            "/etc/plinth/box.toml:2: monitor.ground_node: not with [[sensor]] tables (each gives "
            "its node)");
  EXPECT_EQ(
      box_file_error("[[sensor]]\nnode = 1\n[[sensor]]\nnode = 2\nsensor_health.timeout_s = 1.0\n")
          .rfind("/etc/plinth/box.toml:5: sensor[1].sensor_health.timeout_s: ", 0),
      0U);
  EXPECT_EQ(box_file_error(
                "[[sensor]]\nnode = 1\nsensor_to_statue = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]\n")
                .rfind("/etc/plinth/box.toml:3: sensor[0].sensor_to_statue: ", 0),
            0U);
  EXPECT_EQ(box_file_error("[redundancy]\nwindow_s = 0.001\n")
                .rfind("/etc/plinth/box.toml:2: redundancy.window_s: ", 0),
            0U);
  EXPECT_EQ(box_file_error("[[sensor]]\nnode = 1\n[[sensor]]\nnode = 2\n[[sensor]]\nnode = 3\n"
                           "[[sensor]]\nnode = 4\n[[sensor]]\nnode = 5\n"),
            "/etc/plinth/box.toml:9: sensor[4]: at most 4 sensors");
}

// The example file's [[sensor]] tables (commented out there: the example is one sensor) are
// valid once uncommented in place of monitor.ground_node.
TEST(MonitorSensorsFile, TheExamplesSensorTablesAreValid) {
  std::ifstream in(std::string(PLINTH_SOURCE_DIR) + "/firmware/monitor.example.toml");
  ASSERT_TRUE(in);
  std::string text;
  std::string line;
  int uncommented = 0;
  while (std::getline(in, line)) {
    if (line.rfind("ground_node", 0) == 0) continue;
    if (line.size() > 1 && line[0] == '#' && line[1] != ' ' && line[1] != '#') {
      line.erase(0, 1);
      ++uncommented;
    }
    text.append(line).append("\n");
  }
  ASSERT_GT(uncommented, 5);
  const fw::MonitorFile f = fw::load_monitor_text(text, "example.toml", fw::MonitorConfig{});
  EXPECT_GE(f.config.sensor_count, 2);
  int plates = 0;
  for (int i = 0; i < f.config.sensor_count; ++i) {
    plates += f.config.sensors[static_cast<std::size_t>(i)].role == fw::SensorRole::kPlate ? 1 : 0;
  }
  EXPECT_EQ(plates, 1);
}

}  // namespace
}  // namespace plinth

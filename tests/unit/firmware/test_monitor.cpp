// The box's loop (firmware/monitor): frames and samples in, phase, risk and alarms out.
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "bundled_records.h"
#include "monitor_input.h"
#include "plinth/firmware/frame_decoder.h"
#include "plinth/firmware/monitor.h"
#include "plinth/host/record_io.h"
#include "test_paths.h"
#include "test_support.h"

namespace plinth {
namespace {

namespace fw = firmware;
namespace can = hal::can;
using testing::RecordingSink;

using ::plinth::testing::kSource;

using testing::brienza;

using ::plinth::testing::ns;

// A record replayed as exact samples (m/s2, z reads g): after the lead-in the estimator starts
// at the record's first sample and gives the simulator's events at the simulator's times.
TEST(Monitor, RecordReplayGivesTheSimulatorsEvents) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  const host::Record record = brienza();
  const double gamma = 20.0;
  fw::MonitorConfig config;
  config.estimator.sample_rate_hz = 1.0 / record.dt;
  config.estimator.steps_per_sample = 4;
  config.conditioning.unit = monitor::AccelerationUnit::kMetresPerSecondSquared;
  config.conditioning.startup_window_s = 1.0;
  config.conditioning.tracking_time_constant_s = 1e6;
  config.sensor_health.stuck_samples = 0;
  config.sensor_health.full_scale_g = 1e6;  // the samples are in m/s2, not g
  config.sensor_health.max_valid_g = 1e6;
  fw::Monitor monitor;
  ASSERT_TRUE(monitor.start(config, {&scene, nullptr}).ok());
  RecordingSink estimated;
  monitor.set_event_sink(0, &estimated);
  const long lead_in = std::lround(config.conditioning.startup_window_s / record.dt) +
                       config.sensor_health.recovery_samples - 1;
  const long total = lead_in + static_cast<long>(record.horizontal.size());
  for (long n = 0; n < total && !monitor.status().axes[0].mode.terminal(); ++n) {
    monitor::SensorSample s;
    s.receive_time_ns = ns(static_cast<double>(n) * record.dt);
    s.sequence = static_cast<std::uint8_t>(n & 0xFF);
    const double a = n < lead_in ? 0.0 : gamma * record.horizontal[static_cast<std::size_t>(n - lead_in)];
    s.acceleration_g = Eigen::Vector3d(a, 0.0, kStandardGravity);
    (void)monitor.on_sample(s);
  }
  EXPECT_EQ(monitor.status().estimator_start_ns, ns(static_cast<double>(lead_in) * record.dt));
  EXPECT_EQ(monitor.status().estimator_restarts, 1U);

  RecordingSink reference;
  SolverSettings solver;
  solver.step = config.estimator.step();
  (void)testing::run(scene, Excitation::record(record.horizontal_signal(), {}, gamma),
                     record.duration(), solver.step, &reference);
  ASSERT_GE(reference.events.size(), 2U);
  ASSERT_EQ(estimated.events.size(), reference.events.size());
  for (std::size_t i = 0; i < reference.events.size(); ++i) {
    EXPECT_EQ(estimated.events[i].kind, reference.events[i].kind);
    // 1e-8 s: the offset tracking (time constant 1e6 s) still moves by ~1e-9 m/s2 while quiet.
    EXPECT_NEAR(estimated.events[i].t, reference.events[i].t, 1e-8);
  }
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kAlarm);
}

can::CanFrame sensor_frame(std::uint8_t node, std::uint8_t sequence, double ax_g) {
  can::SensorAcceleration m;
  m.node = node;
  m.ax_g = ax_g;
  m.az_g = 1.0;
  m.sequence = sequence;
  can::CanFrame f;
  EXPECT_TRUE(can::encode(m, f).ok());
  return f;
}

fw::MonitorConfig quick_config() {
  fw::MonitorConfig config;
  config.estimator.sample_rate_hz = 200.0;
  config.conditioning.startup_window_s = 0.5;
  config.sensor_health.stuck_samples = 0;
  return config;
}

// Garbled, foreign and truncated frames are counted and refused (frame_decoder.h); nothing
// reaches the solver.
TEST(Monitor, FramesAreDecodedCountedOrRefused) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  fw::Monitor monitor;
  ASSERT_TRUE(monitor.start(quick_config(), {&scene, nullptr}).ok());
  fw::FrameDecoder decoder;
  decoder.start(quick_config());
  std::int64_t t = 0;
  const auto feed = [&](const can::CanFrame& f) {
    t += ns(0.005);
    return fw::on_frame(monitor, decoder, {f, t});
  };
  for (int n = 0; n < 10; ++n) (void)feed(sensor_frame(1, static_cast<std::uint8_t>(n), 0.0));
  (void)feed(sensor_frame(2, 0, 0.0));  // another node
  can::CanFrame short_frame = sensor_frame(1, 10, 0.0);
  short_frame.length = 3;
  (void)feed(short_frame);
  can::CanFrame reserved = sensor_frame(1, 10, 0.0);
  reserved.data[7] |= 0xF0;  // status bits 4-7 are reserved
  (void)feed(reserved);
  can::CanFrame foreign;
  foreign.id = 0x123;
  foreign.length = 8;
  (void)feed(foreign);
  can::CanFrame heartbeat;
  ASSERT_TRUE(can::encode(can::SensorHeartbeat{1, 100, 1, 2, 0, 0, 0}, heartbeat).ok());
  (void)feed(heartbeat);
  can::CanFrame status;
  ASSERT_TRUE(can::encode(can::MonitorStatus{}, status).ok());
  (void)feed(status);
  const fw::FrameCounters& c = decoder.counters();
  EXPECT_EQ(c.received, 16U);
  EXPECT_EQ(c.sensor_samples, 10U);
  EXPECT_EQ(c.other_nodes, 1U);
  EXPECT_EQ(c.rejected, 2U);
  EXPECT_EQ(c.unknown_identifiers, 1U);
  EXPECT_EQ(c.heartbeats, 1U);
  EXPECT_EQ(c.monitor_frames, 1U);
  EXPECT_EQ(c.last_error, can::CodecError::kReservedBitsSet);
  EXPECT_EQ(monitor.status().sensor.counters.received, 10U);
}

// The ground sensor goes silent: fault (sensor timeout) within the timeout; when it comes back
// the estimator starts again at rest and the fault clears.
TEST(Monitor, SensorSilenceIsAFaultAndTheEstimatorRestartsAfterIt) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  fw::MonitorConfig config = quick_config();
  fw::Monitor monitor;
  ASSERT_TRUE(monitor.start(config, {&scene, nullptr}).ok());
  fw::FrameDecoder decoder;
  decoder.start(config);
  std::uint8_t sequence = 0;
  std::int64_t t = 0;
  const auto feed_for = [&](double seconds) {
    for (int n = 0; n < std::lround(seconds * 200.0); ++n) {
      (void)fw::on_frame(monitor, decoder, {sensor_frame(1, sequence++, 0.0), t});
      t += ns(0.005);
    }
  };
  feed_for(4.0);
  ASSERT_TRUE(monitor.status().estimating);
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kNormal);
  EXPECT_EQ(monitor.status().estimator_restarts, 1U);
  // Silence: ticks every 10 ms; the fault comes within timeout_s (+ one tick).
  const std::int64_t last = t - ns(0.005);
  std::int64_t fault_at = -1;
  for (int k = 1; k <= 30 && fault_at < 0; ++k) {
    const fw::MonitorUpdate u = monitor.on_tick(last + ns(0.01 * k));
    for (std::size_t i = 0; i < u.event_count; ++i) {
      if (u.events[i].level == monitor::AlarmLevel::kFault) {
        EXPECT_EQ(u.events[i].cause, monitor::AlarmCause::kSensorTimeout);
        fault_at = last + ns(0.01 * k);
      }
    }
  }
  ASSERT_GT(fault_at, 0);
  EXPECT_LE(fault_at - last, ns(config.sensor_health.timeout_s + 0.01));
  t = fault_at + ns(1.0);
  // The estimator restarts at rest after recovery_samples, not calibrated (what the block did
  // meanwhile is unknown): fault, cause not_calibrated, until a verification window (0.5 s)
  // of quiet input passes.
  feed_for(0.2);
  EXPECT_EQ(monitor.status().estimator_restarts, 2U);
  EXPECT_TRUE(monitor.status().estimating);
  EXPECT_FALSE(monitor.status().calibrated);
  EXPECT_TRUE(monitor.conditioning().verifying);
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kFault);
  feed_for(0.5);
  EXPECT_TRUE(monitor.status().calibrated);
  feed_for(3.3);
  EXPECT_EQ(monitor.status().estimator_restarts, 2U);
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kNormal);
  EXPECT_EQ(monitor.status().sensor.counters.timeouts, 1U);
}

// The ground falling faster than gravity (the sensor's z reads -0.5 g: v_G'' = -1.5 g) lifts the
// modelled block off: the estimator's model ends (phase lifted_off), which is no collapse; the
// box says it cannot vouch (fault, cause outside_model) until the estimators start again.
TEST(Monitor, LiftOffIsOutsideTheModelNotACollapse) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  fw::Monitor monitor;
  ASSERT_TRUE(monitor.start(quick_config(), {&scene, nullptr}).ok());
  fw::FrameDecoder decoder;
  decoder.start(quick_config());
  RecordingSink events;
  monitor.set_event_sink(0, &events);
  std::uint8_t sequence = 0;
  std::int64_t t = 0;
  std::vector<monitor::AlarmEventRecord> alarms;
  const auto feed_for = [&](double seconds, double az_g) {
    for (int n = 0; n < std::lround(seconds * 200.0); ++n) {
      can::SensorAcceleration m;
      m.node = 1;
      m.az_g = az_g;
      m.sequence = sequence++;
      can::CanFrame f;
      ASSERT_TRUE(can::encode(m, f).ok());
      const fw::MonitorUpdate u = fw::on_frame(monitor, decoder, {f, t});
      for (std::size_t i = 0; i < u.event_count; ++i) alarms.push_back(u.events[i]);
      t += ns(0.005);
    }
  };
  feed_for(4.0, 1.0);
  ASSERT_EQ(monitor.status().alarm, monitor::AlarmLevel::kNormal);
  feed_for(0.1, -0.5);
  const Event* lift = events.first(EventKind::kLiftOff);
  ASSERT_NE(lift, nullptr);
  // As g + v_G'' reaches 0, Eq 16's threshold (b/h)(g + v_G'') vanishes with it: the block may
  // tip onto a corner at the same instant, within the events' time tolerance.
  EXPECT_TRUE(lift->left == Phase::kFullContact || lift->left == Phase::kRocking);
  EXPECT_EQ(monitor.status().axes[0].mode.phase, Phase::kLiftedOff);
  EXPECT_TRUE(monitor.status().axes[0].outside_model);
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kFault);
  ASSERT_FALSE(alarms.empty());
  EXPECT_EQ(alarms.back().level, monitor::AlarmLevel::kFault);
  EXPECT_EQ(alarms.back().cause, monitor::AlarmCause::kOutsideModel);
  for (const monitor::AlarmEventRecord& a : alarms) {
    EXPECT_NE(a.cause, monitor::AlarmCause::kOverturnDetected) << "a lift-off is no collapse";
  }
  feed_for(5.0, 1.0);  // quiet again: the box still cannot vouch
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kFault);
  EXPECT_EQ(monitor.status().axes[0].mode.phase, Phase::kLiftedOff);
}

// A collapse latches the alarm; an Acknowledge frame quoting the latest event releases the
// latch, the alarm stays (its condition holds), a stale one changes nothing.
TEST(Monitor, AcknowledgeFrameReleasesTheLatch) {
  const Scene scene = testing::make(testing::paper_block(0.0));
  fw::Monitor monitor;
  ASSERT_TRUE(monitor.start(quick_config(), {&scene, nullptr}).ok());
  fw::FrameDecoder decoder;
  decoder.start(quick_config());
  std::int64_t t = 0;
  std::uint8_t sequence = 0;
  std::uint8_t last_event = 0;
  // Quiet start-up, then a 1 s push of 0.6 g: the non-isolated block (b1/h = 1/3) overturns.
  for (int n = 0; n < 1400 && !monitor.status().axes[0].mode.terminal(); ++n) {
    const double a = n >= 400 && n < 600 ? 0.6 : 0.0;
    const fw::MonitorUpdate u = fw::on_frame(monitor, decoder, {sensor_frame(1, sequence++, a), t});
    for (std::size_t i = 0; i < u.event_count; ++i) last_event = u.events[i].sequence;
    t += ns(0.005);
  }
  ASSERT_EQ(monitor.status().axes[0].mode.phase, Phase::kOverturned);
  ASSERT_EQ(monitor.status().alarm, monitor::AlarmLevel::kAlarm);
  ASSERT_EQ(monitor.status().latched, monitor::AlarmLevel::kAlarm);
  can::CanFrame ack;
  ASSERT_TRUE(can::encode(can::Acknowledge{can::AlarmLevel::kAlarm, 7,
                                           static_cast<std::uint8_t>(last_event + 1)}, ack).ok());
  EXPECT_EQ(fw::on_frame(monitor, decoder, {ack, t}).acknowledgement, monitor::AckOutcome::kStale);
  ASSERT_TRUE(can::encode(can::Acknowledge{can::AlarmLevel::kAlarm, 7, last_event}, ack).ok());
  EXPECT_EQ(fw::on_frame(monitor, decoder, {ack, t}).acknowledgement,
            monitor::AckOutcome::kReleasedConditionHolds);
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kAlarm);
  EXPECT_EQ(decoder.counters().acknowledgements, 2U);
}

// An operator's acknowledgement from Modbus or MQTT is a call (Monitor::acknowledge), not a
// frame: the same update and status as the Acknowledge frame's, and no frame counted.
TEST(Monitor, AcknowledgeIsACallAsTheFrameIs) {
  const Scene scene = testing::make(testing::paper_block(0.0));
  fw::Monitor by_frame;
  fw::Monitor by_call;
  ASSERT_TRUE(by_frame.start(quick_config(), {&scene, nullptr}).ok());
  ASSERT_TRUE(by_call.start(quick_config(), {&scene, nullptr}).ok());
  fw::FrameDecoder decoder;
  decoder.start(quick_config());
  std::int64_t t = 0;
  std::uint8_t last_event = 0;
  for (int n = 0; n < 1400 && !by_call.status().axes[0].mode.terminal(); ++n) {
    const double a = n >= 400 && n < 600 ? 0.6 : 0.0;
    const can::CanFrame f = sensor_frame(1, static_cast<std::uint8_t>(n & 0xFF), a);
    (void)fw::on_frame(by_frame, decoder, {f, t});
    const fw::MonitorUpdate u = by_call.on_sample(
        {t, static_cast<std::uint8_t>(n & 0xFF), 0, Eigen::Vector3d(a, 0.0, 1.0)});
    EXPECT_EQ(u.status, &by_call.status());
    for (std::size_t i = 0; i < u.event_count; ++i) last_event = u.events[i].sequence;
    t += ns(0.005);
  }
  ASSERT_EQ(by_call.status().latched, monitor::AlarmLevel::kAlarm);
  const std::uint64_t frames_before = decoder.counters().received;
  can::CanFrame ack;
  ASSERT_TRUE(can::encode(can::Acknowledge{can::AlarmLevel::kAlarm, 7, last_event}, ack).ok());
  const fw::MonitorUpdate from_frame = fw::on_frame(by_frame, decoder, {ack, t});
  const fw::MonitorUpdate from_call =
      by_call.acknowledge({monitor::AlarmLevel::kAlarm, last_event});
  EXPECT_EQ(from_call.acknowledgement, monitor::AckOutcome::kReleasedConditionHolds);
  EXPECT_EQ(from_call.acknowledgement, from_frame.acknowledgement);
  ASSERT_EQ(from_call.event_count, from_frame.event_count);
  ASSERT_EQ(from_call.event_count, 1U);
  EXPECT_EQ(from_call.events[0].cause, monitor::AlarmCause::kAcknowledged);
  ASSERT_EQ(from_call.frame_count, from_frame.frame_count);
  for (std::size_t i = 0; i < from_call.frame_count; ++i) {
    EXPECT_EQ(from_call.frames[i].id, from_frame.frames[i].id) << i;
    EXPECT_EQ(from_call.frames[i].data, from_frame.frames[i].data) << i;
  }
  EXPECT_EQ(by_call.status().latched, monitor::AlarmLevel::kNormal);
  EXPECT_EQ(by_call.status().alarm, by_frame.status().alarm);
  EXPECT_EQ(decoder.counters().received, frames_before + 1);  // the frame path's one frame
}

TEST(Monitor, RefusesBadConfigurationNamingTheField) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  fw::Monitor monitor;
  fw::MonitorConfig c = quick_config();
  c.axis_count = 3;
  EXPECT_STREQ(monitor.start(c, {&scene, &scene}).field, "monitor.axis_count");
  c = quick_config();
  c.axis_count = 2;
  EXPECT_STREQ(monitor.start(c, {&scene, nullptr}).field, "monitor.axis_count");
  c = quick_config();
  c.ground_node = 0;
  EXPECT_STREQ(monitor.start(c, {&scene, nullptr}).field, "monitor.ground_node");
  c = quick_config();
  c.quiet_risk = std::nan("");
  EXPECT_STREQ(monitor.start(c, {&scene, nullptr}).field, "monitor.quiet_risk");
  c = quick_config();
  c.estimator.sample_rate_hz = 5000.0;
  EXPECT_STREQ(monitor.start(c, {&scene, nullptr}).field, "estimator.sample_rate_hz");
  c = quick_config();
  c.alarm.warning.off = 0.9;
  EXPECT_FALSE(monitor.start(c, {&scene, nullptr}).ok());
}

// An ensemble: a member's estimate does not depend on where it stands in the ensemble (the
// offset tracking waits for every member); the axis's risk is the worst member's, its mode,
// state and nominal_risk the nominal statue's (member 0).
TEST(Monitor, EnsembleMembersFollowTheirOwnStatues) {
  std::vector<Scene> statues;
  for (const double height_factor : {1.0, 0.87, 1.13}) {  // slenderness 3, 2.6, 3.4
    SceneParams p = testing::paper_isolated(0.0);
    p.block.com_height *= height_factor;
    statues.push_back(testing::make(p));
  }
  const std::vector<Scene> rotated{statues[1], statues[2], statues[0]};
  fw::MonitorConfig config;
  config.estimator.sample_rate_hz = 200.0;
  fw::Monitor first;
  fw::Monitor second;
  ASSERT_TRUE(first.start(config, {std::span<const Scene>(statues), {}}).ok());
  ASSERT_TRUE(second.start(config, {std::span<const Scene>(rotated), {}}).ok());
  ASSERT_EQ(first.ensemble(0).size(), 3);
  testing::QuietThenQuake input(200.0, 10.0, brienza(), 12.0);
  testing::QuietThenQuake same(200.0, 10.0, brienza(), 12.0);  // the same samples again
  bool worst_not_nominal = false;
  for (long n = 0; n < input.size(); ++n) {
    (void)first.on_sample(input.sample(n));
    (void)second.on_sample(same.sample(n));
    double worst = 0.0;
    double nominal = 0.0;
    for (int m = 0; m < 3; ++m) {
      const PlanarEstimator& e = first.ensemble(0).member(m);
      ASSERT_EQ(e.state(), second.ensemble(0).member((m + 2) % 3).state()) << n << " " << m;
      const double r = overturning_risk(statues[static_cast<std::size_t>(m)], e.mode(),
                                        e.state(), config.risk).total;
      worst = std::fmax(worst, r);
      if (m == 0) nominal = r;
    }
    const fw::AxisStatus& axis = first.status().axes[0];
    if (!first.status().estimating) continue;
    ASSERT_EQ(axis.state, first.ensemble(0).nominal().state());
    ASSERT_EQ(axis.risk.total, worst);
    ASSERT_EQ(axis.nominal_risk.total, nominal);
    ASSERT_EQ(axis.risk.total, second.status().axes[0].risk.total);
    worst_not_nominal = worst_not_nominal || (axis.worst_member != 0 && worst > 0.0);
    if (axis.forecast.valid) {
      ASSERT_EQ(axis.forecast.members, 3);
    }
  }
  EXPECT_TRUE(worst_not_nominal);  // the slenderer statue is the more fragile at times
}

// Quiet noise with a drifting sensor bias, then an earthquake that overturns the block: no
// alarm in the quiet part (only the start-up fault), the bias followed, the block at rest, and
// the alarm in the earthquake, ahead of the overturn. (An hour of it, counting allocations, is
// in test_no_allocation.cpp.)
void quiet_then_quake(double quiet_s) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  testing::QuietThenQuake input(200.0, quiet_s, brienza(), 20.0);
  fw::MonitorConfig config;
  config.estimator.sample_rate_hz = 200.0;
  fw::Monitor monitor;
  ASSERT_TRUE(monitor.start(config, {&scene, nullptr}).ok());
  double peak_quiet_u = 0.0;
  double alarm_t = -1.0;
  double false_alarm_t = -1.0;
  for (long n = 0; n < input.size(); ++n) {
    const fw::MonitorUpdate u = monitor.on_sample(input.sample(n));
    const bool quiet = n < input.quiet_samples();
    for (std::size_t i = 0; i < u.event_count; ++i) {
      const monitor::AlarmLevel level = u.events[i].level;
      if (quiet && level != monitor::AlarmLevel::kNormal && level != monitor::AlarmLevel::kFault &&
          false_alarm_t < 0.0) {
        false_alarm_t = input.time(n);
      }
      if (!quiet && level == monitor::AlarmLevel::kAlarm && alarm_t < 0.0) alarm_t = input.time(n);
    }
    if (quiet && monitor.status().estimating) {
      peak_quiet_u = std::fmax(peak_quiet_u, std::fabs(monitor.status().axes[0].state[kU]));
      ASSERT_EQ(monitor.status().axes[0].mode.phase, Phase::kFullContact) << input.time(n);
    }
    if (n == input.quiet_samples() - 1) {
      const Eigen::Vector3d bias = input.bias_g(n) * kStandardGravity;
      const Eigen::Vector3d error = monitor.conditioning().offset_m_s2 - bias;
      EXPECT_LT(error.cwiseAbs().maxCoeff(), 1e-3 * kStandardGravity) << error.x() << " " << error.y() << " " << error.z();
    }
    if (monitor.status().axes[0].mode.terminal()) break;
  }
  EXPECT_LT(false_alarm_t, 0.0) << "false alarm at t = " << false_alarm_t;
  EXPECT_LT(peak_quiet_u, 1e-3);
  ASSERT_GT(alarm_t, 0.0);
  EXPECT_EQ(monitor.status().axes[0].mode.phase, Phase::kOverturned);
  EXPECT_LT(alarm_t, quiet_s + 10.65);  // the overturn, from RecordReplayGivesTheSimulatorsEvents
}

TEST(Monitor, QuietThenQuakeFiveMinutes) { quiet_then_quake(300.0); }

// A regional alert through the monitor: as the bus's frames and as a call (MQTT's), the same
// update; warning with cause regional_alert while quiet; the time to the S arrival counts down
// with the samples; the alert expires and the warning stays latched.
TEST(Monitor, ARegionalAlertRaisesWarningAndExpires) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  fw::MonitorConfig config = quick_config();
  config.regional.fragility_known = true;
  config.regional.fragility = {0.6, 0.5};
  config.regional.expiry_margin_s = 1.0;
  fw::Monitor by_frame;
  fw::Monitor by_call;
  ASSERT_TRUE(by_frame.start(config, {&scene, nullptr}).ok());
  ASSERT_TRUE(by_call.start(config, {&scene, nullptr}).ok());
  fw::FrameDecoder decoder;
  decoder.start(config);
  std::int64_t t = 0;
  const auto quiet = [&](int samples) {
    for (int n = 0; n < samples; ++n) {
      const auto sequence = static_cast<std::uint8_t>((t / ns(0.005)) & 0xFF);
      const can::CanFrame f = sensor_frame(1, sequence, 0.0);
      (void)fw::on_frame(by_frame, decoder, {f, t});
      (void)by_call.on_sample({t, sequence, 0, Eigen::Vector3d(0.0, 0.0, 1.0)});
      t += ns(0.005);
    }
  };
  quiet(800);  // 4 s: calibrated, the start-up fault cleared (lower_hold_s 2 s), normal
  ASSERT_EQ(by_call.status().alarm, monitor::AlarmLevel::kNormal);
  // M 5 at 30 km, 1.2 g expected (sigma 0.5), S in 2 s.
  can::RegionalAlertOrigin origin{9, 1, 5.0, 3.0, 30, false};
  can::RegionalAlert alert{9, 1, 1.2, 0.5, 2.0};
  can::CanFrame fo;
  can::CanFrame fa;
  ASSERT_TRUE(can::encode(origin, fo).ok());
  ASSERT_TRUE(can::encode(alert, fa).ok());
  (void)fw::on_frame(by_frame, decoder, {fo, t - ns(0.001)});
  const fw::MonitorUpdate from_frame = fw::on_frame(by_frame, decoder, {fa, t - ns(0.001)});
  const fw::MonitorUpdate from_call =
      by_call.on_regional_alert(monitor::RegionalAlert{9, 1, false, 5.0, 30.0, 3.0, 1.2, 0.5, 2.0});
  for (const fw::MonitorUpdate* u : {&from_frame, &from_call}) {
    EXPECT_TRUE(u->regional_received);
    EXPECT_TRUE(u->regional.accepted());
    ASSERT_EQ(u->event_count, 1U);
    EXPECT_EQ(u->events[0].level, monitor::AlarmLevel::kWarning);
    EXPECT_EQ(u->events[0].cause, monitor::AlarmCause::kRegionalAlert);
    // Phi(ln(1.2 / 0.6) / sqrt(0.5^2 + 0.5^2)) = 0.8365
    EXPECT_NEAR(u->status->regional.probability, 0.8365, 1e-4);
    EXPECT_NEAR(u->status->regional.time_to_s_arrival_s, 2.0, 1e-3);
  }
  quiet(200);  // 1 s
  EXPECT_NEAR(by_call.status().regional.time_to_s_arrival_s, 1.0, 0.01);
  // Expiry: S arrival (2 s) + M 5's 1.1 s at 30 km (+1.5 s) + the 1 s margin = 5.6 s after.
  quiet(1000);
  EXPECT_EQ(by_call.status().regional.held, 0);
  EXPECT_EQ(by_frame.status().regional.held, 0);
  EXPECT_EQ(by_call.status().regional.expired, 1U);
  EXPECT_EQ(by_call.status().alarm, monitor::AlarmLevel::kWarning);  // latched
  EXPECT_EQ(by_call.status().latched, monitor::AlarmLevel::kWarning);
}

}  // namespace
}  // namespace plinth

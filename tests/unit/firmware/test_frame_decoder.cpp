// The bus's frames as the monitor's inputs (frame_decoder.h): a configured node's sample goes
// to its sensor's index, an Acknowledge is an acknowledgement, anything else is no input.
#include <gtest/gtest.h>

#include "plinth/firmware/can_frames.h"
#include "plinth/firmware/frame_decoder.h"
#include "plinth/monitor/hmac_sha256.h"
#include "test_support.h"

namespace plinth::firmware {

// The CAN protocol (hal/can_codec).
namespace can = hal::can;
namespace {

MonitorConfig two_sensors() {
  MonitorConfig config;
  config.sensor_count = 2;
  config.sensors[0].node = 4;
  config.sensors[1].node = 9;
  config.sensors[1].role = SensorRole::kPlate;
  return config;
}

can::CanFrame encoded(const auto& message) {
  can::CanFrame f;
  EXPECT_TRUE(can::encode(message, f).ok());
  return f;
}

TEST(FrameDecoder, ASensorFrameIsItsSensorsSample) {
  FrameDecoder decoder;
  decoder.start(two_sensors());
  can::SensorAcceleration m;
  m.node = 9;
  m.ax_g = 0.25;
  m.ay_g = -0.5;
  m.az_g = 1.0;
  m.sequence = 77;
  m.status = monitor::sensor_flags::kOverTemperature;
  const FrameInput in = decoder.decode({encoded(m), 123'456});
  ASSERT_EQ(in.kind, FrameInput::Kind::kSensorSample);
  EXPECT_EQ(in.sensor, 1);  // node 9: the second configured sensor
  EXPECT_EQ(in.sample.receive_time_ns, 123'456);
  EXPECT_EQ(in.sample.sequence, 77);
  EXPECT_EQ(in.sample.status, monitor::sensor_flags::kOverTemperature);
  EXPECT_EQ(in.sample.acceleration_g, Vector3r(Real(0.25), Real(-0.5), Real(1.0)));
  m.node = 5;  // not configured
  EXPECT_EQ(decoder.decode({encoded(m), 0}).kind, FrameInput::Kind::kNone);
  EXPECT_EQ(decoder.counters().sensor_samples, 1U);
  EXPECT_EQ(decoder.counters().other_nodes, 1U);
}

// The statue sensor's node: its StatueRotation is the gyroscope's sample, its
// SensorAcceleration the accelerometer's; another node's StatueRotation, or one without a
// statue sensor configured, is no input; a garbled one is refused and counted.
TEST(FrameDecoder, TheStatueSensorsFramesAreItsSamples) {
  MonitorConfig config = two_sensors();
  config.statue_sensor.present = true;
  config.statue_sensor.node = 6;
  FrameDecoder decoder;
  decoder.start(config);
  can::StatueRotation r;
  r.node = 6;
  r.wx_rad_s = 0.5;
  r.wy_rad_s = -1.25;
  r.wz_rad_s = 0.0005;
  r.sequence = 200;
  r.status = monitor::sensor_flags::kSaturated;
  FrameInput in = decoder.decode({encoded(r), 5'000});
  ASSERT_EQ(in.kind, FrameInput::Kind::kStatueRate);
  EXPECT_EQ(in.statue.receive_time_ns, 5'000);
  EXPECT_EQ(in.statue.sequence, 200);
  EXPECT_EQ(in.statue.status, monitor::sensor_flags::kSaturated);
  EXPECT_EQ(in.statue.rotation_rate_rad_s, Vector3r(Real(0.5), Real(-1.25), Real(0.0005)));
  EXPECT_EQ(can::decode(encoded(rotation_message(6, in.statue)), r).error, can::CodecError::kOk);
  EXPECT_EQ(r.wy_rad_s, -1.25);
  can::SensorAcceleration a;
  a.node = 6;
  a.az_g = 1.0;
  in = decoder.decode({encoded(a), 6'000});
  ASSERT_EQ(in.kind, FrameInput::Kind::kStatueAcceleration);
  EXPECT_EQ(in.sample.acceleration_g, Vector3r(0, 0, 1));
  r.node = 7;
  EXPECT_EQ(decoder.decode({encoded(r), 0}).kind, FrameInput::Kind::kNone);
  can::CanFrame garbled = encoded(r);
  garbled.id = 0x376;
  garbled.length = 7;
  EXPECT_EQ(decoder.decode({garbled, 0}).kind, FrameInput::Kind::kNone);
  EXPECT_EQ(decoder.counters().statue_rates, 1U);
  EXPECT_EQ(decoder.counters().statue_accelerations, 1U);
  EXPECT_EQ(decoder.counters().other_nodes, 1U);
  EXPECT_EQ(decoder.counters().rejected, 1U);
  EXPECT_EQ(decoder.counters().last_error, can::CodecError::kWrongLength);
  decoder.start(two_sensors());  // no statue sensor: its frames are another node's
  r.node = 6;
  EXPECT_EQ(decoder.decode({encoded(r), 0}).kind, FrameInput::Kind::kNone);
  EXPECT_EQ(decoder.counters().other_nodes, 1U);
}

// The single-sensor form: its ground_node.
TEST(FrameDecoder, TheSingleSensorFormsNode) {
  MonitorConfig config;
  config.ground_node = 3;
  FrameDecoder decoder;
  decoder.start(config);
  can::SensorAcceleration m;
  m.node = 3;
  const FrameInput in = decoder.decode({encoded(m), 0});
  EXPECT_EQ(in.kind, FrameInput::Kind::kSensorSample);
  EXPECT_EQ(in.sensor, 0);
}

TEST(FrameDecoder, AnAcknowledgeIsAnAcknowledgement) {
  FrameDecoder decoder;
  decoder.start(two_sensors());
  const FrameInput in =
      decoder.decode({encoded(can::Acknowledge{can::AlarmLevel::kWarning, 3, 201}), 0});
  ASSERT_EQ(in.kind, FrameInput::Kind::kAcknowledgement);
  EXPECT_EQ(in.acknowledgement.level, monitor::AlarmLevel::kWarning);
  EXPECT_EQ(in.acknowledgement.event_sequence, 201);
  EXPECT_EQ(decoder.counters().acknowledgements, 1U);
}

// Heartbeats, another box's frames, refused and foreign frames: no input, each counted; a new
// start counts afresh.
TEST(FrameDecoder, OtherFramesAreNoInputAndCounted) {
  FrameDecoder decoder;
  decoder.start(two_sensors());
  EXPECT_EQ(decoder.decode({encoded(can::SensorHeartbeat{4, 1, 0, 1, 0, 0, 0}), 0}).kind,
            FrameInput::Kind::kNone);
  EXPECT_EQ(decoder.decode({encoded(can::AlarmEvent{}), 0}).kind, FrameInput::Kind::kNone);
  can::CanFrame bad = encoded(can::SensorAcceleration{4, 0.0, 0.0, 1.0, 0, 0});
  bad.length = 7;
  EXPECT_EQ(decoder.decode({bad, 0}).kind, FrameInput::Kind::kNone);
  can::CanFrame foreign;
  foreign.id = 0x123;
  foreign.length = 8;
  EXPECT_EQ(decoder.decode({foreign, 0}).kind, FrameInput::Kind::kNone);
  const FrameCounters& c = decoder.counters();
  EXPECT_EQ(c.received, 4U);
  EXPECT_EQ(c.heartbeats, 1U);
  EXPECT_EQ(c.monitor_frames, 1U);
  EXPECT_EQ(c.rejected, 1U);
  EXPECT_EQ(c.last_error, can::CodecError::kWrongLength);
  EXPECT_EQ(c.unknown_identifiers, 1U);
  decoder.start(two_sensors());
  EXPECT_EQ(decoder.counters().received, 0U);
}

// A regional alert is its RegionalAlertOrigin then its RegionalAlert frame (same event and
// version, within 100 ms); an alert frame without its origin frame is a malformed alert.
TEST(FrameDecoder, ARegionalAlertIsItsTwoFrames) {
  FrameDecoder decoder;
  decoder.start(two_sensors());
  can::RegionalAlertOrigin origin;
  origin.event_id = 77;
  origin.version = 2;
  origin.magnitude = 7.0;
  origin.origin_age_s = 10.0;
  origin.distance_km = 120;
  can::RegionalAlert alert;
  alert.event_id = 77;
  alert.version = 2;
  alert.pga_g = 0.3;
  alert.sigma_ln = 0.6;
  alert.s_arrival_in_s = 20.0;
  EXPECT_EQ(decoder.decode({encoded(origin), 1000 * kMs}).kind, FrameInput::Kind::kNone);
  const FrameInput in = decoder.decode({encoded(alert), 1020 * kMs});
  ASSERT_EQ(in.kind, FrameInput::Kind::kRegionalAlert);
  EXPECT_EQ(in.regional.event_id, 77U);
  EXPECT_NEAR(in.regional.origin_age_s, 10.02, 1e-9);
  EXPECT_NEAR(in.regional.pga_g, 0.3, 1e-12);
  // The origin frame is used once: the same alert frame again has none.
  FrameInput again = decoder.decode({encoded(alert), 1030 * kMs});
  EXPECT_EQ(again.kind, FrameInput::Kind::kRegionalMalformed);
  EXPECT_STREQ(again.malformed_field, "RegionalAlertOrigin");
  // Another event's origin, and an origin too long before.
  can::RegionalAlertOrigin other = origin;
  other.event_id = 78;
  (void)decoder.decode({encoded(other), 2000 * kMs});
  EXPECT_EQ(decoder.decode({encoded(alert), 2001 * kMs}).kind,
            FrameInput::Kind::kRegionalMalformed);
  (void)decoder.decode({encoded(origin), 3000 * kMs});
  EXPECT_EQ(decoder.decode({encoded(alert), 3101 * kMs}).kind,
            FrameInput::Kind::kRegionalMalformed);
  // A frame the codec refuses (a magnitude raw above 200): malformed, naming the signal.
  can::CanFrame bad = encoded(origin);
  bad.data[3] = 250;
  const FrameInput refused = decoder.decode({bad, 4000 * kMs});
  EXPECT_EQ(refused.kind, FrameInput::Kind::kRegionalMalformed);
  EXPECT_STREQ(refused.malformed_field, "Magnitude");
  // A refusal no signal explains (the length) names the frame: a short origin frame, a short
  // alert frame after a good origin.
  can::CanFrame short_origin = encoded(origin);
  short_origin.length = 7;
  EXPECT_STREQ(decoder.decode({short_origin, 5000 * kMs}).malformed_field, "RegionalAlertOrigin");
  (void)decoder.decode({encoded(origin), 6000 * kMs});
  can::CanFrame short_alert = encoded(alert);
  short_alert.length = 5;
  EXPECT_STREQ(decoder.decode({short_alert, 6001 * kMs}).malformed_field, "RegionalAlert");
  EXPECT_EQ(decoder.counters().regional_alerts, 1U);
  EXPECT_EQ(decoder.counters().regional_malformed, 6U);
}

// With a key, the pair waits for its RegionalAlertTag: the HMAC of both frames' data and the
// counter, the counter above the last taken. A missing tag, a wrong one or a replayed counter is
// an unauthenticated alert; without a key the tag frame is ignored.
TEST(FrameDecoder, AKeyedRegionalAlertNeedsItsTag) {
  MonitorConfig config = two_sensors();
  monitor::RegionalAlertSettings& room = config.regional;
  room.authentication.required = true;
  for (std::size_t i = 0; i < room.authentication.key.size(); ++i) {
    room.authentication.key[i] = static_cast<std::uint8_t>(3 * i + 1);
  }
  FrameDecoder decoder;
  decoder.start(config);
  const can::RegionalAlertOrigin origin{77, 2, 7.0, 10.0, 120, false};
  const can::RegionalAlert alert{77, 2, 0.3, 0.6, 20.0};
  const can::CanFrame fo = encoded(origin);
  const can::CanFrame fa = encoded(alert);
  // The bridge's tag: HMAC-SHA256(key, origin data, alert data, counter bytes), its first 4.
  const auto tag_frame = [&](std::uint32_t counter, const monitor::RegionalAuthentication& auth) {
    can::CanFrame probe = encoded(can::RegionalAlertTag{counter, 0});
    const monitor::ByteSpan parts[] = {
        {fo.data.data(), 8}, {fa.data.data(), 8}, {probe.data.data(), 4}};
    const monitor::Sha256Digest mac = monitor::hmac_sha256(auth.key, parts, 3);
    const std::uint32_t tag = static_cast<std::uint32_t>(mac[0]) |
                              static_cast<std::uint32_t>(mac[1]) << 8 |
                              static_cast<std::uint32_t>(mac[2]) << 16 |
                              static_cast<std::uint32_t>(mac[3]) << 24;
    return encoded(can::RegionalAlertTag{counter, tag});
  };
  EXPECT_EQ(decoder.decode({fo, 1000 * kMs}).kind, FrameInput::Kind::kNone);
  EXPECT_EQ(decoder.decode({fa, 1010 * kMs}).kind, FrameInput::Kind::kNone) << "waits";
  const FrameInput taken = decoder.decode({tag_frame(5, room.authentication), 1030 * kMs});
  ASSERT_EQ(taken.kind, FrameInput::Kind::kRegionalAlert);
  EXPECT_EQ(taken.regional.event_id, 77U);
  EXPECT_NEAR(taken.regional.origin_age_s, 10.03, 1e-9) << "relative to the tag's time";
  EXPECT_NEAR(taken.regional.s_arrival_in_s, 19.98, 1e-9);
  // The same three frames again: the counter is not above the last taken.
  (void)decoder.decode({fo, 2000 * kMs});
  (void)decoder.decode({fa, 2001 * kMs});
  const FrameInput replay = decoder.decode({tag_frame(5, room.authentication), 2002 * kMs});
  EXPECT_EQ(replay.kind, FrameInput::Kind::kRegionalUnauthenticated);
  EXPECT_STREQ(replay.malformed_field, "Counter");
  // Another key's tag.
  monitor::RegionalAuthentication other = room.authentication;
  other.key[0] ^= 1;
  (void)decoder.decode({fo, 3000 * kMs});
  (void)decoder.decode({fa, 3001 * kMs});
  const FrameInput forged = decoder.decode({tag_frame(6, other), 3002 * kMs});
  EXPECT_EQ(forged.kind, FrameInput::Kind::kRegionalUnauthenticated);
  EXPECT_STREQ(forged.malformed_field, "Tag");
  // No tag: the next alert's origin frame says so; a tag too late is no tag.
  (void)decoder.decode({fo, 4000 * kMs});
  (void)decoder.decode({fa, 4001 * kMs});
  const FrameInput untagged = decoder.decode({fo, 5000 * kMs});
  EXPECT_EQ(untagged.kind, FrameInput::Kind::kRegionalUnauthenticated);
  EXPECT_STREQ(untagged.malformed_field, "RegionalAlertTag");
  (void)decoder.decode({fa, 5001 * kMs});
  EXPECT_EQ(decoder.decode({tag_frame(7, room.authentication), 5200 * kMs}).kind,
            FrameInput::Kind::kRegionalUnauthenticated);
  // The right tag after the refusals: taken (7 was never taken).
  (void)decoder.decode({fo, 6000 * kMs});
  (void)decoder.decode({fa, 6001 * kMs});
  EXPECT_EQ(decoder.decode({tag_frame(7, room.authentication), 6002 * kMs}).kind,
            FrameInput::Kind::kRegionalAlert);
  EXPECT_EQ(decoder.counters().regional_unauthenticated, 4U);
  EXPECT_EQ(decoder.counters().regional_tags, 5U);
  // Without a key: the tag frame is ignored, the pair is the alert.
  FrameDecoder plain;
  plain.start(two_sensors());
  (void)plain.decode({fo, 1000 * kMs});
  EXPECT_EQ(plain.decode({fa, 1001 * kMs}).kind, FrameInput::Kind::kRegionalAlert);
  EXPECT_EQ(plain.decode({tag_frame(1, room.authentication), 1002 * kMs}).kind,
            FrameInput::Kind::kNone);
}

// Refused bus statements lock the bus out while what they met stays held; a new level latched
// ends it (BusStatementGuard).
TEST(BusStatementGuard, FourRefusedInAMinuteLockTheLatchedLevel) {
  BusStatementGuard guard;
  const monitor::AlarmLevel alarm = monitor::AlarmLevel::kAlarm;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(guard.admits(alarm));
    EXPECT_FALSE(guard.refused(i * 30'000 * kMs, alarm));
  }
  // At 0, 30 and 60 s, the fourth at 61 s: 61 s from the first, no lockout.
  EXPECT_FALSE(guard.refused(61'000 * kMs, alarm));
  EXPECT_TRUE(guard.admits(alarm));
  EXPECT_TRUE(guard.refused(62'000 * kMs, alarm)) << "4 refused within 60 s (30, 60, 61, 62 s)";
  EXPECT_FALSE(guard.admits(alarm));
  EXPECT_FALSE(guard.admits(alarm));
  EXPECT_TRUE(guard.admits(monitor::AlarmLevel::kWarning)) << "another level latched: over";
  EXPECT_TRUE(guard.admits(alarm));
  // Nothing held: refusals never lock.
  for (int i = 0; i < 8; ++i) EXPECT_FALSE(guard.refused(70'000 * kMs, monitor::AlarmLevel::kNormal));
}

// Quiet start-up, then a 1 s push of 0.6 g through `decoder`: the non-isolated block of
// `monitor` overturns, alarm latched, the collapse held. The newest event's sequence.
std::uint8_t overturn(Monitor& monitor, FrameDecoder& decoder, std::int64_t& t) {
  std::uint8_t last_event = 0;
  for (int n = 0; n < 1400 && !monitor.status().axes[0].mode.terminal(); ++n) {
    can::SensorAcceleration m;
    m.node = 1;
    m.ax_g = n >= 400 && n < 600 ? 0.6 : 0.0;
    m.az_g = 1.0;
    m.sequence = static_cast<std::uint8_t>(n);
    const MonitorUpdate u = on_frame(monitor, decoder, {encoded(m), t});
    for (std::size_t i = 0; i < u.event_count; ++i) last_event = u.events[i].sequence;
    t += 5 * kMs;
  }
  return last_event;
}

MonitorConfig sweep_config() {
  MonitorConfig config;
  config.estimator.sample_rate_hz = 200.0;
  config.conditioning.startup_window_s = 0.5;
  config.sensor_health.stuck_samples = 0;
  return config;
}

// A non-isolated block's box fed through a FrameDecoder, started and ready to overturn.
class SweptBox : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(monitor.start(config, {&scene, nullptr}).ok());
    decoder.start(config);
  }
  const Scene scene = testing::make(testing::paper_block(0.0));
  const MonitorConfig config = sweep_config();
  Monitor monitor;
  FrameDecoder decoder;
  std::int64_t t = 0;
};

// The sweep issue 33 met: an Acknowledge frame for every sequence number released a latched
// alarm. The guard lets 4 be refused, then ignores the rest while the alarm stays latched; the
// operator's acknowledgement at the box (a call, as Modbus and MQTT make) still releases it.
TEST_F(SweptBox, ASweepOfTheSequencesCannotReleaseALatch) {
  const std::uint8_t last_event = overturn(monitor, decoder, t);
  ASSERT_EQ(monitor.status().latched, monitor::AlarmLevel::kAlarm);
  // Every sequence, the right one last (the sweep's worst case for the box).
  for (int k = 1; k <= 256; ++k) {
    const auto sequence = static_cast<std::uint8_t>(last_event + k);
    t += kMs;
    (void)on_frame(monitor, decoder,
                   {encoded(can::Acknowledge{can::AlarmLevel::kAlarm, 9, sequence}), t});
  }
  EXPECT_EQ(monitor.status().latched, monitor::AlarmLevel::kAlarm) << "the sweep released it";
  const FrameCounters& c = decoder.counters();
  EXPECT_EQ(c.acknowledgements, 256U);
  EXPECT_EQ(c.acknowledgements_refused, 4U);
  EXPECT_EQ(c.acknowledgements_ignored, 252U);
  EXPECT_EQ(c.acknowledgement_lockouts, 1U);
  EXPECT_TRUE(decoder.acknowledgements_locked_out());
  const MonitorUpdate at_box = monitor.acknowledge({monitor::AlarmLevel::kAlarm, last_event});
  EXPECT_EQ(at_box.acknowledgement, monitor::AckOutcome::kReleasedConditionHolds);
  EXPECT_EQ(monitor.status().latched, monitor::AlarmLevel::kNormal);
  (void)on_frame(monitor, decoder,
                 {encoded(can::Acknowledge{can::AlarmLevel::kAlarm, 9, last_event}), t + kMs});
  EXPECT_FALSE(decoder.acknowledgements_locked_out()) << "the latch it met is gone";
}

// The same sweep of StatueStands frames cannot clear a held collapse: 4 refused, the rest
// ignored, the collapse still held; a person's statement at the box still clears it.
TEST_F(SweptBox, ASweepCannotClearAHeldCollapse) {
  std::uint8_t last_event = overturn(monitor, decoder, t);
  ASSERT_TRUE(monitor.status().collapse.held);
  // Quiet ground after the fall (the estimators' own collapse stays: a person's word clears it).
  for (int n = 0; n < 200; ++n) {
    can::SensorAcceleration m;
    m.node = 1;
    m.az_g = 1.0;
    m.sequence = static_cast<std::uint8_t>(n);
    const MonitorUpdate u = on_frame(monitor, decoder, {encoded(m), t});
    for (std::size_t i = 0; i < u.event_count; ++i) last_event = u.events[i].sequence;
    t += 5 * kMs;
  }
  for (int k = 1; k <= 256; ++k) {
    const auto sequence = static_cast<std::uint8_t>(last_event + k);
    t += kMs;
    (void)on_frame(monitor, decoder, {encoded(can::StatueStands{9, sequence}), t});
  }
  EXPECT_TRUE(monitor.status().collapse.held) << "the sweep cleared it";
  const FrameCounters& c = decoder.counters();
  EXPECT_EQ(c.statue_stands, 256U);
  EXPECT_EQ(c.statue_stands_refused, 4U);
  EXPECT_EQ(c.statue_stands_ignored, 252U);
  EXPECT_EQ(c.statue_stands_lockouts, 1U);
  const MonitorUpdate at_box = monitor.statue_stands(last_event);
  EXPECT_EQ(at_box.statue_stands, monitor::StandsOutcome::kCleared);
  EXPECT_FALSE(monitor.status().collapse.held);
}

// A box restarted with a held collapse, on a silent bus (no estimator runs): a person's
// statement clears it; the collapse the status shows is the memory's, not a reading.
TEST_F(SweptBox, AStatementAfterARestartOnASilentBusClearsTheCollapse) {
  (void)overturn(monitor, decoder, t);
  ASSERT_TRUE(monitor.status().collapse.held);
  const BoxMemory memory = monitor.memory();
  Monitor restarted;
  ASSERT_TRUE(restarted.start(config, {&scene, nullptr}).ok());
  restarted.restore(memory);
  const MonitorUpdate first = restarted.poll();
  ASSERT_GT(first.event_count, 0U);
  EXPECT_TRUE(restarted.status().collapse.held);
  EXPECT_TRUE(restarted.status().axes[0].mode.collapsed()) << "the memory's collapse shown";
  const std::uint8_t latest = first.events[first.event_count - 1].sequence;
  const MonitorUpdate stated = restarted.statue_stands(latest);
  EXPECT_EQ(stated.statue_stands, monitor::StandsOutcome::kCleared);
  EXPECT_FALSE(restarted.status().collapse.held);
}

}  // namespace
}  // namespace plinth::firmware

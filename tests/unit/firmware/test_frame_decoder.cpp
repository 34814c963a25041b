// The bus's frames as the monitor's inputs (frame_decoder.h): a configured node's sample goes
// to its sensor's index, an Acknowledge is an acknowledgement, anything else is no input.
#include <gtest/gtest.h>

#include "plinth/firmware/can_frames.h"
#include "plinth/firmware/frame_decoder.h"

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

}  // namespace
}  // namespace plinth::firmware

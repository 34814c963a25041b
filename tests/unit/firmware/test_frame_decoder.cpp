// The bus's frames as the monitor's inputs (frame_decoder.h): a configured node's sample goes
// to its sensor's index, an Acknowledge is an acknowledgement, anything else is no input.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace plinth::firmware
